#!/usr/bin/python3
"""ParaView opens a run: pvbatch shows particles.xmf and grid.xmf in a render view and steps it through
the outputs (paraview_probe.py). Two runs:

  * a 2-D run on 3 ranks (one without particles): one time step per diagnostics row at the
    diagnostics' times, every particle as a point and a vertex cell, the particle and grid arrays with
    their components, and the grid where the particles are;
  * a jet entering a tank (moving_box_2d): the particle count grows and the grid's active box grows and
    moves from output to output. At every output the render view must hold that output's particles
    and that output's box of cells (count, bounds, the range of every grid array as in the HDF5 file),
    not the first output's box (issue 14: ParaView kept the first step's extent).

Then scripts/render_step.py draws a step to PNG. Debian's ParaView renders through X only: the probe
and the picture run on a private Xvfb display (flotsam_run.PrivateDisplay), not under `xvfb-run -a`,
which races with other X servers starting at the same moment.

usage: check_paraview.py <flotsam> <mpiexec> <tests/runs/scenes> <scripts folder>"""

import json
import os
import shutil
import subprocess
from xml.etree import ElementTree

import h5py
import matplotlib.image
import numpy as np

from flotsam_run import Checks, Flotsam, PrivateDisplay, main_arguments, read_diagnostics

PROBE = os.path.join(os.path.dirname(os.path.abspath(__file__)), "paraview_probe.py")

PARTICLE_ARRAYS = {"position": 3, "velocity": 3, "mass": 1, "volume": 1, "density": 1, "stress": 9, "mean_stress": 1, "pressure": 1,
                   "material": 1, "id": 1, "rank": 1}
GRID_POINT_ARRAYS = {"mass": 1, "velocity": 3}
GRID_CELL_ARRAYS = {"density_water": 1, "mean_stress_water": 1, "density_wood_block": 1,
                    "mean_stress_wood_block": 1}


def probe(checks, pvbatch, environment, run, label):
    """What the render view of pvbatch holds at each output of `run` (paraview_probe.py); None on failure."""
    result = subprocess.run([pvbatch, PROBE, run], capture_output=True, text=True, timeout=300, env=environment)
    lines = [line for line in result.stdout.splitlines() if line.startswith("PROBE ")]
    if not checks.check(result.returncode == 0 and len(lines) == 1, f"{label}: pvbatch shows the XDMF files",
                        result.stderr[-2000:]):
        return None
    return json.loads(lines[0][len("PROBE "):])


def check_two_materials(checks, flotsam, scenes, pvbatch, environment):
    name = "two_materials_2d"
    flotsam.remove(name)
    scene = flotsam.scene(os.path.join(scenes, name + ".nml"), name + ".nml", name)
    result = flotsam.run(scene, 3)
    if not checks.check(result.returncode == 0, "run on 3 ranks", result.stderr[-2000:]):
        return False
    rows = read_diagnostics(flotsam.path(name))
    times = [float(r["time"]) for r in rows]
    seen = probe(checks, pvbatch, environment, flotsam.path(name), name)
    if seen is None:
        return False

    particles, grid = seen["particles"], seen["grid"]
    checks.check(np.allclose(particles["times"], times, rtol=1e-15, atol=0), "particles: time steps of the diagnostics",
                 f"{particles['times']} against {times}")
    checks.check(np.allclose(grid["times"], times, rtol=1e-15, atol=0), "grid: time steps of the diagnostics")
    for row, step in zip(rows, particles["steps"]):
        n = int(row["particles"])
        checks.check(step["points"] == n and step["cells"] == n, f"particles at t = {row['time']}: {n} points and cells",
                     f"{step['points']} points, {step['cells']} cells")
    checks.check(particles["point_arrays"] == PARTICLE_ARRAYS, "particle arrays and components",
                 f"{particles['point_arrays']}")
    checks.check(grid["point_arrays"] == GRID_POINT_ARRAYS, "grid node arrays", f"{grid['point_arrays']}")
    checks.check(grid["cell_arrays"] == GRID_CELL_ARRAYS, "grid cell arrays per material", f"{grid['cell_arrays']}")
    for p, g in zip(particles["steps"], grid["steps"]):
        pb, gb = p["bounds"], g["bounds"]
        inside = all(gb[2 * k] <= pb[2 * k] and pb[2 * k + 1] <= gb[2 * k + 1] for k in range(3))
        checks.check(inside and gb[4] == gb[5] == 0.0 and gb[0] >= -1.0, f"grid at t = {p['time']} holds the particles",
                     f"particles {pb}, grid {gb}")
    low, high = particles["mean_stress_range"]
    checks.check(low < 0.0, "mean stress: compression in the water", f"range {low} .. {high}")
    return True


def same_range(shown, values):
    """ParaView's range of an array equals the finite minimum and maximum of the HDF5 dataset."""
    finite = values[np.isfinite(values)]
    if finite.size == 0:
        return shown is None
    return shown is not None and np.allclose(shown, [finite.min(), finite.max()], rtol=1e-12, atol=0)


