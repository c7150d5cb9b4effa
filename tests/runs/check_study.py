#!/usr/bin/python3
"""scripts/study on small studies of the hydrostatic tank:
  * 2 x 2 cases of 20 steps, 2 at once (--jobs 2): each case prints a line when it starts and when it
    ends, and runs with a TMPDIR of its own (Open MPI's session directories); results.csv has a row
    per case with its parameters, cost and accuracy columns; pareto.png;
  * a second call runs nothing again (resumed), --case N runs (here: finds done) case N only;
  * the base scene changed: a case is not reused but run again, its old folder moved to superseded/
    (or, with --stale refuse, the study stops and the folder stays as it was);
  * a case stopped by SIGTERM to its ranks (what a batch system sends), and one whose study got
    SIGTERM (the study passes SIGUSR1 on to the case), are not done: the study exits with 5, and the
    next call continues them from their checkpoints; their cost adds up both invocations;
  * --report tabulates the cases that are done without running anything; a bad study file is refused;
  * the measures: [load] on the tank (its side wall's force, exact at rest on the aligned grid:
    rho g H^2 / 2 = 51 200 N/m) and [surge] on a coarse dam break of Koshizuka & Oka (inputs/dam_break_ko.nml,
    10 cells per L): the front at the measured times, each within 10 % of the measurement while the
    front has not yet run ahead (T < 1.6), and growing with T; a [surge] without its width is refused;
  * [ensemble] (issue 52): 20 random cases of a block carried onto a column (position along the flume,
    initial velocity) in one command: results.csv with 20 rows and their samples, ensemble.csv with the
    column's filtered peak and impulse (median between the 10 % and 90 % quantiles, the steady count),
    ensemble.png; the same seed gives the same cases (--dry-run), another seed others, and case i does
    not depend on the number of cases; a distribution the study does not know is refused.

usage: check_study.py <flotsam> <mpiexec> <tests/runs/scenes> <scripts folder>"""

import csv
import glob
import os
import shutil
import signal
import subprocess
import sys

from flotsam_run import Checks, DrainedPopen, child_pids, main_arguments, read_diagnostics, wait_for_rows


def ended(line):
    """A study line saying a case ran to its end: to end_time (finished) or to its max_steps."""
    return ": finished, " in line or ": max_steps, " in line


def descendants(pid):
    found, todo = [], [pid]
    while todo:
        children = child_pids(todo.pop())
        found += children
        todo += children
    return found


def ranks_of(process, flotsam):
    """The flotsam processes below `process` (the study, its mpiexec, the launcher's proxies)."""
    ranks = []
    for pid in descendants(process.pid):
        try:
            with open(f"/proc/{pid}/cmdline", "rb") as f:
                if f.read().split(b"\0")[0].decode() == flotsam:
                    ranks.append(pid)
        except OSError:
            pass
    return ranks


def read_results(path):
    with open(path) as f:
        return list(csv.DictReader(f))


def write_study(path, scene, output, parameters, measures="[hydrostatic]\ndensity = 1000.0\ngravity = 10.0\n"
                "[load]\ncolumn = x_max_fx\nexpected = 51200.0\n"):
    with open(path, "w") as f:
        f.write(f"[study]\nscene = {scene}\nranks = 2\noutput = {output}\n[parameters]\n{parameters}\n{measures}")


