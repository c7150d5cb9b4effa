#!/usr/bin/python3
"""The HDF5 fields files and XDMF time series of a run, read back with h5py and meshio and checked
against the run's own diagnostics.csv: one fields file per diagnostics row at the same time and step,
particle counts, total mass, kinetic energy, fluid volume and maximum speed recomputed from the
particle fields, unique ids, positions in the world frame, consistent stress fields, a grid whose nodal
mass sums to the total mass, the largest rank's share (max_rank_share) from the particles' ranks, and
the XDMF files listing every output time. The 2-D scene runs on 3 ranks of which one holds no particle
(load balancing off); the 3-D scene on 2 ranks, balanced: no rank holds more than 60 % of the
particles at any output. The run's timing.csv: every phase of the time loop, adding up to the loop's
wall time, with nothing charged to the smoothing phase of a scene without smoothing. A jet whose
particle count grows (moving_box_2d): meshio's TimeSeriesReader and scripts/particle_series.py give
every output its own particles. Also runs scripts/plot_diagnostics.py.

usage: check_output.py <flotsam> <mpiexec> <tests/runs/scenes> <scripts folder>"""

import csv
import os
import subprocess
import sys
from xml.etree import ElementTree

import h5py
import meshio
import numpy as np

from flotsam_run import Checks, Flotsam, main_arguments, read_diagnostics


