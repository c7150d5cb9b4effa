#!/usr/bin/python3
"""Short versions of the paper's scenes (inputs/tank_filling.nml, hydrostatic_tank.nml at 45 degrees,
floating_block.nml) and of the debris scenes (debris_column_2d.nml, debris_column_3d.nml), run from the
files themselves with only the end time, the output folder and (debris: a smoke run in Debug) the cell
size changed (scripts/scene_variant.py), and checked for: mass conservation, the inflow mass flux
rho v0 H (within 1 %, and layer by layer), no particle behind a wall, unique ids, a block that stays
intact, and no debris particle inside the column; the 3-D showcase debris_impact_3d.nml coarse
(h = 0.05 m) for 0.03 s: its container is one rigid body in bodies.csv, the column is in loads.csv.
The full reproductions are scripts/paper_figures.py (CTest label validation).

usage: check_scenes.py <flotsam> <mpiexec> <tests/runs/scenes> <scripts folder>"""

import os
import sys

import h5py
import numpy as np

from flotsam_run import Checks, Flotsam, main_arguments, read_diagnostics

RHO = 1000.0
# a particle this close behind a wall counts as on it (the safeguard puts particles exactly on it)
ON_WALL = 1e-9


def final_particles(folder, rows):
    path = os.path.join(folder, "fields", f"fields_{len(rows) - 1:06d}.h5")
    with h5py.File(path) as f:
        return {key: f["particles"][key][:] for key in ("position", "material", "mass", "id")}


def run(checks, flotsam, inputs, scene, name, ranks, changes):
    from scene_variant import write_variant
    changes.setdefault("run", {})["output_dir"] = f"'{name}'"
    path = write_variant(os.path.join(inputs, scene), flotsam.path(name + ".nml"), changes)
    flotsam.remove(name)
    result = flotsam.run(path, ranks)
    ok = checks.check(result.returncode == 0, f"{name}: runs on {ranks} ranks", result.stderr[-2000:])
    return (read_diagnostics(flotsam.path(name)) if ok else None), flotsam.path(name)


def check_inside(checks, name, x, left_wall_from, right, floor=0.0):
    """No particle behind the floor, the right wall, or the left wall above `left_wall_from` (the
    opening below it is closed or fed, so nothing may be behind it either)."""
    worst = min((x[:, 1] - floor).min(), (right - x[:, 0]).min(), x[:, 0].min())
    checks.check(worst >= -ON_WALL, f"{name}: no particle behind a wall", f"deepest {worst:.3e} m")


def check_inflow(checks, name, rows, speed, height, spacing, solid_mass=0.0):
    """Mass = solid + rho Dp H x floor(v0 t / Dp) at every output (layer by layer), and the flux over
    the run within 1 % of rho v0 H."""
    worst = 0.0
    for row in rows:
        t = float(row["time"])
        layers = np.floor(speed * t / spacing + 1e-9)
        expected = solid_mass + RHO * spacing * height * layers
        worst = max(worst, abs(float(row["total_mass"]) - expected) / max(expected, 1.0))
    checks.check(worst < 1e-12, f"{name}: injected mass = rho Dp H per layer at every output", f"{worst:.2e}")
    t_end = float(rows[-1]["time"])
    flux = (float(rows[-1]["total_mass"]) - solid_mass) / t_end
    checks.close(flux, RHO * speed * height, 0.01, f"{name}: mean inflow mass flux = rho v0 H within 1 %")


