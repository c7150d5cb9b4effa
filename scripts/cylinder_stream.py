#!/usr/bin/python3
"""Drag on a fixed cylinder in a steady stream (inputs/cylinder_stream.nml) at three resolutions.

    scripts/cylinder_stream.py [--flotsam PATH] [--ranks N] [--out DIR] [--cells 0.04,0.02,0.01]
                               [--window 1.0,2.0] [--report]

Runs the scene once per cell size (command-line overrides only: cell_size and output_dir) into
<out>/h_<cell size>/, then from each run's loads.csv ('cylinder_fx', 'cylinder_fy': the mean force over
each 10 ms row) the mean drag and its fluctuation (standard deviation of the rows) over the window
after the transient, the drag coefficient C_D = F / (0.5 rho U^2 D) and the mean lift. Writes
<out>/cylinder_stream.md (the table of docs/contact.md) and <out>/cylinder_stream.png (drag histories).
--report reads the runs already there without running anything. Exit status 1 if a run failed.
"""

import argparse
import os
import subprocess
import sys
import time

import matplotlib
import numpy as np

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "scripts"))
from debris_column import read_csv  # noqa: E402
SCENE = os.path.join(ROOT, "inputs", "cylinder_stream.nml")
RHO, U, RADIUS = 1000.0, 1.0, 0.1      # the scene's density, inlet speed and cylinder radius


def wall_seconds(folder):
    """The run's wall time from run_summary.csv (its last row)."""
    return float(read_csv(os.path.join(folder, "run_summary.csv"))["wall_seconds"][-1])


def run(flotsam, ranks, cell, folder):
    command = [os.environ.get("FLOTSAM_MPIEXEC") or "mpirun", "-np", str(ranks), flotsam, SCENE,
               "--set", f"&grid cell_size = {cell} /",
               "--set", f"&run output_dir = '{folder}', overwrite = .true., progress_interval = 0.0 /"]
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    start = time.time()
    result = subprocess.run(command, env=env, capture_output=True, text=True)
    if result.returncode != 0:
        print(result.stderr[-2000:], file=sys.stderr)
    return result.returncode, time.time() - start


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--flotsam", default=os.path.join(ROOT, "build", "release", "flotsam"))
    parser.add_argument("--ranks", type=int, default=2)
    parser.add_argument("--out", default=os.path.join("output", "cylinder_stream_study"))
    parser.add_argument("--cells", default="0.04,0.02,0.01")
    parser.add_argument("--window", default="1.0,2.0", help="t0,t1 [s] of the averaging window")
    parser.add_argument("--report", action="store_true")
    args = parser.parse_args()
    cells = [float(c) for c in args.cells.split(",")]
    t0, t1 = (float(t) for t in args.window.split(","))
    out = os.path.abspath(args.out)
    os.makedirs(out, exist_ok=True)
    lines = ["| h [m] | R/h | run time [s] | mean drag F [N/m] | fluctuation (std) [N/m] | "
             "C_D = F / (0.5 rho U^2 D) | mean drag, 1st / 2nd half of the window [N/m] | mean lift [N/m] |",
             "|---|---|---|---|---|---|---|---|"]
    fig, ax = plt.subplots(figsize=(7, 4))
    failed = 0
    for cell in cells:
        folder = os.path.join(out, f"h_{cell}")
        seconds = float("nan")
        if not args.report:
            code, seconds = run(args.flotsam, args.ranks, cell, folder)
            failed += code != 0
            print(f"h = {cell}: exit {code}, {seconds:.0f} s", flush=True)
            if code != 0:
                continue
        loads = read_csv(os.path.join(folder, "loads.csv"))
        if args.report:
            seconds = wall_seconds(folder)
        t, fx, fy = loads["time"], loads["cylinder_fx"], loads["cylinder_fy"]
        window = (t > t0 + 1e-9) & (t <= t1 + 1e-9)
        mean, std = fx[window].mean(), fx[window].std()
        middle = 0.5 * (t0 + t1)
        halves = fx[window & (t <= middle + 1e-9)].mean(), fx[window & (t > middle + 1e-9)].mean()
        cd = mean / (0.5 * RHO * U * U * 2 * RADIUS)
        lines.append(f"| {cell} | {RADIUS / cell:.1f} | {seconds:.0f} | {mean:.1f} | {std:.1f} ({std / mean:.1%}) | "
                     f"{cd:.2f} | {halves[0]:.1f} / {halves[1]:.1f} | {fy[window].mean():+.1f} |")
        print(lines[-1], flush=True)
        ax.plot(t, fx, lw=0.8, label=f"h = {cell} m (R/h = {RADIUS / cell:.1f})")
    ax.axvspan(t0, t1, color="0.9", zorder=0, label="averaging window")
    ax.set_xlabel("time [s]")
    ax.set_ylabel("drag on the cylinder [N/m]")
    ax.set_title("Cylinder in a stream (inputs/cylinder_stream.nml), loads.csv cylinder_fx")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(out, "cylinder_stream.png"), dpi=120)
    with open(os.path.join(out, "cylinder_stream.md"), "w") as f:
        f.write(f"window {t0} .. {t1} s\n\n" + "\n".join(lines) + "\n")
    print(os.path.join(out, "cylinder_stream.md"))
    sys.exit(1 if failed else 0)


if __name__ == "__main__":
    main()
