#!/usr/bin/python3
"""Debris hitting a column (inputs/debris_column_2d.nml, debris_column_3d.nml): the column's load, the
block's path, and the peak-load study.

    scripts/debris_column.py run <scene> [--out DIR] [--ranks N] [--flotsam PATH]
    scripts/debris_column.py report <run folder> [<water-only run folder>] [--png FILE]
    scripts/debris_column.py peaks <study output folder>      (inputs/studies/debris_peak.study)

run     runs the scene and the same scene without its 'debris' body (water only) into <out>/debris and
        <out>/water (overrides: output_dir; the water-only scene is the file with the &body 'debris'
        group taken out), then reports both.
report  from loads.csv ('column_f*'), bodies.csv ('debris_*') and the particle fields: the column's peak
        force and its time, the mean force after the impact, the block's smallest distance from the
        column over all outputs (negative: a block particle inside the column) and its rebound
        velocity; with a water-only run, its peak too (what the water alone puts on the column); and
        a plot of the column's force history (both runs) with the block's x velocity.
peaks   one row per case of a finished study: cell size, particles per cell, the column's peak force
        and its time, the impulse on the column within 10 ms of the peak (each row the mean force over
        its interval), the steps and the run's wall time (from the study's results.csv).
Exit status 1 if a run failed or a block particle is inside the column.
"""

import argparse
import csv
import glob
import os
import re
import subprocess
import sys

import h5py
import matplotlib
import numpy as np
import pandas

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "scripts"))
from scene_variant import _group_end  # noqa: E402


def read_csv(path):
    """Column name -> numpy array of a Flotsam CSV (docs/output.md: one pandas call reads it)."""
    return {name: column.to_numpy() for name, column in pandas.read_csv(path, comment="#").items()}


def column_box(folder):
    """(lower, upper) of the &structure 'column' from the run's resolved scene.nml."""
    text = open(os.path.join(folder, "scene.nml")).read()
    for match in re.finditer(r"&structure\b", text, re.IGNORECASE):
        group = text[match.start():_group_end(text, match.start())]
        if re.search(r"name\s*=\s*'column'", group, re.IGNORECASE):
            def reals(name):
                found = re.search(rf"\b{name}\s*=\s*([-+0-9.eE,\s]+?)(?:,\s*[a-z_]+\s*=|\n|$)", group, re.IGNORECASE)
                return np.array([float(v) for v in found.group(1).replace(",", " ").split()])
            dim = int(re.search(r"\bdim\s*=\s*(\d)", text).group(1))
            centre, size = reals("centre")[:dim], reals("size")[:dim]
            return centre - size / 2, centre + size / 2
    raise SystemExit(f"{folder}/scene.nml: no &structure 'column'")


def without_debris(scene, path):
    """The scene file with its &body 'debris' group taken out, written to path."""
    text = open(scene).read()
    for match in re.finditer(r"&body\b", text, re.IGNORECASE):
        end = _group_end(text, match.start())
        if re.search(r"name\s*=\s*'debris'", text[match.start():end], re.IGNORECASE):
            text = text[:match.start()] + text[end + 1:]
            break
    else:
        raise SystemExit(f"{scene}: no &body 'debris'")
    with open(path, "w") as f:
        f.write(text)


def block_distance(folder, lower, upper):
    """Smallest distance of a debris particle from the column box over all outputs (negative: inside),
    and the output where it occurs."""
    worst, where = np.inf, None
    for path in sorted(glob.glob(os.path.join(folder, "fields", "fields_*.h5"))):
        with h5py.File(path) as f:
            x = f["particles/position"][:]
            material = f["particles/material"][:]
            time = float(f.attrs["time"])
        block = x[material == material.max(), :len(lower)]      # wood: the last material of the scene
        outside = np.maximum(lower - block, block - upper)          # > 0 along an axis where outside
        distance = np.where(outside.max(axis=1) > 0, np.linalg.norm(np.maximum(outside, 0), axis=1),
                            outside.max(axis=1))
        if distance.min() < worst:
            worst, where = distance.min(), time
    return worst, where