def check_surge(checks, scripts, inputs, work, flotsam_path, mpiexec):
    """[surge]: the dam break's front against Koshizuka & Oka at the measured times."""
    study = os.path.join(work, "surge.study")
    out = os.path.join(work, "surge")
    write_study(study, os.path.join(inputs, "dam_break_ko.nml"), out,
                "grid cell_size = [0.0146]\nrun output_interval = [0.005]",
                "[surge]\nwidth = 0.146\ngravity = 9.81\n")
    result = subprocess.run([sys.executable, os.path.join(scripts, "study"), study, "--flotsam", flotsam_path,
                             "--mpiexec", mpiexec], capture_output=True, text=True)
    results = os.path.join(out, "results.csv")
    if not checks.check(result.returncode == 0 and os.path.exists(results), "[surge]: the dam break study runs",
                        result.stdout[-800:] + result.stderr[-800:]):
        return
    row = read_results(results)[0]
    measured = {0.381: 1.111, 0.769: 1.252, 1.153: 1.505, 1.537: 1.892, 1.935: 2.241, 2.323: 2.615,
                2.719: 3.003, 3.096: 3.624}
    z = [float(row[f"surge_Z_{t:.3f}"]) for t in measured]
    early = [(zi, measured[t]) for zi, t in zip(z, measured) if t < 1.6]
    checks.check(all(abs(zi / ref - 1) < 0.1 for zi, ref in early), "[surge]: the front within 10 % of Koshizuka & "
                 "Oka while T < 1.6", str(early))
    checks.check(all(b > a for a, b in zip(z, z[1:])), "[surge]: the front advances with T", str(z))
    deviation = sum(abs(zi / ref - 1) for zi, ref in zip(z, measured.values())) / len(z)
    checks.check(abs(float(row["surge_front_error_percent"]) - 100 * deviation) < 1e-9,
                 "[surge]: surge_front_error_percent is the mean |Z / Z_measured - 1|", row["surge_front_error_percent"])
    with open(os.path.join(work, "no_width.study"), "w") as f:
        f.write(f"[study]\nscene = {os.path.join(inputs, 'dam_break_ko.nml')}\n[parameters]\ngrid rotation = [0.0]\n"
                "[surge]\ngravity = 9.81\n")
    bad = subprocess.run([sys.executable, os.path.join(scripts, "study"), os.path.join(work, "no_width.study"),
                          "--dry-run"], capture_output=True, text=True)
    checks.check(bad.returncode != 0 and "[surge] width is required" in bad.stderr, "[surge] without width is refused",
                 bad.stderr)


def write_ensemble_study(path, scene, output, seed, cases):
    with open(path, "w") as f:
        f.write(f"[study]\nscene = {scene}\nranks = 1\noutput = {output}\n"
                f"[ensemble]\ncases = {cases}\nseed = {seed}\nloads = column\n"
                "[random]\nbody:block shift = uniform([-0.02, 0.0], [0.02, 0.0])\n"
                "body:block velocity = normal([0.5, 0.0], [0.1, 0.0])\n")


