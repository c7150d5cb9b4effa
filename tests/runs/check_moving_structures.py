#!/usr/bin/python3
"""Moving structures (`&structure motion`, issue 18), in whole runs (tests/runs/scenes/moving_structures):

1. Piston (piston.nml): a box spanning the flume's depth pushed at U = 0.1 m/s into water h = 0.1 m deep
   (the table of the &wall piston, scenes/moving_walls/piston.csv) makes a bore; the force the drive needs,
   the mean of paddle_fx over 1-2 s, is rho g h1^2 / 2 (the jump conditions of check_moving_walls.py's
   piston) within 3 %; no particle lost.
2. Stop (stop.nml): the box, reaching through the floor, pushes water quasi-statically by 0.025 m into a
   flume 0.5 m long and stops; at rest the load on it (mean over 2.5-3.5 s, one seiche period) is the
   hydrostatic force rho g h'^2 / 2 of the raised level h' = h L / (L - S) within 1 %; no particle lost.
3. Cylinder (cylinder.nml): a submerged circle dragged 0.2125 m through still water: at no output is a
   particle inside it (deeper than 1e-9 h); no particle lost.
4. Lift (lift.nml): a rigid crate on a platform that lifts it (1 m/s^2 to 0.2 m/s): the crate's velocity is
   the platform's to 1e-9 m/s and its bottom on the platform's top to 1e-9 m at every row, the platform
   carries M g to 1e-9 at constant speed, and the impulse it gives over 0-0.6 s is M g t + M U to 1e-9
   (the rigid contact acts relative to the structure's velocity).
5. Restart and ranks: the cylinder to t = 0.4 s stopped at step 610 and continued from its step-600
   checkpoint writes loads.csv byte for byte, and is refused once cylinder.csv changed (one line naming
   motion_checksum); 1 and 2 ranks agree to 1e-10 of the largest force.

usage: check_moving_structures.py <flotsam> <mpiexec> <tests/runs/scenes> [<scripts folder>] [--figures DIR]"""

import argparse
import glob
import os
import time

import h5py
import numpy as np
import pandas as pd

from check_moving_walls import G, H, RHO, check_piston, check_restart_and_ranks, interval_mean
from flotsam_run import Checks, Flotsam

FOLDER = "moving_structures"


def copy_beside(flotsam, folder, names):
    """The motion files `names` of scenes/<folder> into the working directory (the scenes name them
    relative to themselves)."""
    for name in names:
        with open(os.path.join(folder, name)) as source, open(flotsam.path(name), "w") as copy:
            copy.write(source.read())


def run(checks, flotsam, scenes, scene, tables, ranks=2):
    """Run scenes/moving_structures/<scene>.nml; its output folder, or None."""
    folder = os.path.join(scenes, FOLDER)
    flotsam.remove(scene)
    path = flotsam.scene(os.path.join(folder, scene + ".nml"), scene + ".nml", scene)
    copy_beside(flotsam, folder, tables)
    start = time.time()
    result = flotsam.run(path, ranks, "--overwrite", timeout=1800)
    if checks.check(result.returncode == 0, f"{scene}: run on {ranks} ranks ({time.time() - start:.0f} s)",
                    result.stderr[-2000:]):
        return flotsam.path(scene)
    return None


def check_nothing_lost(checks, directory, label):
    diagnostics = pd.read_csv(os.path.join(directory, "diagnostics.csv"), comment="#")
    lost = int(diagnostics["lost_particles"].iloc[-1])
    checks.check(lost == 0, f"{label}: no particle lost", f"{lost} lost")


def check_stop(checks, flotsam, scenes):
    directory = run(checks, flotsam, scenes, "stop", ["stop.csv"])
    if directory is None:
        return
    length, stroke = 0.5, 0.025
    level = H * length / (length - stroke)
    exact = RHO * G * level ** 2 / 2.0
    loads = pd.read_csv(os.path.join(directory, "loads.csv"), comment="#")
    t = loads["time"].to_numpy()
    force = interval_mean(t, -loads["paddle_fx"].to_numpy(), 2.5, 3.5)
    before = interval_mean(t, -loads["paddle_fx"].to_numpy(), 0.0, 0.2)
    error = force / exact - 1.0
    print(f"     stop: at rest the box carries {force:.3f} N/m (mean over 2.5-3.5 s) against rho g h'^2 / 2 = "
          f"{exact:.3f} N/m, h' = {level:.6f} m ({error:+.2%}); before the push {before:.3f} N/m against "
          f"rho g h^2 / 2 = {RHO * G * H ** 2 / 2.0:.3f} N/m", flush=True)
    checks.check(abs(error) <= 0.01, "stop: the load settles to the hydrostatic force of the raised level within 1 %",
                 f"{error:+.2%}")
    check_nothing_lost(checks, directory, "stop")


