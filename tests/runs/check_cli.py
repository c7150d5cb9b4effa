#!/usr/bin/python3
"""The command line and what a run says on standard error (docs/output.md, docs/input.md):
  * `flotsam --version`: version, git commit, build type, MPI and HDF5 libraries; exit 0 without a scene
  * a run starts with a banner (version, commit, ranks, scene, output folder) and ends with one line
    (outcome, steps, simulated time, wall time, particle-steps/s); max_steps is named as the outcome
  * output times are k x output_interval: diagnostics.csv of output_interval = 0.1 reads 0.1, 0.2, 0.3
  * linear APIC with a fluid gets one warning line after the banner (docs/theory.md, APIC); B-splines none
  * two whole scenes (`flotsam a.nml b.nml`) are refused with a usage hint
  * scenes too large for the machine are refused before any particle is made, on every rank: the dam
    break at 100 particles per cell under `ulimit -v` (2 GB per process), at 20000 without a limit

usage: check_cli.py <flotsam> <mpiexec> <tests/runs/scenes> <scripts folder>"""

import os
import shlex
import subprocess
import time

from flotsam_run import Checks, Flotsam, csv_data_lines, main_arguments, pass_on_array_copies, read_diagnostics

RANKS = 2


def error_lines(stderr):
    return [line for line in stderr.splitlines() if line.startswith("flotsam: error")]


def run_per_rank(flotsam, scene, arguments, limit_kib=None, timeout=120):
    """Run on RANKS ranks with each rank's exit status printed by a shell around it; returns
    (CompletedProcess, [exit status of each rank], seconds)."""
    inner = shlex.join([flotsam.flotsam, scene, *arguments]) + '; echo "rank exit status $?" >&2'
    if limit_kib:
        inner = f"ulimit -v {limit_kib}; " + inner
    command = [flotsam.mpiexec, "-np", str(RANKS), "sh", "-c", inner]
    start = time.monotonic()
    result = subprocess.run(command, cwd=flotsam.workdir, env=flotsam.environment, capture_output=True, text=True,
                            timeout=timeout)
    seconds = time.monotonic() - start
    pass_on_array_copies(result.stderr)
    codes = [int(line.split()[-1]) for line in result.stderr.splitlines() if line.startswith("rank exit status")]
    return result, codes, seconds