def main():
    flotsam_path, mpiexec, _scenes, rest = main_arguments()
    scripts = os.path.abspath(rest[0])
    sys.path.insert(0, scripts)
    inputs = os.path.join(os.path.dirname(scripts), "inputs")
    checks = Checks()
    flotsam = Flotsam(flotsam_path, mpiexec, "output")

    # Fig. 1 scene, standard MPM: 0.4 s of filling (8 layers of Dp = 0.05 m: the flux is exact at 0.4 s)
    rows, folder = run(checks, flotsam, inputs, "tank_filling.nml", "filling", 2,
                       {"run": {"end_time": "0.4", "output_interval": "0.02"}})
    if rows:
        check_inflow(checks, "filling", rows, 1.0, 1.0, 0.05)
        state = final_particles(folder, rows)
        check_inside(checks, "filling", state["position"], 1.0, 3.0)
        front = state["position"][:, 0].max()
        # pinned at the opening (an empty-node threshold gone wrong) the front stays below 0.1 m
        checks.check(front > 0.25, "filling: the stream advances (0.4 m injected)", f"front at {front:.3f} m")
        checks.check(len(np.unique(state["id"])) == len(state["id"]), "filling: ids unique")

    # Figs. 3-4 scene on the 45 degree grid, FOAL1: 0.2 s at rest
    rows, folder = run(checks, flotsam, inputs, "hydrostatic_tank.nml", "tank45", 2,
                       {"run": {"end_time": "0.2", "output_interval": "0.02"}, "grid": {"rotation": "45.0"}})
    if rows:
        mass = [float(r["total_mass"]) for r in rows]
        checks.close(mass[-1], 3.2 * 3.2 * RHO, 1e-12, "tank45: mass = rho x 3.2 m x 3.2 m, kept")
        h = [float(r["h_eq"]) for r in rows]
        checks.check(max(abs(v / 3.2 - 1) for v in h) < 0.005, "tank45: h_eq within 0.5 % of 3.2 m",
                     f"{min(h)} .. {max(h)}")
        energy = max(float(r["kinetic_energy"]) for r in rows)
        # bounded: a tenth of a percent of the water's potential energy rho g H^2 W / 2
        checks.check(energy < 1e-3 * RHO * 10 * 3.2 ** 3 / 2, "tank45: kinetic energy stays small", f"{energy:.3e} J")
        state = final_particles(folder, rows)
        x = state["position"]
        check_inside(checks, "tank45", x, 0.0, 3.2)
        checks.check(abs(x[:, 2]).max() == 0.0, "tank45: positions written in the world frame (z = 0)")

    # Fig. 5 scene: 0.5 s of injection with the block falling onto the floor, on 2 ranks
    rows, folder = run(checks, flotsam, inputs, "floating_block.nml", "block", 2,
                       {"run": {"end_time": "0.5", "output_interval": "0.05"}})
    if rows:
        block_mass = 0.4 * 0.4 * 300.0
        check_inflow(checks, "block", rows, 1.0, 1.0, 0.1 / 3, solid_mass=block_mass)
        state = final_particles(folder, rows)
        x, block = state["position"], state["material"] == 2
        check_inside(checks, "block", x, 1.0, 3.0)
        checks.check(len(np.unique(state["id"])) == len(state["id"]), "block: ids unique")
        checks.close(state["mass"][block].sum(), block_mass, 1e-12, "block: block mass kept")
        size = x[block, :2].max(axis=0) - x[block, :2].min(axis=0)
        # intact: the particle cloud keeps the block's size (0.4 m less one spacing between the outer
        # particles) within a spacing either way
        checks.check(np.all(np.abs(size - (0.4 - 0.1 / 3)) < 0.1 / 3), "block: stays intact (size kept)", str(size))

    # debris scenes, smoke runs: the 2-D one coarse (h = 0.04) through the block's impact on the column
    # (at 0.51 s), the 3-D one at its own resolution for 0.02 s (the full runs: scripts/debris_column.py)
    for scene, name, changes in (
            ("debris_column_2d.nml", "debris2d", {"run": {"end_time": "0.6", "output_interval": "0.05"},
                                                  "grid": {"cell_size": "0.04"}}),
            ("debris_column_3d.nml", "debris3d", {"run": {"end_time": "0.02", "output_interval": "0.01"}})):
        rows, folder = run(checks, flotsam, inputs, scene, name, 2, changes)
        if not rows:
            continue
        mass = [float(r["total_mass"]) for r in rows]
        checks.close(mass[-1], mass[0], 1e-12, f"{name}: mass kept")
        state = final_particles(folder, rows)
        x, block = state["position"], state["material"] == 2
        checks.check(len(np.unique(state["id"])) == len(state["id"]), f"{name}: ids unique")
        dim = 3 if name == "debris3d" else 2
        # the column of the scene file: 2-D x 2.0 .. 2.1, y < 0.3; 3-D x 1.6 .. 1.72, y 0.24 .. 0.36
        lower, upper = ((2.0, 0.0), (2.1, 0.3)) if dim == 2 else ((1.6, 0.24, 0.0), (1.72, 0.36, 0.8))
        inside = np.all((x[block, :dim] > lower) & (x[block, :dim] < upper), axis=1).sum()
        checks.check(block.any() and inside == 0, f"{name}: no debris particle inside the column",
                     f"{inside} of {block.sum()}")
        if dim == 2:
            # carried from x = 1.275 m to the column (its centroid half a block, 0.075 m, before the face)
            front = x[block, 0].mean() + 0.075
            checks.check(front > 1.9, f"{name}: the surge carries the block to the column", f"front at {front:.3f} m")

    check_debris_impact(checks, flotsam, inputs)
    sys.exit(checks.summary())


