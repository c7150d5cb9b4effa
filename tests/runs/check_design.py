#!/usr/bin/env python3
"""scripts/design_check.py on whole runs (issue 52, item 4): the FEMA P-646 numbers it prints are the
formulas applied to the run's own gauges and bodies, recomputed here from gauges.csv and bodies.csv.

  1. inputs/column_in_flow.nml (2-D dam break onto a column, to t = 0.6 s): (h u^2)_max = max over rows
     of level x vx^2 where the velocity gauge sees fluid; F_d = 1/2 1100 x 2.0 x 1 m x (h u^2)_max; F_s =
     1.5 F_d (to 1e-12); the simulated peak and mean come from loads.csv's column_fx.
  2. tests/runs/scenes/structures/column_flow.nml (a block carried onto a column): the debris check
     with k = E A / L: F_i = u sqrt(k m), m from bodies.csv's '# mass' line (rho x area of the block),
     u the block's largest speed before the column's filtered peak.
  3. Bad arguments: an unknown structure, --body without a stiffness: exit 2.
"""
import math
import os
import subprocess
import sys

import numpy as np
import pandas as pd

from flotsam_run import Checks, Flotsam, main_arguments


def design(scripts, *arguments):
    return subprocess.run([sys.executable, os.path.join(scripts, "design_check.py"), *arguments],
                          capture_output=True, text=True, timeout=300)


def table(path):
    frame = pd.read_csv(path, comment="#")
    return dict(zip(frame["quantity"], frame["value"]))


def check_drag(checks, flotsam, root, scripts):
    name = "design_column"
    flotsam.remove(name)
    scene = flotsam.scene(os.path.join(root, "inputs", "column_in_flow.nml"), name + ".nml", name, end_time=0.6)
    result = flotsam.run(scene, 2)
    if not checks.check(result.returncode == 0, "column_in_flow to 0.6 s", result.stderr[-2000:]):
        return
    folder = flotsam.path(name)
    out = os.path.join(folder, "design.csv")
    run = design(scripts, folder, "--structure", "column", "--out", out)
    if not checks.check(run.returncode == 0, "design_check.py --structure column", run.stderr[-2000:]):
        return
    values = table(out)
    gauges = pd.read_csv(os.path.join(folder, "gauges.csv"), comment="#")
    flux = np.where(gauges["u_up_samples"] > 0, gauges["h_up_level"] * gauges["u_up_vx"] ** 2, 0.0)
    drag = 0.5 * 1100.0 * 2.0 * 1.0 * flux.max()
    checks.check(flux.max() > 0.1, f"the bore reaches the gauges: (h u^2)_max = {flux.max():.4g} m^3/s^2")
    checks.close(values["(h u^2)_max"], flux.max(), 1e-12, "(h u^2)_max = max of level x vx^2 from gauges.csv")
    checks.close(values["FEMA hydrodynamic F_d"], drag, 1e-12,
                 f"F_d = 1/2 rho_s C_d B (h u^2)_max = {drag:.6g} N/m from the gauges")
    checks.close(values["FEMA surge F_s"], 1.5 * drag, 1e-12, "F_s = 1.5 F_d")
    loads = pd.read_csv(os.path.join(folder, "loads.csv"), comment="#")
    raw = loads["column_fx"].iloc[int(np.argmax(loads["column_fx"].abs()))]
    checks.close(values["simulated force, raw peak"], raw, 1e-12, f"the simulated raw peak is loads.csv's ({raw:.6g} N/m)")
    checks.check("F_d" in run.stdout and "N/m" in run.stdout, "the table is printed with units")


def check_debris(checks, flotsam, scenes, scripts):
    name = "design_debris"
    flotsam.remove(name)
    scene = flotsam.scene(os.path.join(scenes, "structures", "column_flow.nml"), name + ".nml", name)
    result = flotsam.run(scene, 2)
    if not checks.check(result.returncode == 0, "column_flow (a block onto a column)", result.stderr[-2000:]):
        return
    folder = flotsam.path(name)
    # the scene has no gauges: a one-row gauges.csv for the drag part (the debris part reads bodies.csv only)
    with open(os.path.join(folder, "gauges.csv"), "w") as f:
        f.write("time,h_level,h_samples,u_vx,u_vy,u_samples\n# written by the test\n0.01,0.1,1,1.0,0.0,3\n")
    E, A, L = 2.0e6, 0.06, 0.06
    out = os.path.join(folder, "design.csv")
    run = design(scripts, folder, "--structure", "column", "--body", "debris", "--youngs-modulus", str(E),
                 "--area", str(A), "--length", str(L), "--out", out)
    if not checks.check(run.returncode == 0, "design_check.py --body debris", run.stderr[-2000:]):
        return
    values = table(out)
    checks.close(values["debris mass m"], 600.0 * 0.06 * 0.06, 1e-9, "the block's mass from bodies.csv: rho x area")
    bodies = pd.read_csv(os.path.join(folder, "bodies.csv"), comment="#")
    speed = np.hypot(bodies["debris_vx"], bodies["debris_vy"])
    checks.check(0.0 < values["debris speed u"] <= speed.max() + 1e-12,
                 f"u = {values['debris speed u']:.4g} m/s, the block's speed before the peak (largest {speed.max():.4g})")
    k = E * A / L
    exact = values["debris speed u"] * math.sqrt(k * values["debris mass m"])
    checks.close(values["FEMA-style debris impact F_i"], exact, 1e-12, f"F_i = u sqrt(k m), k = E A / L = {k:.4g} N/m/m")


def check_bad(checks, scripts, folder):
    for arguments, text, label in [
            (["--structure", "pier"], "no structure 'pier'", "an unknown structure"),
            (["--structure", "column", "--body", "debris"], "needs --stiffness", "--body without a stiffness")]:
        run = design(scripts, folder, *arguments)
        checks.check(run.returncode == 2 and text in run.stderr, f"{label}: exit 2 with a message", run.stderr[-500:])


def main():
    flotsam_path, mpiexec, scenes, rest = main_arguments()
    scripts = rest[0]
    root = os.path.dirname(os.path.abspath(scripts))
    checks = Checks()
    flotsam = Flotsam(flotsam_path, mpiexec, "design")
    check_drag(checks, flotsam, root, scripts)
    check_debris(checks, flotsam, scenes, scripts)
    check_bad(checks, scripts, flotsam.path("design_debris"))
    return checks.summary()


if __name__ == "__main__":
    raise SystemExit(main())