def main():
    flotsam_path, mpiexec, scenes, rest = main_arguments()
    inputs = os.path.join(os.path.dirname(os.path.abspath(rest[0])), "inputs")
    dam_break = os.path.join(inputs, "dam_break.nml")
    checks = Checks()
    flotsam = Flotsam(flotsam_path, mpiexec, "output")

    # --version: no scene, no MPI launcher needed
    result = subprocess.run([flotsam.flotsam, "--version"], cwd=flotsam.workdir, env=flotsam.environment,
                            capture_output=True, text=True, timeout=60)
    lines = result.stdout.splitlines()
    checks.check(result.returncode == 0, "--version: exit status 0", str(result.returncode))
    for prefix in ("flotsam ", "commit ", "build type ", "MPI library ", "HDF5 library "):
        found = [line for line in lines if line.startswith(prefix) and len(line) > len(prefix)]
        checks.check(len(found) == 1, f"--version: a line '{prefix}...'", result.stdout)
    version = lines[0].split()[1] if lines else "?"
    checks.check(any("Open MPI" in line or "MPICH" in line for line in lines), "--version: the MPI library's own string",
                 result.stdout)
    checks.check(any(line.startswith("HDF5 library 1.") for line in lines), "--version: the HDF5 version", result.stdout)

    # banner, final line, output times of k x 0.1
    column = os.path.join(scenes, "column.nml")
    flotsam.remove("times")
    result = flotsam.run(column, RANKS, "--set", "&run end_time = 0.3, output_interval = 0.1, output_dir = 'times', "
                         "checkpoint_interval_steps = 0 /", "--set", "&grid cell_size = 0.05 /")
    stderr = result.stderr.splitlines()
    if checks.check(result.returncode == 0, "short run", result.stderr[-1500:]):
        first = stderr[0] if stderr else ""
        checks.check(first.startswith(f"flotsam {version} (commit ") and f"on {RANKS} ranks" in first
                     and "scene " + column in first and "output folder times" in first,
                     "banner: version, commit, ranks, scene, output folder", first)
        last = stderr[-1] if stderr else ""
        checks.check(last.startswith("flotsam: end of run: finished, ") and " steps to t = 0.3 s in " in last
                     and "s wall time, " in last and last.endswith(" particle-steps/s"),
                     "final line: outcome, steps, simulated time, wall time, particle-steps/s", last)
        times = [line.split(",")[0] for line in csv_data_lines(flotsam.path("times", "diagnostics.csv"))[1:]]
        checks.check(times == ["0.0", "0.1", "0.2", "0.3"], "diagnostics.csv times are 0.0, 0.1, 0.2, 0.3 exactly",
                     str(times))
        rows = read_diagnostics(flotsam.path("times"))
        checks.check([float(r["time"]) for r in rows] == [0.0, 0.1, 0.2, 0.3], "they read back as the decimals")

    flotsam.remove("capped")
    result = flotsam.run(column, RANKS, "--set", "&run max_steps = 5, output_dir = 'capped' /")
    last = result.stderr.splitlines()[-1] if result.stderr else ""
    checks.check(result.returncode == 0 and last.startswith("flotsam: end of run: max_steps, 5 steps to t = "),
                 "max_steps run: the final line names max_steps", last)
    with open(flotsam.path("capped", "run_summary.csv")) as f:
        checks.check(f.read().strip().endswith(",max_steps"), "max_steps run: run_summary.csv outcome max_steps")

    # advice on a valid scene likely to fail: linear APIC with a fluid warns once (rank 0), after the banner;
    # the same on B-splines does not
    for shape, expected in (("linear", 1), ("bspline2", 0)):
        folder = f"apic_{shape}"
        flotsam.remove(folder)
        result = flotsam.run(dam_break, RANKS, "--set", f"&run transfer = 'apic', max_steps = 2, output_dir = '{folder}' /",
                             "--set", f"&grid shape_function = '{shape}' /")
        warnings = [line for line in result.stderr.splitlines() if line.startswith("flotsam: warning: ")]
        advice = [line for line in warnings if "transfer = 'apic' with &grid shape_function = 'linear' and a fluid" in line
                  and "shape_function = 'bspline2' runs them" in line]
        checks.check(result.returncode == 0 and len(warnings) == expected and len(advice) == expected,
                     f"APIC on {shape} shape functions with water: {expected} warning line(s), the run goes on",
                     result.stderr[-1200:])
        if expected:
            checks.check(result.stderr.splitlines()[0].startswith("flotsam ") and result.stderr.splitlines()[1] == advice[0],
                         "the warning follows the banner", result.stderr[:600])

    # two whole scenes
    flotsam.remove("column")
    result = flotsam.run(column, RANKS, column)
    errors = error_lines(result.stderr)
    checks.check(result.returncode == 2, "two scenes: exit status 2", str(result.returncode))
    checks.check(len(errors) == 1 and "column.nml is a whole scene, not an override file" in errors[0]
                 and "usage: flotsam <scene.nml>" in errors[0], "two scenes: one message with a usage hint", str(errors))
    checks.check(not os.path.exists(flotsam.path("column")), "two scenes: no output folder")

    # scenes too large: refused before seeding, on every rank
    cases = [
        ("100 particles per cell, ulimit -v 2 GB", 100, 2000000, 30,
         "variable particles_per_cell = 100 makes 25000000 particles, about"),
        ("20000 particles per cell", 20000, None, 30,
         "variable particles_per_cell = 20000 makes 1000000000000 particles, about"),
    ]
    for label, ppc, limit, seconds_allowed, expected in cases:
        flotsam.remove("large")
        result, codes, seconds = run_per_rank(flotsam, dam_break, [
            "--set", f"&body particles_per_cell = {ppc} /", "--set", "&run output_dir = 'large' /"], limit)
        errors = error_lines(result.stderr)
        checks.check(len(errors) == 1 and expected in errors[0] and "per rank on 2 ranks, more than the" in errors[0]
                     and "available" in errors[0] and "dam_break.nml with --set 1, --set 2: group &body (1st" in errors[0],
                     f"{label}: one message with the group, variable, count, estimate and memory available",
                     str(errors) + result.stderr[-800:])
        checks.check(codes == [2] * RANKS, f"{label}: exit status 2 on every rank", str(codes))
        checks.check(seconds < seconds_allowed, f"{label}: refused within {seconds_allowed} s", f"{seconds:.1f} s")
        checks.check("Error allocating" not in result.stderr and "Backtrace" not in result.stderr,
                     f"{label}: no runtime error or backtrace")
        checks.check(not os.path.exists(flotsam.path("large")), f"{label}: no output folder")
    raise SystemExit(checks.summary())


if __name__ == "__main__":
    main()