def check_run(checks, flotsam, scenes, name, ranks, fluid_materials, empty_rank=None):
    flotsam.remove(name)
    scene = flotsam.scene(os.path.join(scenes, name + ".nml"), name + ".nml", name)
    result = flotsam.run(scene, ranks)
    if not checks.check(result.returncode == 0, f"{name}: run on {ranks} ranks", result.stderr[-2000:]):
        return
    rows = read_diagnostics(flotsam.path(name))
    directory = flotsam.path(name)
    with open(scene) as f:
        text = f.read()
    dim = 3 if "dim = 3" in text else 2
    check_timing(checks, name, directory, smoothed="stabilization" in text and "FOAL1" in text)

    for index, row in enumerate(rows):
        label = f"{name} output {index}"
        path = os.path.join(directory, "fields", f"fields_{index:06d}.h5")
        if not checks.check(os.path.exists(path), f"{label}: fields file exists"):
            continue
        with h5py.File(path) as f:
            checks.close(f.attrs["time"], float(row["time"]), 1e-15, f"{label}: time")
            checks.check(int(f.attrs["step"]) == int(row["step"]), f"{label}: step")
            p = f["particles"]
            n = int(row["particles"])
            checks.check(p["position"].shape == (n, 3) and p["stress"].shape == (n, 9),
                         f"{label}: {n} particles with 3 coordinates and 9 stress components",
                         f"{p['position'].shape}, {p['stress'].shape}")
            mass, velocity, volume, density = p["mass"][:], p["velocity"][:], p["volume"][:], p["density"][:]
            material, ids, rank = p["material"][:], p["id"][:], p["rank"][:]
            checks.close(mass.sum(), float(row["total_mass"]), 1e-12, f"{label}: total mass")
            checks.close(0.5 * (mass * (velocity ** 2).sum(axis=1)).sum(), float(row["kinetic_energy"]), 1e-10,
                         f"{label}: kinetic energy")
            fluid = np.isin(material, fluid_materials)
            checks.close(volume[fluid].sum(), float(row["fluid_volume"]), 1e-10, f"{label}: fluid volume")
            checks.close(np.sqrt((velocity ** 2).sum(axis=1).max()), float(row["max_speed"]), 1e-12,
                         f"{label}: max speed")
            checks.check(np.allclose(volume, mass / density, rtol=1e-14), f"{label}: volume = mass / density")
            checks.check(np.array_equal(np.sort(ids), np.arange(n)), f"{label}: ids unique, 0 .. N-1")
            checks.check(np.array_equal(p["connectivity"][:], np.arange(n)), f"{label}: connectivity 0 .. N-1")
            if n > 0:
                checks.close(np.bincount(rank).max() / n, float(row["max_rank_share"]), 1e-15,
                             f"{label}: max_rank_share = largest count in /particles/rank / N")
            if ranks == 2 and empty_rank is None:     # load balancing on (the default)
                checks.check(float(row["max_rank_share"]) <= 0.6, f"{label}: no rank holds more than 60 %",
                             row["max_rank_share"])
            if empty_rank is not None:
                checks.check(empty_rank not in rank and set(rank) <= set(range(ranks)),
                             f"{label}: rank {empty_rank} held no particle and still wrote", f"{set(rank)}")
            stress = p["stress"][:].reshape(n, 3, 3)
            checks.check(np.allclose(stress, stress.transpose(0, 2, 1), rtol=0, atol=0), f"{label}: stress symmetric")
            checks.check(np.allclose(p["mean_stress"][:], np.trace(stress, axis1=1, axis2=2) / 3, rtol=1e-13,
                                     atol=1e-9), f"{label}: mean stress = trace / 3")
            position = p["position"][:]
            if dim == 2:
                checks.check(not position[:, 2].any() and not velocity[:, 2].any() and
                             not stress[:, 2, 0:2].any(), f"{label}: z = 0 in 2-D")
            g = f["grid"]
            checks.close(g["node/mass"][:].sum(), float(row["total_mass"]), 1e-10, f"{label}: grid mass")
            node_dims = g["node/mass"].shape
            checks.check(g["node/velocity"].shape == node_dims + (3,), f"{label}: nodal velocity shape")
            densities = [k for k in g["cell"] if k.startswith("density_")]
            for key in densities:
                cells = g["cell"][key][:]
                checks.check(cells.shape == tuple(max(d - 1, 1) for d in node_dims),
                             f"{label}: {key} on the cells", f"{cells.shape} for nodes {node_dims}")
                filled = cells[np.isfinite(cells)]
                checks.check(filled.size > 0 and np.all(filled > 0), f"{label}: {key} positive where present")

    # the particle time series, as meshio reads it
    with meshio.xdmf.TimeSeriesReader(os.path.join(directory, "particles.xmf")) as reader:
        points, cells = reader.read_points_cells()
        times = [reader.read_data(k)[0] for k in range(reader.num_steps)]
        checks.check(reader.num_steps == len(rows), f"{name} particles.xmf: one step per diagnostics row",
                     f"{reader.num_steps} steps, {len(rows)} rows")
        checks.check(np.allclose(times, [float(r["time"]) for r in rows], rtol=1e-15, atol=0),
                     f"{name} particles.xmf: the diagnostics times")
        checks.check(points.shape == (int(rows[0]["particles"]), 3) and cells[0].type == "vertex",
                     f"{name} particles.xmf: point cloud of vertices", f"{points.shape}, {cells[0].type}")
        _, point_data, _ = reader.read_data(reader.num_steps - 1)
        checks.check({"velocity", "stress", "mean_stress", "density", "id", "rank"} <= set(point_data),
                     f"{name} particles.xmf: arrays", f"{sorted(point_data)}")

    # the grid time series (a structured mesh, which meshio does not read): times and data items. Each
    # member of the temporal collection is a spatial collection of one uniform grid (docs/output.md).
    root = ElementTree.parse(os.path.join(directory, "grid.xmf")).getroot()
    members = list(root.find(".//Grid[@CollectionType='Temporal']"))
    times = [float(m.find("Time").get("Value")) for m in members]
    checks.check(np.allclose(times, [float(r["time"]) for r in rows], rtol=1e-15, atol=0),
                 f"{name} grid.xmf: one grid per diagnostics time", f"{times}")
    checks.check(all(m.get("CollectionType") == "Spatial" and len(m.findall("Grid[@GridType='Uniform']")) == 1
                     for m in members), f"{name} grid.xmf: each time one uniform grid in a spatial collection")
    grids = [m if m.get("GridType") == "Uniform" else m.find("Grid") for m in members]
    shapes_agree = True
    for g in grids:
        for item in g.iter("DataItem"):
            if item.get("Format") != "HDF":
                continue
            file, dataset = item.text.split(":")
            with h5py.File(os.path.join(directory, file)) as f:
                shapes_agree &= f[dataset].shape == tuple(int(d) for d in item.get("Dimensions").split())
    checks.check(shapes_agree, f"{name} grid.xmf: every data item has the shape of its dataset")