def report(folder, water=None, png=None):
    loads = read_csv(os.path.join(folder, "loads.csv"))
    bodies = read_csv(os.path.join(folder, "bodies.csv"))
    lower, upper = column_box(folder)
    t, fx = loads["time"], loads["column_fx"]
    peak = int(np.argmax(fx))
    unit = "N/m" if len(lower) == 2 else "N"
    print(f"{folder}: column peak fx {fx[peak]:.1f} {unit} at t = {t[peak]:.4f} s "
          f"(row of {t[1] - t[0]:.4g} s); mean fx over the last 0.3 s {fx[t > t[-1] - 0.3].mean():.1f} {unit}")
    distance, when = block_distance(folder, lower, upper)
    print(f"  block: smallest distance from the column {distance * 1000:+.1f} mm (at t = {when:.2f} s; "
          f"negative = inside); x velocity after the peak: min {bodies['debris_vx'][bodies['time'] > t[peak]].min():+.3f} m/s, "
          f"at the end {bodies['debris_vx'][-1]:+.3f} m/s; end position x {bodies['debris_x'][-1]:.3f} m")
    fig, (ax, bx) = plt.subplots(2, 1, figsize=(7, 5.5), sharex=True, gridspec_kw={"height_ratios": [2, 1]})
    ax.plot(t, fx, lw=0.8, label="water + block")
    if water:
        w = read_csv(os.path.join(water, "loads.csv"))
        wpeak = int(np.argmax(w["column_fx"]))
        print(f"  water only: column peak fx {w['column_fx'][wpeak]:.1f} {unit} at t = {w['time'][wpeak]:.4f} s; "
              f"mean over the last 0.3 s {w['column_fx'][w['time'] > w['time'][-1] - 0.3].mean():.1f} {unit}")
        ax.plot(w["time"], w["column_fx"], lw=0.8, label="water only (no block)")
    ax.set_ylabel(f"column force x [{unit}]")
    with h5py.File(sorted(glob.glob(os.path.join(folder, "fields", "fields_*.h5")))[0]) as f:
        scene = os.path.basename(f.attrs["scene_file"].decode())
    ax.set_title(f"{scene}: loads.csv column_fx ({(t[1] - t[0]) * 1000:.0f} ms rows)")
    ax.legend(fontsize=8)
    bx.plot(bodies["time"], bodies["debris_vx"], color="C2", lw=0.8)
    bx.set_ylabel("block v_x [m/s]")
    bx.set_xlabel("time [s]")
    fig.tight_layout()
    png = png or os.path.join(folder, "column_force.png")
    fig.savefig(png, dpi=120)
    print(f"  wrote {png}")
    return distance >= 0


def run(scene, out, ranks, flotsam):
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    os.makedirs(out, exist_ok=True)
    water_scene = os.path.join(out, "water_only.nml")
    without_debris(scene, water_scene)
    ok = True
    for name, path in (("debris", scene), ("water", water_scene)):
        folder = os.path.join(out, name)
        command = [os.environ.get("FLOTSAM_MPIEXEC") or "mpirun", "-np", str(ranks), flotsam, path,
                   "--set", f"&run output_dir = '{folder}', overwrite = .true., progress_interval = 0.0 /"]
        result = subprocess.run(command, env=env, capture_output=True, text=True)
        print(result.stdout.strip().splitlines()[-1] if result.stdout.strip() else "", result.stderr[-1000:])
        ok = ok and result.returncode == 0
    return ok and report(os.path.join(out, "debris"), os.path.join(out, "water"),
                         os.path.join(out, "column_force.png"))


def peaks(output):
    with open(os.path.join(output, "results.csv")) as f:
        rows = list(csv.DictReader(f))
    print("| cell size [m] | particles per cell | peak column force [N/m] | at t [s] | impulse t_peak ± 10 ms [N s/m] "
          "| steps | wall time [s] | particle-steps/s per core |")
    print("|---|---|---|---|---|---|---|---|")
    for row in rows:
        loads = read_csv(os.path.join(output, "cases", row["case"], "loads.csv"))
        i = int(np.argmax(loads["column_fx"]))
        cell = next(v for k, v in row.items() if k.endswith("cell_size"))
        ppc = next(v for k, v in row.items() if k.endswith("particles_per_cell"))
        t = loads["time"]
        near = np.abs(t - t[i]) <= 0.01 + 1e-9
        impulse = (loads["column_fx"][near] * np.diff(np.concatenate([[0.0], t]))[near]).sum()
        print(f"| {cell} | {ppc} | {loads['column_fx'][i]:.0f} | {t[i]:.3f} | {impulse:.1f} | {row['steps']} | "
              f"{float(row['wall_seconds']):.0f} | {float(row['particle_steps_per_second_per_core']):.3g} |")
    return True


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("command", choices=["run", "report", "peaks"])
    parser.add_argument("paths", nargs="+")
    parser.add_argument("--out", default=os.path.join("output", "debris_column"))
    parser.add_argument("--ranks", type=int, default=2)
    parser.add_argument("--flotsam", default=os.path.join(ROOT, "build", "release", "flotsam"))
    parser.add_argument("--png")
    args = parser.parse_args()
    if args.command == "run":
        ok = run(os.path.abspath(args.paths[0]), os.path.abspath(args.out), args.ranks, args.flotsam)
    elif args.command == "report":
        ok = report(args.paths[0], args.paths[1] if len(args.paths) > 1 else None, args.png)
    else:
        ok = peaks(args.paths[0])
    sys.exit(0 if ok else 1)


if __name__ == "__main__":
    main()