def check_moving_box(checks, flotsam, scenes, pvbatch, environment):
    """The jet of moving_box_2d: every output drawn with its own particles and its own box of cells."""
    name = "moving_box_2d"
    flotsam.remove(name)
    scene = flotsam.scene(os.path.join(scenes, name + ".nml"), name + ".nml", name)
    result = flotsam.run(scene, 2)
    if not checks.check(result.returncode == 0, f"{name}: run on 2 ranks", result.stderr[-2000:]):
        return
    directory = flotsam.path(name)
    rows = read_diagnostics(directory)
    seen = probe(checks, pvbatch, environment, directory, name)
    if seen is None:
        return
    particles, grid = seen["particles"], seen["grid"]
    times = [float(r["time"]) for r in rows]
    if not checks.check(np.allclose(particles["times"], times, rtol=1e-15, atol=0) and
                        np.allclose(grid["times"], times, rtol=1e-15, atol=0),
                        f"{name}: one time step per diagnostics row", f"{particles['times']}, {grid['times']}"):
        return
    # the box of each output as grid.xmf gives it (lower corner, x y z) and the spacing
    root = ElementTree.parse(os.path.join(directory, "grid.xmf")).getroot()
    members = root.find(".//Grid[@CollectionType='Temporal']")
    origins, spacing = [], None
    for member in members:
        origin, step = member.iter("Geometry").__next__().findall("DataItem")
        origins.append([float(v) for v in origin.text.split()][::-1])
        spacing = float(step.text.split()[0])
    boxes = set()
    for index, (p, g) in enumerate(zip(particles["steps"], grid["steps"])):
        label = f"{name} output {index} (t = {rows[index]['time']})"
        with h5py.File(os.path.join(directory, "fields", f"fields_{index:06d}.h5")) as f:
            position = f["particles/position"][:]
            node_mass = f["grid/node/mass"][:]
            cell = {key: f["grid/cell"][key][:] for key in f["grid/cell"]}
            node_velocity = f["grid/node/velocity"][:]
        n = len(position)
        checks.check(n == int(rows[index]["particles"]) and p["points"] == n and p["cells"] == n,
                     f"{label}: the view shows the output's {n} particles", f"{p['points']} points, {p['cells']} cells")
        checks.check(np.allclose(p["bounds"], np.column_stack([position.min(axis=0), position.max(axis=0)]).ravel(),
                                 rtol=0, atol=1e-12), f"{label}: the particles where the file has them",
                     f"{p['bounds']}")
        nodes = node_mass.shape[::-1]                       # x, y, z
        cells = int(np.prod([max(k - 1, 1) for k in nodes]))
        checks.check(g["points"] == node_mass.size and g["cells"] == cells,
                     f"{label}: the view shows the output's box of {nodes[0] - 1} x {nodes[1] - 1} cells",
                     f"{g['points']} points and {g['cells']} cells shown, the file has {node_mass.size} and {cells}")
        low = np.array(origins[index])
        high = low + spacing * (np.array(nodes) - 1)
        # the surface representation holds its points in single precision
        checks.check(np.allclose(g["bounds"], np.column_stack([low, high]).ravel(), rtol=1e-6, atol=1e-6),
                     f"{label}: the box where grid.xmf puts it", f"shown {g['bounds']}, box {low} .. {high}")
        boxes.add(tuple(np.round(np.concatenate([low, high]), 9)))
        same = all(same_range(g["cell_ranges"].get(key), values) for key, values in cell.items())
        same &= same_range(g["point_ranges"].get("mass"), node_mass)
        same &= same_range(g["point_ranges"].get("velocity"), node_velocity[..., 0])
        checks.check(same, f"{label}: the grid arrays shown have the file's ranges",
                     f"shown {g['cell_ranges']} {g['point_ranges']}")
    checks.check(len(boxes) == len(rows) and len({int(r["particles"]) for r in rows}) == len(rows),
                 f"{name}: the box and the particle count change at every output (what this test is about)",
                 f"{len(boxes)} boxes in {len(rows)} outputs")


def main():
    flotsam_path, mpiexec, scenes, rest = main_arguments()
    scripts = rest[0]
    checks = Checks()
    pvbatch = shutil.which("pvbatch")
    xvfb = shutil.which("Xvfb")
    if not checks.check(pvbatch is not None and xvfb is not None, "pvbatch and Xvfb installed",
                        "install Debian's python3-paraview and xvfb (scripts/flotsam setup)"):
        return checks.summary()

    flotsam = Flotsam(flotsam_path, mpiexec, "paraview")
    with PrivateDisplay(xvfb) as environment:
        if check_two_materials(checks, flotsam, scenes, pvbatch, environment):
            picture = flotsam.path("step.png")
            if os.path.exists(picture):
                os.remove(picture)
            render = subprocess.run([pvbatch, os.path.join(scripts, "render_step.py"), flotsam.path("two_materials_2d"),
                                     "--time", "0.05", "-o", picture], capture_output=True, text=True, timeout=300,
                                    env=environment)
            drawn = render.returncode == 0 and os.path.exists(picture)
            checks.check(drawn, "render_step.py writes a PNG", render.stderr[-2000:])
            if drawn:
                image = matplotlib.image.imread(picture)
                colours = len(np.unique(image.reshape(-1, image.shape[-1])[:, :3], axis=0))
                checks.check(image.shape[:2] == (700, 1200) and colours > 50, "the PNG shows coloured particles",
                             f"{image.shape}, {colours} colours")
        check_moving_box(checks, flotsam, scenes, pvbatch, environment)
    return checks.summary()


if __name__ == "__main__":
    raise SystemExit(main())