def check_debris_impact(checks, flotsam, inputs):
    """The showcase debris_impact_3d.nml, smoke run: h = 0.05 m (twice the scene's, an eighth of its
    particles) for 0.03 s on 2 ranks. It starts, keeps its mass, and writes what the scene is for: the
    container in bodies.csv (one rigid body: its particles keep their distances to round-off, it rests
    on the floor until the bore comes) and the column's force and moment in loads.csv."""
    import pandas
    rows, folder = run(checks, flotsam, inputs, "debris_impact_3d.nml", "impact3d", 2,
                       {"run": {"end_time": "0.03", "output_interval": "0.015", "particle_fields": "'all'"},
                        "grid": {"cell_size": "0.05"}})
    if not rows:
        return
    mass = [float(r["total_mass"]) for r in rows]
    checks.close(mass[-1], mass[0], 1e-12, "impact3d: mass kept")
    bodies = pandas.read_csv(os.path.join(folder, "bodies.csv"), comment="#")
    loads = pandas.read_csv(os.path.join(folder, "loads.csv"), comment="#")
    wanted = [f"container_{c}" for c in ("x", "y", "z", "vx", "vy", "vz", "rx", "ry", "rz", "fx", "fy", "fz")]
    checks.check(set(wanted) <= set(bodies.columns) and not any(c.startswith("reservoir_") for c in bodies.columns),
                 "impact3d: bodies.csv has the container (and not the water)", str(list(bodies.columns)))
    checks.check({f"column_{c}" for c in ("fx", "fy", "fz", "mx", "my", "mz")} <= set(loads.columns),
                 "impact3d: loads.csv has the column's force and moment", str(list(loads.columns)))
    if "container_z" in bodies.columns:
        # 0.15 m high on the floor: its centroid at 0.075 m, held there by the floor's contact
        drift = (bodies["container_z"] - 0.075).abs().max()
        checks.check(drift < 1e-3, "impact3d: the container rests on the floor before the bore", f"{drift:.2e} m")
    first = final_particles(folder, rows[:1])
    last = final_particles(folder, rows)
    ids = {}
    for label, state in (("first", first), ("last", last)):
        box = state["material"] == 2
        order = np.argsort(state["id"][box])
        ids[label] = state["position"][box][order]
    a, b = ids["first"], ids["last"]
    rigid = len(a) == len(b) and len(a) > 0
    if rigid:
        # distances of every particle to two others: unchanged by a rigid motion
        change = max(np.abs(np.linalg.norm(a - a[k], axis=1) - np.linalg.norm(b - b[k], axis=1)).max()
                     for k in (0, len(a) - 1))
        rigid = change < 1e-9
    checks.check(rigid, "impact3d: the container moves as one rigid body", f"{len(a)} particles")


if __name__ == "__main__":
    main()
