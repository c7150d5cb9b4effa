#!/usr/bin/env python3
"""Panels and load cells (issue 52; docs/loads.md, "Panels and load cells"): whole runs whose panels.csv
is held against the exact hydrostatic pressure and against loads.csv.

  1. 2-D water at rest: each submerged panel of 1-10 cells (edges on and off the nodes, at the floor and
     inside) reads rho g (H - y_c) within 1 %, its force the pressure times its length; the panels tiling
     the side x_min and the floor add up to their loads.csv entries in every row (1e-10), a panel has no
     tangential force on a slip wall, the tank's load cell equals the sum of every entry, and two load
     cells cutting the side x_max add up to it. On 1 rank and 2 ranks (the same rows to 1e-10).
  2. 3-D water at rest: rectangles of 1 x 2 to 3 x 8 cells on two sides within 1 %, tiling to 1e-10.
  3. A dam break with quadratic B-splines (loads reach a second layer of nodes behind the box sides):
     every row the panels tiling a face add up to its load, the load cells to the sums (1e-10).
  4. A block sliding on a table (contact body fields): two load cells cutting the table add up to the
     table's load in every row, the body fields' part included.
  5. A submerged box structure (not turned): a panel per face, spanning it; the four add up to its load
     in loads.csv in every row (1e-10): a face ends at the box's edges.
  6. panels.csv reads with one pandas call; its header names units, scene and program.
"""
import os

import pandas as pd

from flotsam_run import Checks, Flotsam, main_arguments

RHO, G = 1000.0, 9.81
TILING = 1e-10          # relative to the largest load of the entry over the run


def read(directory, file):
    return pd.read_csv(os.path.join(directory, file + ".csv"), comment="#")


def run(checks, flotsam, scenes, scene, ranks, name=None):
    name = name or os.path.splitext(scene)[0]
    flotsam.remove(name)
    path = flotsam.scene(os.path.join(scenes, "panels", scene), name + ".nml", name)
    result = flotsam.run(path, ranks)
    if not checks.check(result.returncode == 0, f"{name}: run on {ranks} ranks", result.stderr[-2000:]):
        return None
    return read(flotsam.path(name), "panels"), read(flotsam.path(name), "loads")


def tiles(checks, panels, loads, parts, entry, components, label):
    """The panels `parts` add up to loads.csv's `entry` in every row, per force component."""
    for c in components:
        total = sum(panels[f"{p}_{c}"] for p in parts)
        scale = max(loads[f"{entry}_{c}"].abs().max(), 1e-300)
        worst = (total - loads[f"{entry}_{c}"]).abs().max() / scale
        checks.check(worst <= TILING, f"{label}: {' + '.join(parts)} = {entry} {c} in every row "
                     f"(largest difference {worst:.1e} of max |{entry}_{c}| = {scale:.4g})")


def whole_tank(checks, panels, loads, entries, label):
    """The load cell `tank` around the whole scene = the sum of the entries (relative to the largest entry:
    the two sides' fx cancel)."""
    for c in ("fx", "fy"):
        everything = sum(loads[f"{e}_{c}"] for e in entries)
        scale = max(loads[f"{e}_{c}"].abs().max() for e in entries)
        worst = (panels[f"tank_{c}"] - everything).abs().max() / scale
        checks.check(worst <= TILING, f"{label}: the tank's load cell = the sum of every entry, {c} "
                     f"({worst:.1e} of the largest entry)")


def pressures(checks, panels, H, spans, axis_name, label):
    """Each panel of `spans` (name -> (lower, upper) along the vertical) reads rho g (H - centre) within 1 %."""
    mean = panels.mean()
    for name, (a, b) in spans.items():
        exact = RHO * G * (H - 0.5 * (a + b))
        close = abs(mean[f"{name}_pressure"] / exact - 1)
        checks.check(close <= 0.01, f"{label}: {name} ({axis_name} {a:g} .. {b:g} m) mean pressure "
                     f"{mean[f'{name}_pressure']:.6g} Pa against rho g (H - {axis_name}_c) = {exact:.6g} Pa, "
                     f"relative error {close:.2e} (tolerance 0.01)")


def check_2d(checks, flotsam, scenes):
    results = {}
    for ranks in (1, 2):
        results[ranks] = run(checks, flotsam, scenes, "hydrostatic_2d.nml", ranks, f"panels_2d_np{ranks}")
    if results[2] is None:
        return None
    panels, loads = results[2]
    h, H = 0.02, 0.5
    spans = {"side_1": (0.0, h), "side_2": (h, 0.06), "side_3": (0.06, 0.163), "side_4": (0.163, 0.2),
             "side_5": (0.2, 0.4), "side_6": (0.4, 0.42)}
    pressures(checks, panels, H, spans, "y", "2-D")
    mean = panels.mean()
    for name, (a, b) in spans.items():
        checks.check(abs(-mean[f"{name}_fx"] - mean[f"{name}_pressure"] * (b - a)) <= 1e-9 * abs(mean[f"{name}_fx"]),
                     f"2-D: {name} force = -pressure x length (the wall x_min is pushed towards -x)")
    floor = {"floor_1": (0.0, 0.02), "floor_2": (0.02, 0.31), "floor_3": (0.31, 0.4)}
    for name in floor:
        checks.close(mean[f"{name}_pressure"], RHO * G * H, 0.01, f"2-D: {name} reads rho g H on the floor")
    tiles(checks, panels, loads, [f"side_{k}" for k in range(1, 8)], "x_min", ["fx"], "2-D")
    tiles(checks, panels, loads, list(floor), "y_min", ["fy"], "2-D")
    tangential = max(panels[f"side_{k}_fy"].abs().max() for k in range(1, 8))
    checks.check(tangential <= 1e-12 * abs(loads["x_min_fx"]).max(),
                 f"2-D: no tangential force on the panels of a slip wall ({tangential:.1e} N/m)")
    whole_tank(checks, panels, loads, ("x_min", "x_max", "y_min"), "2-D")
    tiles(checks, panels, loads, ["right_low", "right_high"], "x_max", ["fx"], "2-D load cells")
    if results[1] is not None:
        one = results[1][0]
        forces = [c for c in panels.columns if c != "time"]
        scale = max(panels[c].abs().max() for c in forces)
        worst = max((one[c] - panels[c]).abs().max() for c in forces) / scale
        checks.check(worst <= 1e-10, f"2-D: panels.csv on 1 rank and on 2 ranks agree ({worst:.1e} of the largest value)")
    return flotsam.path("panels_2d_np2")


