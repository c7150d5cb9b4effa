#!/usr/bin/python3
"""Hydrograph inflow (issue 18, item 2): an &inlet whose speed, and with height_from_file its height,
follow a time table (tests/runs/scenes/hydrograph/hydrograph.csv: a ramp from rest, a near-step drop
after a breakpoint, a rising and falling height), in whole runs on 2 ranks:

  1. the injected mass (diagnostics.csv total_mass, every 0.05 s) equals rho0 W int_0^t v H dt, computed
     here exactly from the table, to within one particle layer rho0 Dp H: never more, and less by at most
     the last partial layer; with the table's speed only (H = the opening's height) and with its height;
  2. a run stopped at step 560 and continued from its checkpoint at step 500 (before the breakpoints at
     0.6 and 0.61 s) gives diagnostics.csv, loads.csv and the last fields file's particles byte for byte
     the uninterrupted run's;
  3. after the table changes, that restart is refused (velocity_checksum differs) with exit code 2 and
     one line.

usage: check_hydrograph.py <flotsam> <mpiexec> <tests/runs/scenes> <scripts folder>"""

import glob
import os
import shutil

import h5py
import numpy as np
import pandas as pd

from flotsam_run import Checks, Flotsam, checkpoint_at_step, csv_data_lines, main_arguments

RHO = 1000.0
CELL = 0.05
PPC = 2
OPENING = 0.3


def flux_integral(table, t, height_from_file):
    """int_0^t v H dt of the piecewise-linear table (values held outside it): Simpson per piece (exact)."""
    times = table["t"].to_numpy()
    v = lambda s: np.interp(s, times, table["velocity"].to_numpy())
    h = (lambda s: np.interp(s, times, table["height"].to_numpy())) if height_from_file else (lambda s: OPENING)
    cuts = np.unique(np.concatenate([[0.0, t], times[(times > 0.0) & (times < t)]]))
    total = 0.0
    for a, b in zip(cuts[:-1], cuts[1:]):
        m = 0.5 * (a + b)
        total += (b - a) / 6.0 * (v(a) * h(a) + 4.0 * v(m) * h(m) + v(b) * h(b))
    return total


def check_mass(checks, flotsam, scenes, name, height_from_file):
    scene = flotsam.path(name + ".nml")
    with open(os.path.join(scenes, "hydrograph", "hydrograph_2d.nml")) as f:
        text = f.read().replace("output_dir = 'hydrograph'", f"output_dir = '{name}'")
    if height_from_file:
        text = text.replace("velocity_file = 'hydrograph.csv'", "velocity_file = 'hydrograph.csv'\n   height_from_file = .true.")
    with open(scene, "w") as f:
        f.write(text)
    flotsam.remove(name)
    result = flotsam.run(scene, 2)
    if not checks.check(result.returncode == 0, f"{name}: runs on 2 ranks", result.stderr[-2000:]):
        return None
    table = pd.read_csv(flotsam.path("hydrograph.csv"), comment="#")
    rows = pd.read_csv(flotsam.path(name, "diagnostics.csv"), comment="#")
    spacing = CELL / PPC
    worst = 0.0
    within = True
    for t, mass in zip(rows["time"], rows["total_mass"]):
        expected = RHO * flux_integral(table, t, height_from_file)
        h = np.interp(t, table["t"], table["height"]) if height_from_file else OPENING
        layer = RHO * spacing * max(h, table["height"].max() if height_from_file else OPENING)
        deficit = (expected - mass) / (RHO * spacing * h)
        worst = max(worst, deficit)
        # never more than entered (a layer due at exactly t may come 1e-9 of a layer early: round-off)
        within &= -1e-6 * layer <= expected - mass <= layer
        print(f"   {name}: t = {t:.2f} s  mass {mass:.6f}  rho int v H dt {expected:.6f}  "
              f"short by {deficit:.4f} layers rho Dp H(t)", flush=True)
    final_expected = RHO * flux_integral(table, rows["time"].iloc[-1], height_from_file)
    checks.check(within and rows["total_mass"].iloc[-1] > 0.5 * final_expected,
                 f"{name}: injected mass = rho int v H dt within one particle layer at all {len(rows)} output "
                 f"times (at t = 1 s: {rows['total_mass'].iloc[-1]:.4f} of {final_expected:.4f} kg/m; "
                 f"largest shortfall {worst:.3f} x rho Dp H(t))")
    return flotsam.path(name)


