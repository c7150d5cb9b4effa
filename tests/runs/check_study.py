#!/usr/bin/python3
"""scripts/study on a small study of the hydrostatic tank (2 x 2 cases of a few steps): every case
runs once, a second call runs nothing again (resumable), results.csv has a row per case with its
parameters, cost and accuracy columns, and pareto.png is written; a bad study file is refused.

usage: check_study.py <flotsam> <mpiexec> <tests/runs/scenes> <scripts folder>"""

import csv
import os
import shutil
import subprocess
import sys

from flotsam_run import Checks, main_arguments


def main():
    flotsam_path, _mpiexec, _scenes, rest = main_arguments()
    scripts = os.path.abspath(rest[0])
    inputs = os.path.join(os.path.dirname(scripts), "inputs")
    checks = Checks()
    work = os.path.abspath("study")
    shutil.rmtree(work, ignore_errors=True)       # a clean start: the study would resume a previous one
    os.makedirs(work)
    study = os.path.join(work, "small.study")
    with open(study, "w") as f:
        f.write(f"""[study]
scene = {os.path.join(inputs, "hydrostatic_tank.nml")}
ranks = 2
output = {os.path.join(work, "out")}
[parameters]
material:water stabilization = ["C0", "NB"]
grid rotation = [0.0, 45.0]
run max_steps = [20]
[hydrostatic]
density = 1000.0
gravity = 10.0
""")
    command = [sys.executable, os.path.join(scripts, "study"), study, "--flotsam", flotsam_path]
    first = subprocess.run(command, capture_output=True, text=True)
    checks.check(first.returncode == 0, "the study runs", first.stderr[-1500:])
    # each case stops at its max_steps (the outcome run_summary.csv names)
    checks.check(first.stdout.count(": max_steps, ") == 4 and "done before" not in first.stdout, "4 cases run",
                 first.stdout)
    second = subprocess.run(command, capture_output=True, text=True)
    checks.check(second.returncode == 0 and second.stdout.count("done before") == 4, "resumed: nothing run again",
                 second.stdout)
    results = os.path.join(work, "out", "results.csv")
    if checks.check(os.path.exists(results), "results.csv written"):
        with open(results) as f:
            rows = list(csv.DictReader(f))
        checks.check(len(rows) == 4, "one row per case", str(len(rows)))
        needed = ["case", "material:water stabilization", "grid rotation", "wall_seconds", "steps",
                  "particle_steps_per_second_per_core", "peak_memory_bytes", "outcome", "h_eq_drift_percent",
                  "h_cm_drift_percent", "pressure_rms_error_relative", "max_kinetic_energy", "mass_change_relative"]
        checks.check(all(k in rows[0] for k in needed), "cost and accuracy columns", str(list(rows[0])))
        checks.check(all(r["steps"] == "20" for r in rows), "each case ran its 20 steps")
        checks.check(all(int(r["peak_memory_bytes"]) > 1e6 for r in rows), "peak memory measured")
        aligned = [r for r in rows if float(r["grid rotation"]) == 0.0 and r["material:water stabilization"] == "C0"]
        # C0 holds the tank at rest on the aligned grid: only its cell averaging differs from rho g (H - y):
        # RMS h / (sqrt(12) H) = 0.4 / (sqrt(12) 3.2) = 0.036
        checks.check(len(aligned) == 1 and abs(float(aligned[0]["pressure_rms_error_relative"]) - 0.036) < 0.003,
                     "aligned tank, C0: pressure error = the cell-averaging error", str(aligned))
    checks.check(os.path.exists(os.path.join(work, "out", "pareto.png")), "pareto.png written")

    with open(os.path.join(work, "bad.study"), "w") as f:
        f.write("[study]\nscene = nowhere.nml\n[parameters]\ngrid rotation = [0.0]\n")
    bad = subprocess.run([sys.executable, os.path.join(scripts, "study"), os.path.join(work, "bad.study"),
                          "--flotsam", flotsam_path], capture_output=True, text=True)
    checks.check(bad.returncode != 0 and "nowhere.nml not found" in bad.stderr, "a bad study file is refused",
                 bad.stderr)
    raise SystemExit(checks.summary())


if __name__ == "__main__":
    main()