def check_3d(checks, flotsam, scenes):
    result = run(checks, flotsam, scenes, "hydrostatic_3d.nml", 2, "panels_3d")
    if result is None:
        return
    panels, loads = result
    H = 0.3
    spans = {"side_1": (0.0, 0.05), "side_2": (0.0, 0.05), "side_3": (0.05, 0.2), "side_4": (0.05, 0.2),
             "back_1": (0.1, 0.25), "back_2": (0.0, 0.05)}
    pressures(checks, panels, H, spans, "z", "3-D")
    tiles(checks, panels, loads, [f"side_{k}" for k in range(1, 6)], "x_min", ["fx"], "3-D")


def check_dam_break(checks, flotsam, scenes):
    result = run(checks, flotsam, scenes, "dam_break_bspline2.nml", 2, "panels_dam_break")
    if result is None:
        return
    panels, loads = result
    checks.check(loads["x_max_fx"].abs().max() > 10.0, "dam break: the water reaches the wall x_max "
                 f"(largest |x_max_fx| {loads['x_max_fx'].abs().max():.4g} N/m)")
    tiles(checks, panels, loads, [f"wall_{k}" for k in range(1, 5)], "x_max", ["fx", "fy"], "dam break")
    tiles(checks, panels, loads, ["floor_1", "floor_2"], "y_min", ["fy"], "dam break")
    tiles(checks, panels, loads, ["ramp_cell"], "ramp", ["fx", "fy"], "dam break")
    whole_tank(checks, panels, loads, ("ramp", "x_min", "x_max", "y_min"), "dam break")


def check_contact(checks, flotsam, scenes):
    result = run(checks, flotsam, scenes, "block_on_table.nml", 2, "panels_contact")
    if result is None:
        return
    panels, loads = result
    tiles(checks, panels, loads, ["table_left", "table_right"], "table", ["fx", "fy"], "contact")
    early = panels[panels["time"] <= 0.1]
    checks.check((early["table_left_fx"].abs() > 1e-3 * loads["table_fx"].abs().max()).any(),
                 "contact: the sliding block's friction reaches the table's left load cell "
                 f"(largest |table_left_fx| before 0.1 s: {early['table_left_fx'].abs().max():.4g} N/m)")


def check_structure(checks, flotsam, scenes):
    result = run(checks, flotsam, scenes, "pontoon.nml", 2, "panels_pontoon")
    if result is None:
        return
    panels, loads = result
    faces = ["top", "bottom", "left", "right"]
    tiles(checks, panels, loads, faces, "pontoon", ["fy"], "structure")
    # fx is zero by symmetry (1e-12 N/m): held against the vertical load
    worst = (sum(panels[f"{p}_fx"] for p in faces) - loads["pontoon_fx"]).abs().max() / loads["pontoon_fy"].abs().max()
    checks.check(worst <= TILING, f"structure: the faces' fx = pontoon fx in every row ({worst:.1e} of max |pontoon_fy|)")
    checks.check((panels["bottom_pressure"] > panels["top_pressure"]).all(),
                 "structure: the bottom face deeper, more pressure than the top in every row")


def check_readable(checks, directory):
    path = os.path.join(directory, "panels.csv")
    frame = pd.read_csv(path, comment="#")
    checks.check(list(frame.columns[:4]) == ["time", "side_1_pressure", "side_1_fx", "side_1_fy"] and
                 "tank_fx" in frame.columns and "tank_pressure" not in frame.columns,
                 "panels.csv: columns time, <panel>_pressure, _fx, _fy; a load cell has no _pressure")
    with open(path) as f:
        comments = [line for line in f if line.startswith("#")]
    text = "".join(comments)
    checks.check("units: time s; _pressure Pa; _fx _fy _fz N/m" in text and "panels_2d_np2.nml" in text and
                 "written by flotsam" in text, "panels.csv: header comments give units, scene and program")


def main():
    flotsam_path, mpiexec, scenes, _ = main_arguments()
    checks = Checks()
    flotsam = Flotsam(flotsam_path, mpiexec, "panels")
    directory = check_2d(checks, flotsam, scenes)
    if directory is not None:
        check_readable(checks, directory)
    check_3d(checks, flotsam, scenes)
    check_dam_break(checks, flotsam, scenes)
    check_contact(checks, flotsam, scenes)
    check_structure(checks, flotsam, scenes)
    return checks.summary()


if __name__ == "__main__":
    raise SystemExit(main())