def check_ensemble(checks, scripts, scenes, work, flotsam_path, mpiexec):
    """[ensemble]: random debris cases, their distribution, reproducible."""
    scene = os.path.join(scenes, "structures", "column_flow.nml")
    study = os.path.join(work, "ensemble.study")
    out = os.path.join(work, "ensemble")
    write_ensemble_study(study, scene, out, 7, 20)
    base = [sys.executable, os.path.join(scripts, "study")]
    result = subprocess.run(base + [study, "--flotsam", flotsam_path, "--mpiexec", mpiexec, "--jobs", "2"],
                            capture_output=True, text=True)
    summary = os.path.join(out, "ensemble.csv")
    if not checks.check(result.returncode == 0 and os.path.exists(summary), "[ensemble]: 20 cases run in one command",
                        result.stdout[-1500:] + result.stderr[-1500:]):
        return
    rows = read_results(os.path.join(out, "results.csv"))
    checks.check(len(rows) == 20 and all(r["sample"] for r in rows) and all(r["body:block shift"] for r in rows),
                 f"[ensemble]: results.csv has a row per case with its sample ({len(rows)} rows)")
    with open(summary) as f:
        lines = [line for line in f if not line.startswith("#")]
    table = {r["measure"]: r for r in csv.DictReader(lines)}
    peak = table.get("column_peak_filtered")
    ok = peak is not None and int(peak["cases"]) == 20 and \
        float(peak["q10"]) <= float(peak["median"]) <= float(peak["q90"]) and float(peak["median"]) > 0 and \
        1 <= int(peak["cases_for_steady_median"]) <= 20
    checks.check(ok, "[ensemble]: ensemble.csv: the column's filtered peak over 20 cases, q10 <= median <= q90, "
                 "the steady count", str(peak))
    peaks = sorted(float(r["column_peak_filtered"]) for r in rows)
    checks.check(peak is not None and abs(float(peak["median"]) - 0.5 * (peaks[9] + peaks[10])) <= 1e-9 * peaks[10],
                 "[ensemble]: its median is the median of results.csv's column_peak_filtered")
    checks.check("column_impulse" in table and float(table["column_impulse"]["median"]) > 0,
                 "[ensemble]: and the impulse of the event")
    checks.check(os.path.getsize(os.path.join(out, "ensemble.png")) > 5000, "[ensemble]: ensemble.png (box plot)")
    checks.check(peaks[0] < peaks[-1], f"[ensemble]: the cases differ (peaks {peaks[0]:.4g} .. {peaks[-1]:.4g} N/m)")

    def dry(seed, cases):
        path = os.path.join(work, f"dry_{seed}_{cases}.study")
        write_ensemble_study(path, scene, os.path.join(work, "dry"), seed, cases)
        return subprocess.run(base + [path, "--dry-run"], capture_output=True, text=True).stdout.splitlines()

    same, other, fewer = dry(7, 20), dry(8, 20), dry(7, 5)
    checks.check(same == dry(7, 20) and len(same) == 20, "[ensemble]: the same seed gives the same cases")
    checks.check(same != other, "[ensemble]: another seed gives other cases")
    checks.check(fewer == same[:5], "[ensemble]: case i does not depend on the number of cases")
    with open(os.path.join(work, "bad_ensemble.study"), "w") as f:
        f.write(f"[study]\nscene = {scene}\n[ensemble]\ncases = 3\nseed = 1\n[random]\n"
                "body:block rotation = gauss(0.0, 5.0)\n")
    bad = subprocess.run(base + [os.path.join(work, "bad_ensemble.study"), "--dry-run"], capture_output=True, text=True)
    checks.check(bad.returncode != 0 and "expected uniform(low, high), normal(mean, sd) or choice" in bad.stderr,
                 "[ensemble]: an unknown distribution is refused with the file, section and variable", bad.stderr)


