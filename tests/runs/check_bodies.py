#!/usr/bin/python3
"""Bodies of any shape and bodies read from files of points (issue 15, item 2), in whole runs:

  1. a point file that lists a box's lattice (CSV with '#' comment lines and an extra column, read the
     same by pandas; and HDF5 with datasets position (n, 2) and volume (n)) gives the box's particles and
     the box's results: the fields files' particles and bodies.csv agree with the box run to round-off
     (1e-12; bit for bit in the Debug build), on 2 ranks;
  2. an elastic disk (shape = 'circle') dropped on the floor, on 1, 2 and 4 ranks: bodies.csv agrees to
     1e-10 (check_loads.py's comparison); it falls freely (y = y0 - g t^2/2 within 1e-3 m before it lands),
     rebounds (vy > 0 after the landing) and does not sink into the floor by more than one cell;
  3. an elastic sphere (shape = 'sphere') dropped in 3-D, on 1, 2 and 4 ranks: the same;
  4. restart of the point-file block: stopped at max_steps and continued from its checkpoint, bodies.csv
     equals the uninterrupted run byte for byte; after the points file changes, the restart is refused
     (points_checksum differs) on every rank, with exit code 2;
  5. a points file in HDF5 that lacks its volume dataset, and one with a position of 3 components per
     point but a NaN: one-line errors naming the file, no output folder.

usage: check_bodies.py <flotsam> <mpiexec> <tests/runs/scenes> <scripts folder>"""

import glob
import os
import re

import h5py
import numpy as np
import pandas as pd

from check_loads import agreement, read
from flotsam_run import Checks, Flotsam, checkpoint_at_step, main_arguments

G = 9.81


def lattice_of_box(lower, upper, cell_size, ppc):
    """The lattice seed_bodies gives an unrotated box (body_lattice.f90): positions (n, 2), volumes (n)."""
    lower, upper = np.array(lower), np.array(upper)
    n = np.rint((upper - lower) / (cell_size / ppc)).astype(int)
    spacing = (upper - lower) / n
    j, i = np.meshgrid(np.arange(n[1]), np.arange(n[0]), indexing="ij")      # x fastest, as the ids
    x = lower[0] + (i.ravel() + 0.5) * spacing[0]
    y = lower[1] + (j.ravel() + 0.5) * spacing[1]
    return np.column_stack([x, y]), np.full(x.size, spacing[0] * spacing[1])


def particles(directory, index):
    """Particles of fields file `index` ordered by id: id, position, velocity, mass."""
    with h5py.File(os.path.join(directory, "fields", f"fields_{index:06d}.h5")) as f:
        ids = f["particles/id"][()]
        order = np.argsort(ids)
        return {name: f[f"particles/{name}"][()][order] for name in ["id", "position", "velocity", "mass"]}


def bodies_rows(directory):
    with open(os.path.join(directory, "bodies.csv")) as f:
        return [line for line in f.read().splitlines() if not line.startswith("#")]


