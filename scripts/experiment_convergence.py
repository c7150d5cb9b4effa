#!/usr/bin/python3
"""Errors against the flume experiments at several resolutions, for three settings (issue 50, item 4).

usage: scripts/experiment_convergence.py [lobovsky] [spheric] [--out DIR] [--flotsam PATH] [--ranks N]
                                         [--cells h1,h2,...] [--settings standard,FOAL1,recommended]

Runs inputs/validation/lobovsky_h300.nml (2-D; h = 10, 5, 2.5 mm: H/h = 30, 60, 120) and/or
spheric_test2.nml (3-D; h = 4 and 2 cm) with each setting,

  standard     no stabilization, multilinear shape functions, the default 5 % PIC blend
  FOAL1        FOAL1, multilinear, 5 % PIC (the code's defaults with FOAL1)
  recommended  the scene as it is (FOAL1, quadratic B-splines, 1 % PIC)

compares each run with its measurements (scripts/compare_experiment.py, tables kept in --out) and prints a
Markdown table of the errors:

  Lobovsky  plateau: mean |sim/exp - 1| of the 10 ms means of sensors 1-3 at 0.475 ... 0.675 s; p4: the
            mean ratio of sensor 4 there; arrival: sensor 1's, simulation - measurement; peak: sensor 1's
            first-impact peak over the measured event's; levels: the mean NMAE of the levels H1-H3 over
            0-1.0 s, H4: H4's (where the run-up falls back over the gauge)
  SPHERIC   plateau: mean |sim/exp - 1| of P1-P4 at 0.5, 0.6, 0.8, 1.0 s; arrival: P1's; H2, H4: NMAE
            over 0-1.5 s

and each run's wall time and steps. A run already in --out (its gauges.csv and run_summary.csv) by the
same flotsam executable is not run again. Release build expected (scripts/flotsam build): the finest
Lobovsky runs take about 10 minutes each on 2 cores, SPHERIC at h = 2 cm about half an hour.
"""

import argparse
import csv
import os
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import compare_experiment  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SCENES = {
    "lobovsky": dict(scene="inputs/validation/lobovsky_h300.nml", cells=(0.01, 0.005, 0.0025),
                     data="tests/data/experiments/lobovsky2014_h300_pressure.csv",
                     levels="tests/data/experiments/lobovsky2014_h300_levels.csv"),
    "spheric": dict(scene="inputs/validation/spheric_test2.nml", cells=(0.04, 0.02),
                    data="tests/data/experiments/spheric_test2_kleefsman2005.csv"),
}
SETTINGS = {
    "standard": ["&material name = 'water', stabilization = 'none' /", "&grid shape_function = 'linear' /",
                 "&run flip_fraction = 0.95 /"],
    "FOAL1": ["&material name = 'water', stabilization = 'FOAL1' /", "&grid shape_function = 'linear' /",
              "&run flip_fraction = 0.95 /"],
    "recommended": [],
}


def mpiexec():
    return os.environ.get("FLOTSAM_MPIEXEC", "mpirun")


def run(flotsam, ranks, scene, settings, cell, output):
    summary = os.path.join(output, "run_summary.csv")
    if os.path.exists(summary) and os.path.getmtime(summary) > os.path.getmtime(flotsam):
        return
    command = [mpiexec(), "-np", str(ranks), flotsam, os.path.join(ROOT, scene), "--overwrite",
               "--set", f"&run output_dir = '{output}', particle_output = .false. /",
               "--set", f"&grid cell_size = {cell} /"]
    for override in settings:
        command += ["--set", override]
    environment = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    print(" ".join(command), flush=True)
    subprocess.run(command, check=True, env=environment, stdout=subprocess.DEVNULL)


def run_facts(output):
    """Wall time [s] and steps from run_summary.csv (its columns by name)."""
    with open(os.path.join(output, "run_summary.csv"), encoding="utf-8") as file:
        rows = [row for row in csv.reader(line for line in file if not line.startswith("#"))]
    values = dict(zip(rows[0], rows[-1]))
    return float(values.get("wall_seconds", "nan")), values.get("steps", "?")


def errors(name, experiment, table, levels=None):
    value = compare_experiment.value
    if name == "lobovsky":
        ratios = [value(table, s, f"mean@{t:g}") for s in ("p1", "p2", "p3") for t in experiment.times]
        p4 = [value(table, "p4", f"mean@{t:g}") for t in experiment.times]
        return {"plateau": sum(abs(r - 1) for r in ratios) / len(ratios), "p4": sum(p4) / len(p4),
                "arrival": value(table, "p1", "arrival"), "peak": value(table, "p1", "peak"),
                "levels": sum(value(levels, g, "nmae") for g in ("H1", "H2", "H3")) / 3,
                "H4": value(levels, "H4", "nmae")}
    ratios = [value(table, s, f"mean@{t:g}") for s in ("P1", "P2", "P3", "P4") for t in experiment.times]
    return {"plateau": sum(abs(r - 1) for r in ratios) / len(ratios), "arrival": value(table, "P1", "arrival"),
            "H2": value(table, "H2", "nmae"), "H4": value(table, "H4", "nmae")}


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("cases", nargs="*", default=["lobovsky", "spheric"])
    parser.add_argument("--out", default=os.path.join(ROOT, "output", "experiment_convergence"))
    parser.add_argument("--flotsam", default=os.path.join(ROOT, "build", "release", "flotsam"))
    parser.add_argument("--ranks", type=int, default=2)
    parser.add_argument("--cells", help="comma-separated cell sizes [m] (default: the case's)")
    parser.add_argument("--settings", default="standard,FOAL1,recommended")
    arguments = parser.parse_args()
    flotsam = os.path.abspath(arguments.flotsam)
    if not os.access(flotsam, os.X_OK):
        sys.exit(f"experiment_convergence.py: no flotsam executable at {flotsam} (scripts/flotsam build)")
    for name in arguments.cases:
        case = SCENES[name]
        experiment = compare_experiment.read_experiment(os.path.join(ROOT, case["data"]))
        measured_levels = (compare_experiment.read_experiment(os.path.join(ROOT, case["levels"]))
                           if "levels" in case else None)
        cells = [float(c) for c in arguments.cells.split(",")] if arguments.cells else case["cells"]
        rows = []
        for setting in arguments.settings.split(","):
            for cell in cells:
                output = os.path.abspath(os.path.join(arguments.out, f"{name}_{setting}_{cell:g}"))
                run(flotsam, arguments.ranks, case["scene"], SETTINGS[setting], cell, output)
                t_run, values = compare_experiment.read_run(output)
                table = compare_experiment.compare(experiment, t_run, values, experiment.times)
                table.to_csv(output + "_comparison.csv", index=False)
                levels = (compare_experiment.compare(measured_levels, t_run, values, measured_levels.times)
                          if measured_levels else None)
                wall, steps = run_facts(output)
                rows.append((setting, cell, errors(name, experiment, table, levels), wall, steps))
        keys = list(rows[0][2])
        print(f"\n{experiment.name}\n")
        print("| setting | h [m] | " + " | ".join(keys) + " | wall time [s] | steps |")
        print("|" + "---|" * (len(keys) + 4))
        for setting, cell, measures, wall, steps in rows:
            cells_text = " | ".join(f"{measures[k]:+.3f}" if k == "arrival" else f"{measures[k]:.3f}" for k in keys)
            print(f"| {setting} | {cell:g} | {cells_text} | {wall:.0f} | {steps} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