def main():
    flotsam_path, mpiexec, scenes, rest = main_arguments()
    flotsam_path = os.path.abspath(flotsam_path)
    scripts = os.path.abspath(rest[0])
    inputs = os.path.join(os.path.dirname(scripts), "inputs")
    checks = Checks()
    work = os.path.abspath("study")
    shutil.rmtree(work, ignore_errors=True)       # a clean start: the study would resume a previous one
    os.makedirs(work)
    scene = os.path.join(work, "tank.nml")        # a copy: changed below
    shutil.copy(os.path.join(inputs, "hydrostatic_tank.nml"), scene)
    study = os.path.join(work, "small.study")
    out = os.path.join(work, "out")
    write_study(study, scene, out, 'material:water stabilization = ["C0", "NB"]\ngrid rotation = [0.0, 45.0]\n'
                "run max_steps = [20]")
    base = [sys.executable, os.path.join(scripts, "study"), study, "--flotsam", flotsam_path, "--mpiexec", mpiexec]

    def run(*arguments):
        return subprocess.run(base + list(arguments), capture_output=True, text=True)

    # the first call through a launcher that notes the TMPDIR each case gets, then starts it
    launches = os.path.join(work, "launches.log")
    wrapper = os.path.join(work, "mpiexec_noting_tmpdir")
    with open(wrapper, "w") as f:
        f.write(f'#!/bin/sh\n[ -d "$TMPDIR" ] && there=exists || there=missing\n'
                f'echo "${{TMPDIR:-unset}} $there" >> "{launches}"\nexec "{mpiexec}" "$@"\n')
    os.chmod(wrapper, 0o755)
    first = subprocess.run(base[:-1] + [wrapper, "--jobs", "2"], capture_output=True, text=True)
    checks.check(first.returncode == 0, "the study runs (--jobs 2)", first.stderr[-1500:])
    with open(launches) as f:
        started = [line.split() for line in f]
    tmpdirs = {tmpdir for tmpdir, there in started if there == "exists"}
    # Open MPI's session directories live in $TMPDIR: cases that share one can break each other's start
    checks.check(len(started) == 4 and len(tmpdirs) == 4 and os.environ.get("TMPDIR") not in tmpdirs and
                 not any(os.path.exists(d) for d in tmpdirs),
                 "each case started with a TMPDIR of its own, removed after it", str(started))
    lines = first.stdout.splitlines()
    checks.check(sum(line.endswith(": started") for line in lines) == 4 and
                 sum(ended(line) and "(exit 0)" in line for line in lines) == 4 and
                 "done before" not in first.stdout, "4 cases run, a line as each starts and ends", first.stdout)
    # with 2 at once, the second case starts before the first ends
    starts = [i for i, line in enumerate(lines) if line.endswith(": started")]
    ends = [i for i, line in enumerate(lines) if "(exit 0)" in line]
    checks.check(len(starts) == 4 and len(ends) == 4 and starts[1] < ends[0], "--jobs 2: two cases at once",
                 first.stdout)
    second = run()
    checks.check(second.returncode == 0 and second.stdout.count("done before") == 4 and "started" not in second.stdout,
                 "resumed: nothing run again", second.stdout)
    one = run("--case", "2")
    checks.check(one.returncode == 0 and one.stdout.count("done before") == 1 and "[2/4]" in one.stdout,
                 "--case 2: that case only", one.stdout)
    results = os.path.join(out, "results.csv")
    if checks.check(os.path.exists(results), "results.csv written"):
        rows = read_results(results)
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
        checks.check(len(aligned) == 1 and abs(float(aligned[0]["load_error_percent"])) < 1e-6,
                     "[load]: the aligned tank's side wall carries rho g H^2 / 2 (load_error_percent)",
                     str(aligned and aligned[0]["load_error_percent"]))
    checks.check(os.path.exists(os.path.join(out, "pareto.png")), "pareto.png written")
    check_surge(checks, scripts, inputs, work, flotsam_path, mpiexec)

    # --- the base scene changes: nothing stale is reused ------------------------------------------------
    with open(scene) as f:
        text = f.read()
    with open(scene, "w") as f:
        f.write(text.replace("end_time = 3.0", "end_time = 2.0"))
    case1 = os.path.join(out, "cases", rows[0]["case"]) if os.path.exists(results) else ""
    with open(os.path.join(case1, "run_summary.csv")) as f:
        summary_before = f.read()
    refused = run("--case", "1", "--stale", "refuse")
    checks.check(refused.returncode == 1 and "changed since its run: the scene file" in refused.stderr and
                 "started" not in refused.stdout, "scene changed, --stale refuse: stops, names the change",
                 refused.stdout + refused.stderr)
    with open(os.path.join(case1, "run_summary.csv")) as f:
        checks.check(f.read() == summary_before, "--stale refuse: the case folder untouched")
    moved = run("--case", "1")
    aside = os.path.join(out, "superseded", rows[0]["case"] + ".1")
    checks.check(moved.returncode == 0 and "changed since its run: the scene file: moved to " + aside in moved.stdout
                 and "done before" not in moved.stdout and any(ended(line) for line in moved.stdout.splitlines()),
                 "scene changed: the case runs again, its old folder moved aside", moved.stdout + moved.stderr)
    if os.path.exists(os.path.join(aside, "run_summary.csv")):
        with open(os.path.join(aside, "run_summary.csv")) as f:
            checks.check(f.read() == summary_before, "superseded/: the old results kept as they were")
    else:
        checks.check(False, "superseded/: the old results kept as they were", aside)
    report = run("--report")
    checks.check(report.returncode == 0 and "wrote" in report.stdout and "(1 of 4 cases)" in report.stdout and
                 report.stdout.count("run with another key (stale)") == 3 and "started" not in report.stdout,
                 "--report: only the case run with the changed scene is tabulated", report.stdout + report.stderr)

    # --- stopped cases are continued from their checkpoints --------------------------------------------
    long_study = os.path.join(work, "long.study")
    long_out = os.path.join(work, "long")
    steps = 2000
    write_study(long_study, scene, long_out, f'material:water stabilization = ["C0", "NB"]\nrun max_steps = [{steps}]')
    long_base = [sys.executable, os.path.join(scripts, "study"), long_study, "--flotsam", flotsam_path,
                 "--mpiexec", mpiexec]
    folders = [os.path.join(long_out, "cases", f"stabilization-{s}_max_steps-{steps}") for s in ("C0", "NB")]
    for number, how in ((1, "ranks"), (2, "study")):
        process = DrainedPopen(long_base + ["--case", str(number)], stdout=subprocess.PIPE,
                               stderr=subprocess.PIPE, text=True)
        started = wait_for_rows(os.path.join(folders[number - 1], "diagnostics.csv"), process)
        if how == "ranks":         # a batch system's SIGTERM to the job's processes
            for pid in ranks_of(process, flotsam_path):
                os.kill(pid, signal.SIGTERM)
        else:                      # SIGTERM to the study only: it passes SIGUSR1 on to its case
            process.send_signal(signal.SIGTERM)
        stdout, stderr = process.communicate(timeout=300)
        checks.check(started and process.returncode == 5 and "stopped_by_signal" in stdout and not any(ended(line) for line in stdout.splitlines()),
                     f"case {number} stopped (SIGTERM to the {how}): the study exits with 5",
                     f"{process.returncode}: {stdout} {stderr[-800:]}")
    again = subprocess.run(long_base, capture_output=True, text=True)
    checks.check(again.returncode == 0 and again.stdout.count("continuing from checkpoints/checkpoint_") == 2 and
                 sum(ended(line) for line in again.stdout.splitlines()) == 2 and "done before" not in again.stdout,
                 "the stopped cases continue from their checkpoints", again.stdout + again.stderr[-800:])
    long_results = os.path.join(long_out, "results.csv")
    if checks.check(os.path.exists(long_results), "results of the continued cases"):
        rows = read_results(long_results)
        checks.check(len(rows) == 2 and all(r["steps"] == str(steps) and r["invocations"] == "2" and
                                            r["outcome"] in ("finished", "max_steps") for r in rows),
                     f"cost of a continued case: its {steps} steps over 2 invocations", str(rows))
        last = [read_diagnostics(folder)[-1] for folder in folders]
        checks.check(all(int(row["step"]) == steps for row in last), "the continued runs reached their last step",
                     str([row["step"] for row in last]))
    third = subprocess.run(long_base, capture_output=True, text=True)
    checks.check(third.returncode == 0 and third.stdout.count("done before") == 2, "then done", third.stdout)

    with open(os.path.join(work, "bad.study"), "w") as f:
        f.write("[study]\nscene = nowhere.nml\n[parameters]\ngrid rotation = [0.0]\n")
    bad = subprocess.run([sys.executable, os.path.join(scripts, "study"), os.path.join(work, "bad.study"),
                          "--flotsam", flotsam_path], capture_output=True, text=True)
    checks.check(bad.returncode != 0 and "nowhere.nml not found" in bad.stderr, "a bad study file is refused",
                 bad.stderr)
    bad_case = run("--case", "9")
    checks.check(bad_case.returncode != 0 and "--case 9: the study has cases 1 to 4" in bad_case.stderr,
                 "--case out of range is refused", bad_case.stderr)
    check_ensemble(checks, scripts, scenes, work, flotsam_path, mpiexec)
    leftovers = glob.glob(os.path.join(work, "**", "*.tmp"), recursive=True)
    checks.check(not leftovers, "no temporary files left", str(leftovers))
    raise SystemExit(checks.summary())


if __name__ == "__main__":
    main()