def check_points_reproduce_box(checks, flotsam, scenes):
    template = os.path.join(scenes, "bodies", "block_2d.nml")
    with open(template) as f:
        text = f.read()
    box_line = "lower = 0.31, 0.4, upper = 0.63, 0.57"
    position, volume = lattice_of_box([0.31, 0.4], [0.63, 0.57], 0.05, 2)
    # CSV: comment lines, columns in another order and one more column, numbers that read back exactly
    with open(flotsam.path("block_points.csv"), "w") as f:
        f.write("# the lattice of the block of block_2d.nml\n# one line per particle\n"
                "volume,id,x,y\n")
        for k in range(len(volume)):
            f.write(f"{volume[k]!r},{k},{position[k, 0]!r},{position[k, 1]!r}\n")
    table = pd.read_csv(flotsam.path("block_points.csv"), comment="#", float_precision="round_trip")
    checks.check(np.array_equal(table[["x", "y"]].to_numpy(), position) and
                 np.array_equal(table["volume"].to_numpy(), volume),
                 f"points: the CSV of {len(volume)} points reads back exactly with pandas.read_csv(comment='#')")
    with h5py.File(flotsam.path("block_points.h5"), "w") as f:
        f["position"] = position
        f["volume"] = volume
    runs = {}
    for name, body in [("block_box", box_line), ("block_csv", "points_file = 'block_points.csv'"),
                       ("block_h5", "points_file = 'block_points.h5'")]:
        flotsam.remove(name)
        path = flotsam.path(name + ".nml")
        with open(path, "w") as f:
            f.write(re.sub(r"output_dir\s*=\s*'[^']*'", f"output_dir = '{name}'", text.replace(box_line, body)))
        result = flotsam.run(path, 2)
        if checks.check(result.returncode == 0, f"points: {name} on 2 ranks", result.stderr[-2000:]):
            runs[name] = flotsam.path(name)
    if "block_box" not in runs:
        return
    box = runs["block_box"]
    outputs = len(glob.glob(os.path.join(box, "fields", "fields_*.h5")))
    for name in ["block_csv", "block_h5"]:
        if name not in runs:
            continue
        worst, bitwise = 0.0, True
        for index in range(outputs):
            a, b = particles(box, index), particles(runs[name], index)
            if not np.array_equal(a["id"], b["id"]):
                worst = np.inf
                break
            for field in ["position", "velocity", "mass"]:
                scale = max(np.abs(a[field]).max(), 1e-300)
                worst = max(worst, np.abs(a[field] - b[field]).max() / scale)
                bitwise = bitwise and np.array_equal(a[field], b[field])
        checks.check(worst <= 1e-12, f"points: {name}'s particles (ids, positions, velocities, masses) in all "
                                     f"{outputs} outputs equal the box's: largest difference {worst:.1e} of the "
                                     f"largest value, {'bit for bit' if bitwise else 'to round-off'}")
        reference, other = read(box, "bodies"), read(runs[name], "bodies")
        difference = np.abs(reference.to_numpy() - other.to_numpy()).max() if reference.shape == other.shape \
            else np.inf
        checks.check(reference.shape == other.shape and list(reference.columns) == list(other.columns) and
                     difference <= 1e-12 * np.abs(reference.to_numpy()).max(),
                     f"points: {name}'s bodies.csv equals the box's ({len(reference)} rows, largest difference "
                     f"{difference:.1e}, {'bit for bit' if bodies_rows(box) == bodies_rows(runs[name]) else 'round-off'})")
    return runs.get("block_csv")


def check_drop(checks, flotsam, scenes, scene, body, dim, radius, cell):
    """A dropped elastic disk / sphere on 1, 2 and 4 ranks."""
    template = os.path.join(scenes, "bodies", scene + ".nml")
    runs = {}
    for ranks in (1, 2, 4):
        name = f"{scene}_np{ranks}"
        flotsam.remove(name)
        path = flotsam.scene(template, name + ".nml", name)
        result = flotsam.run(path, ranks)
        if checks.check(result.returncode == 0, f"{scene}: run on {ranks} ranks", result.stderr[-2000:]):
            runs[ranks] = flotsam.path(name)
    if 2 not in runs:
        return
    reference = read(runs[2], "bodies")
    for ranks in (1, 4):
        if ranks in runs:
            agreement(checks, "bodies", reference, read(runs[ranks], "bodies"), f"{scene}: {ranks} ranks against 2")
    up = f"{body}_{'y' if dim == 2 else 'z'}"
    velocity = f"{body}_v{'y' if dim == 2 else 'z'}"
    height = reference[up].to_numpy()
    time = reference["time"].to_numpy()
    start = 0.4 if dim == 2 else 0.25                       # centre of the shape in the scene
    landing = np.sqrt(2 * (start - radius) / G)
    # the floor acts once the lowest particles' nodes reach it: one cell before the shape touches it
    free = time < np.sqrt(2 * (start - radius - cell) / G)
    fall = np.abs(height[free] - (start - G * time[free] ** 2 / 2)).max()
    checks.check(free.sum() > 5 and fall <= 1e-3,
                 f"{scene}: free fall before the landing at {landing:.3f} s: centroid within {fall:.1e} m of "
                 f"y0 - g t^2/2 ({free.sum()} rows)")
    checks.check((reference[velocity].to_numpy()[time > landing] > 0).any(),
                 f"{scene}: it rebounds (upward velocity after the landing, up to "
                 f"{reference[velocity].max():.3f} m/s)")
    checks.check(height.min() >= radius - cell,
                 f"{scene}: lowest centroid {height.min():.4f} m: no deeper into the floor than one cell "
                 f"(radius {radius} m, cell {cell} m)")