def last_particles(directory):
    path = sorted(glob.glob(os.path.join(directory, "fields", "fields_*.h5")))[-1]
    with h5py.File(path) as f:
        ids = f["particles/id"][()]
        order = np.argsort(ids)
        return os.path.basename(path), {key: f[f"particles/{key}"][()][order]
                                        for key in ["id", "position", "velocity", "mass", "pressure"]
                                        if f"particles/{key}" in f}


def check_restart(checks, flotsam, reference):
    scene = flotsam.path("height.nml")
    with open(scene) as f:
        text = f.read()
    split = text.replace("output_dir = 'height'", "output_dir = 'height_split'").replace(
        "floor_size = 1.0", "floor_size = 1.0\n   checkpoint_interval_steps = 100\n   max_steps = 560")
    with open(flotsam.path("height_split.nml"), "w") as f:
        f.write(split)
    flotsam.remove("height_split")
    result = flotsam.run(flotsam.path("height_split.nml"), 2)
    if not checks.check(result.returncode == 0, "restart: the hydrograph run stopped at step 560",
                        result.stderr[-2000:]):
        return
    checkpoint, time = checkpoint_at_step(flotsam, "height_split", 500)
    if not checks.check(checkpoint is not None, "restart: a checkpoint at step 500"):
        return
    checks.check(time < 0.6, f"restart: the checkpoint (t = {time:.4f} s) lies before the breakpoints at 0.6 and 0.61 s")
    with open(flotsam.path("height_continue.nml"), "w") as f:
        f.write(text.replace("output_dir = 'height'", "output_dir = 'height_split'"))
    result = flotsam.run(flotsam.path("height_continue.nml"), 2, "--restart", checkpoint)
    if not checks.check(result.returncode == 0, "restart: continued from the checkpoint at step 500",
                        result.stderr[-2000:]):
        return
    for name in ["diagnostics.csv", "loads.csv"]:
        rows = csv_data_lines(flotsam.path("height_split", name))
        expected = csv_data_lines(os.path.join(reference, name))
        checks.check(rows == expected and len(rows) > 10,
                     f"restart: {name} byte for byte the uninterrupted run's ({len(expected)} lines)",
                     f"{len(rows)} lines")
    file_a, a = last_particles(reference)
    file_b, b = last_particles(flotsam.path("height_split"))
    checks.check(file_a == file_b and all(np.array_equal(a[k], b[k]) for k in a) and a["id"].size > 100,
                 f"restart: {file_a}'s {a['id'].size} particles (ids, positions, velocities, masses) bit for bit")
    # the table changes: one speed 1 % larger
    original = open(flotsam.path("hydrograph.csv")).read()
    with open(flotsam.path("hydrograph.csv"), "w") as f:
        f.write(original.replace("0.3,0.8,0.20", "0.3,0.808,0.20"))
    result = flotsam.run(flotsam.path("height_continue.nml"), 2, "--restart", checkpoint)
    with open(flotsam.path("hydrograph.csv"), "w") as f:
        f.write(original)
    errors = [line for line in result.stderr.splitlines() if "flotsam: error:" in line]
    checks.check(result.returncode == 2 and len(errors) == 1 and "velocity_checksum" in errors[0],
                 "restart: refused after the table changed (exit 2, one line naming velocity_checksum)",
                 f"exit {result.returncode}: {errors}")


def main():
    flotsam_path, mpiexec, scenes, _ = main_arguments()
    checks = Checks()
    flotsam = Flotsam(flotsam_path, mpiexec, "hydrograph")
    shutil.copy(os.path.join(scenes, "hydrograph", "hydrograph.csv"), flotsam.path("hydrograph.csv"))
    check_mass(checks, flotsam, scenes, "speed", False)
    reference = check_mass(checks, flotsam, scenes, "height", True)
    if reference:
        check_restart(checks, flotsam, reference)
    return checks.summary()


if __name__ == "__main__":
    raise SystemExit(main())
