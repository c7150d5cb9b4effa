#!/usr/bin/python3
"""ParaView opens a run: pvbatch reads particles.xmf and grid.xmf of a 2-D run on 3 ranks (one without
particles) and must see one time step per diagnostics row at the diagnostics' times, every particle as
a point and a vertex cell, the particle and grid arrays with their components, and the grid where the
particles are. Then scripts/render_step.py draws a step to PNG (under xvfb-run: Debian's ParaView
renders through X only).

usage: check_paraview.py <flotsam> <mpiexec> <tests/runs/scenes> <scripts folder>"""

import json
import os
import shutil
import subprocess

import matplotlib.image
import numpy as np

from flotsam_run import Checks, Flotsam, main_arguments, read_diagnostics

PARTICLE_ARRAYS = {"velocity": 3, "mass": 1, "volume": 1, "density": 1, "stress": 9, "mean_stress": 1, "pressure": 1,
                   "material": 1, "id": 1, "rank": 1}
GRID_POINT_ARRAYS = {"mass": 1, "velocity": 3}
GRID_CELL_ARRAYS = {"density_water": 1, "mean_stress_water": 1, "density_wood_block": 1,
                    "mean_stress_wood_block": 1}


def main():
    flotsam_path, mpiexec, scenes, rest = main_arguments()
    scripts = rest[0]
    checks = Checks()
    pvbatch = shutil.which("pvbatch")
    xvfb_run = shutil.which("xvfb-run")
    if not checks.check(pvbatch is not None and xvfb_run is not None, "pvbatch and xvfb-run installed",
                        "install Debian's python3-paraview and xvfb (scripts/flotsam setup)"):
        return checks.summary()

    flotsam = Flotsam(flotsam_path, mpiexec, "paraview")
    name = "two_materials_2d"
    flotsam.remove(name)
    scene = flotsam.scene(os.path.join(scenes, name + ".nml"), name + ".nml", name)
    result = flotsam.run(scene, 3)
    if not checks.check(result.returncode == 0, "run on 3 ranks", result.stderr[-2000:]):
        return checks.summary()
    rows = read_diagnostics(flotsam.path(name))
    times = [float(r["time"]) for r in rows]

    probe = subprocess.run([pvbatch, os.path.join(os.path.dirname(os.path.abspath(__file__)), "paraview_probe.py"),
                            flotsam.path(name)], capture_output=True, text=True, timeout=300)
    lines = [line for line in probe.stdout.splitlines() if line.startswith("PROBE ")]
    if not checks.check(probe.returncode == 0 and len(lines) == 1, "pvbatch reads the XDMF files",
                        probe.stderr[-2000:]):
        return checks.summary()
    seen = json.loads(lines[0][len("PROBE "):])

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

    picture = flotsam.path("step.png")
    if os.path.exists(picture):
        os.remove(picture)
    render = subprocess.run([xvfb_run, "-a", pvbatch, os.path.join(scripts, "render_step.py"), flotsam.path(name),
                             "--time", "0.05", "-o", picture], capture_output=True, text=True, timeout=300)
    drawn = render.returncode == 0 and os.path.exists(picture)
    checks.check(drawn, "render_step.py writes a PNG", render.stderr[-2000:])
    if drawn:
        image = matplotlib.image.imread(picture)
        colours = len(np.unique(image.reshape(-1, image.shape[-1])[:, :3], axis=0))
        checks.check(image.shape[:2] == (700, 1200) and colours > 50, "the PNG shows coloured particles",
                     f"{image.shape}, {colours} colours")
    return checks.summary()


if __name__ == "__main__":
    raise SystemExit(main())