def check_restart(checks, flotsam, csv_run):
    """The point-file block stopped and continued; then a changed points file."""
    scene = flotsam.path("block_csv.nml")
    with open(scene) as f:
        text = f.read()
    split = text.replace("output_dir = 'block_csv'", "output_dir = 'block_split'").replace(
        "load_interval = 0.005", "load_interval = 0.005\n   checkpoint_interval_steps = 100\n   max_steps = 250")
    with open(flotsam.path("block_split.nml"), "w") as f:
        f.write(split)
    flotsam.remove("block_split")
    result = flotsam.run(flotsam.path("block_split.nml"), 2)
    if not checks.check(result.returncode == 0, "restart: the points block stopped at step 250",
                        result.stderr[-2000:]):
        return
    checkpoint, _ = checkpoint_at_step(flotsam, "block_split", 200)
    if not checks.check(checkpoint is not None, "restart: a checkpoint at step 200"):
        return
    with open(flotsam.path("block_continue.nml"), "w") as f:
        f.write(text.replace("output_dir = 'block_csv'", "output_dir = 'block_split'"))
    result = flotsam.run(flotsam.path("block_continue.nml"), 2, "--restart", checkpoint)
    checks.check(result.returncode == 0, "restart: continued from the checkpoint at step 200", result.stderr[-2000:])
    rows, expected = bodies_rows(flotsam.path("block_split")), bodies_rows(csv_run)
    checks.check(rows == expected and len(rows) > 10,
                 f"restart: bodies.csv byte for byte the uninterrupted run's ({len(expected)} rows)",
                 f"{len(rows)} rows")
    # the points change: one volume 1 % larger
    table = open(flotsam.path("block_points.csv")).read().splitlines()
    fields = table[3].split(",")
    fields[0] = repr(float(fields[0]) * 1.01)
    table[3] = ",".join(fields)
    with open(flotsam.path("block_points.csv"), "w") as f:
        f.write("\n".join(table) + "\n")
    result = flotsam.run(flotsam.path("block_continue.nml"), 2, "--restart", checkpoint)
    errors = [line for line in result.stderr.splitlines() if "flotsam: error:" in line]
    checks.check(result.returncode == 2 and len(errors) == 1 and "points_checksum" in errors[0],
                 "restart: refused after the points file changed (exit 2, one line naming points_checksum)",
                 f"exit {result.returncode}: {errors}")


def check_hdf5_errors(checks, flotsam, scenes):
    template = os.path.join(scenes, "bodies", "block_2d.nml")
    with open(template) as f:
        text = f.read()
    box_line = "lower = 0.31, 0.4, upper = 0.63, 0.57"
    with h5py.File(flotsam.path("no_volume.h5"), "w") as f:
        f["position"] = np.array([[0.5, 0.5], [0.55, 0.5]])
    with h5py.File(flotsam.path("nan_point.h5"), "w") as f:
        f["position"] = np.array([[0.5, 0.5, 0.0], [np.nan, 0.5, 0.0]])
        f["volume"] = np.array([1e-3, 1e-3])
    for name, expected in [("no_volume", "no_volume.h5: no dataset volume"),
                           ("nan_point", "nan_point.h5: point 1 (0-based) is not finite")]:
        flotsam.remove(name)
        path = flotsam.path(name + ".nml")
        with open(path, "w") as f:
            f.write(re.sub(r"output_dir\s*=\s*'[^']*'", f"output_dir = '{name}'",
                           text.replace(box_line, f"points_file = '{name}.h5'")))
        result = flotsam.run(path, 2)
        errors = [line for line in result.stderr.splitlines() if "flotsam: error:" in line]
        checks.check(result.returncode == 2 and len(errors) == 1 and expected in errors[0] and
                     "group &body (2nd, name 'block', material 'wood'): variable points_file" in errors[0] and
                     not os.path.exists(flotsam.path(name)),
                     f"points: {name}.h5 refused with one line naming the scene, the body and the file, "
                     "no output folder", f"exit {result.returncode}: {errors}")


def main():
    flotsam_path, mpiexec, scenes, _ = main_arguments()
    checks = Checks()
    flotsam = Flotsam(flotsam_path, mpiexec, "bodies")
    csv_run = check_points_reproduce_box(checks, flotsam, scenes)
    if csv_run:
        check_restart(checks, flotsam, csv_run)
    check_hdf5_errors(checks, flotsam, scenes)
    check_drop(checks, flotsam, scenes, "disk_2d", "disk", 2, 0.15, 0.05)
    check_drop(checks, flotsam, scenes, "sphere_3d", "ball", 3, 0.12, 0.05)
    return checks.summary()


if __name__ == "__main__":
    raise SystemExit(main())