def check_cylinder(checks, flotsam, scenes):
    directory = run(checks, flotsam, scenes, "cylinder", ["cylinder.csv"])
    if directory is None:
        return
    table = np.genfromtxt(os.path.join(scenes, FOLDER, "cylinder.csv"), delimiter=",", comments="#", skip_header=1)
    centre, radius, cell = np.array([0.2, 0.12]), 0.04, 0.0125
    deepest, inside, outputs = 0.0, 0, 0
    for path in sorted(glob.glob(os.path.join(directory, "fields", "fields_*.h5"))):
        with h5py.File(path) as f:
            t = float(f.attrs["time"])
            x = f["particles/position"][:, :2]
        now = centre + [np.interp(t, table[:, 0], table[:, 1]), np.interp(t, table[:, 0], table[:, 2])]
        phi = np.linalg.norm(x - now, axis=1) - radius
        deepest = max(deepest, float(-phi.min()))
        inside += int(np.count_nonzero(phi < -1e-9 * cell))
        outputs += 1
    checks.check(outputs == 21 and inside == 0,
                 f"cylinder: no particle inside the moving circle at any of {outputs} outputs (deepest "
                 f"{deepest:.1e} m)", f"{inside} particle-outputs inside")
    check_nothing_lost(checks, directory, "cylinder")


def check_lift(checks, flotsam, scenes):
    table = np.genfromtxt(os.path.join(scenes, FOLDER, "lift.csv"), delimiter=",", comments="#", skip_header=1)
    directory = run(checks, flotsam, scenes, "lift", ["lift.csv"])
    if directory is None:
        return
    bodies = pd.read_csv(os.path.join(directory, "bodies.csv"), comment="#")
    loads = pd.read_csv(os.path.join(directory, "loads.csv"), comment="#")
    t = bodies["time"].to_numpy()
    # the platform's displacement, and its velocity over the 1 ms step that ends at the row's time
    d = np.interp(t, table[:, 0], table[:, 2])
    v = (d - np.interp(t - 1.0e-3, table[:, 0], table[:, 2])) / 1.0e-3
    speed = np.abs(bodies["box_vy"].to_numpy() - v).max()
    place = np.abs(bodies["box_y"].to_numpy() - 0.1 - (0.2 + d)).max()
    checks.check(speed <= 1e-9 and place <= 1e-9,
                 f"lift: the crate moves with the platform (velocity to {speed:.1e} m/s, its bottom on the "
                 f"platform's top to {place:.1e} m, {len(t)} rows)")
    mass = 500.0 * 0.3 * 0.2
    tl = loads["time"].to_numpy()
    force = -loads["platform_fy"].to_numpy()
    steady = tl > 0.32
    weight = np.abs(force[steady] / (mass * G) - 1.0).max()
    checks.check(weight <= 1e-9, f"lift: at constant speed the platform carries M g = {mass * G:.2f} N/m "
                 f"(largest relative deviation {weight:.1e})")
    widths = np.diff(np.concatenate(([0.0], tl)))
    impulse = float(np.sum(force * widths))
    expected = mass * G * tl[-1] + mass * 0.2
    checks.check(abs(impulse / expected - 1.0) <= 1e-9,
                 f"lift: impulse on the platform over 0-{tl[-1]:g} s {impulse:.6f} N s/m = M g t + M U = "
                 f"{expected:.6f} N s/m ({impulse / expected - 1.0:+.1e})")


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("flotsam")
    parser.add_argument("mpiexec")
    parser.add_argument("scenes", help="tests/runs/scenes")
    parser.add_argument("scripts", nargs="?")
    parser.add_argument("--figures", default=None)
    parser.add_argument("--ranks", type=int, default=2)
    arguments = parser.parse_args()
    checks = Checks()
    flotsam = Flotsam(arguments.flotsam, arguments.mpiexec, "output")
    scenes = os.path.abspath(arguments.scenes)
    figures = os.path.abspath(arguments.figures) if arguments.figures else None
    started = time.time()
    check_lift(checks, flotsam, scenes)
    check_cylinder(checks, flotsam, scenes)
    check_stop(checks, flotsam, scenes)
    check_piston(checks, flotsam, scenes, arguments.ranks, figures, folder=FOLDER,
                 table=os.path.join("..", "moving_walls", "piston.csv"), label="structure_piston", gauge_x=0.5)
    if os.path.exists(flotsam.path("structure_piston", "diagnostics.csv")):
        check_nothing_lost(checks, flotsam.path("structure_piston"), "structure_piston")
    check_restart_and_ranks(checks, arguments.flotsam, arguments.mpiexec, scenes, folder=FOLDER,
                            scene="cylinder.nml", tables=("cylinder.csv",), end_time=0.4, label="cylinder")
    print(f"total {time.time() - started:.0f} s", flush=True)
    return checks.summary()


if __name__ == "__main__":
    raise SystemExit(main())