def check_particle_series(checks, flotsam, scenes, scripts):
    """moving_box_2d: the particle count grows with the inflow. meshio's TimeSeriesReader must give every
    output's own particles (the array `position`, as many rows as every other array), and so must
    scripts/particle_series.py (a meshio.Mesh per output), equal to the fields files."""
    name = "moving_box_2d"
    flotsam.remove(name)
    scene = flotsam.scene(os.path.join(scenes, name + ".nml"), name + ".nml", name)
    result = flotsam.run(scene, 2)
    if not checks.check(result.returncode == 0, f"{name}: run on 2 ranks", result.stderr[-2000:]):
        return
    directory = flotsam.path(name)
    rows = read_diagnostics(directory)
    counts = [int(r["particles"]) for r in rows]
    checks.check(len(set(counts)) == len(counts), f"{name}: the particle count changes at every output",
                 f"{counts}")
    stored = []
    for index in range(len(rows)):
        with h5py.File(os.path.join(directory, "fields", f"fields_{index:06d}.h5")) as f:
            stored.append((f["particles/position"][:], f["particles/mean_stress"][:]))

    with meshio.xdmf.TimeSeriesReader(os.path.join(directory, "particles.xmf")) as reader:
        reader.read_points_cells()
        for k in range(reader.num_steps):
            time, point_data, _ = reader.read_data(k)
            position, mean_stress = stored[k]
            checks.check("position" in point_data and np.array_equal(point_data["position"], position),
                         f"{name} meshio step {k} (t = {time}): the output's {counts[k]} particle positions",
                         f"arrays {sorted(point_data)}, {len(point_data.get('position', []))} positions")
            checks.check(all(len(v) == counts[k] for v in point_data.values()) and
                         np.array_equal(point_data["mean_stress"], mean_stress),
                         f"{name} meshio step {k}: every array has {counts[k]} rows",
                         f"{ {key: len(v) for key, v in point_data.items()} }")

    sys.path.insert(0, scripts)
    try:
        from particle_series import particle_steps
        steps = list(particle_steps(directory))
    except Exception as error:          # reported as a failed check, not a crash of the test
        steps = []
        checks.check(False, f"{name}: scripts/particle_series.py reads the series", repr(error))
    for k, (time, mesh) in enumerate(steps):
        position, mean_stress = stored[k]
        checks.check(time == float(rows[k]["time"]) and np.array_equal(mesh.points, position) and
                     np.array_equal(mesh.cells[0].data.ravel(), np.arange(counts[k])) and
                     np.array_equal(mesh.point_data["mean_stress"], mean_stress),
                     f"{name} particle_series.py step {k}: time, {counts[k]} points, vertex cells, arrays",
                     f"t = {time}, points {mesh.points.shape}")
    checks.check(len(steps) == len(rows), f"{name} particle_series.py: one mesh per output",
                 f"{len(steps)} meshes, {len(rows)} outputs")


PHASES = ["particles_to_grid", "grid_update", "walls", "stabilization", "grid_to_particles", "constitutive",
          "inflow", "node_halo", "migration", "sort", "time_step", "health_check", "diagnostics", "output",
          "checkpoint", "rebalance", "volume_correction", "loads", "other"]


def check_timing(checks, name, directory, smoothed):
    """timing.csv against run_summary.csv (docs/output.md)."""
    with open(os.path.join(directory, "timing.csv"), newline="") as f:
        rows = {row["phase"]: row for row in csv.DictReader(f)}
    with open(os.path.join(directory, "run_summary.csv"), newline="") as f:
        summary = next(csv.DictReader(f))
    if not checks.check(list(rows) == PHASES + ["total"], f"{name} timing.csv: one row per phase and the total",
                        f"{list(rows)}"):
        return
    mean = {phase: float(row["seconds_mean"]) for phase, row in rows.items()}
    largest = {phase: float(row["seconds_max"]) for phase, row in rows.items()}
    checks.check(all(0 <= mean[p] <= largest[p] for p in PHASES), f"{name} timing.csv: 0 <= mean <= max")
    checks.close(sum(mean[p] for p in PHASES), mean["total"], 1e-9, f"{name} timing.csv: phases add up to the total")
    wall = float(summary["wall_seconds"])
    checks.check(0.5 * wall <= largest["total"] <= wall + 0.05, f"{name} timing.csv: total within the run's wall time",
                 f"{largest['total']} s of {wall} s")
    checks.check(mean["particles_to_grid"] > 0 and mean["grid_to_particles"] > 0, f"{name} timing.csv: the transfers")
    if not smoothed:
        # two clock reads per step; the margin is for the rank being descheduled between them on a busy machine
        checks.check(largest["stabilization"] < 0.01 * largest["total"] + 0.005,
                     f"{name} timing.csv: no smoothing, no time for it",
                     f"{largest['stabilization']} s of {largest['total']} s")


def main():
    flotsam_path, mpiexec, scenes, rest = main_arguments()
    checks = Checks()
    flotsam = Flotsam(flotsam_path, mpiexec, "output")
    check_run(checks, flotsam, scenes, "two_materials_2d", 3, fluid_materials=[1], empty_rank=2)
    check_run(checks, flotsam, scenes, "column_3d", 2, fluid_materials=[1])
    if rest:
        check_particle_series(checks, flotsam, scenes, os.path.abspath(rest[0]))

    # the matplotlib script plots the diagnostics of a run
    if rest:
        picture = flotsam.path("diagnostics.png")
        if os.path.exists(picture):
            os.remove(picture)
        result = subprocess.run([sys.executable, os.path.join(rest[0], "plot_diagnostics.py"),
                                 flotsam.path("two_materials_2d"), "-o", picture], capture_output=True, text=True)
        checks.check(result.returncode == 0 and os.path.getsize(picture) > 10000,
                     "plot_diagnostics.py draws the diagnostics", result.stderr[-1000:])
    return checks.summary()


if __name__ == "__main__":
    raise SystemExit(main())
