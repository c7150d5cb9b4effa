#!/usr/bin/python3
"""Fixed structures (`&structure`, issue 15) in whole runs, against loads and motions known exactly; the
scenes are in tests/runs/scenes/structures/ (each explains its set-up and the exact values):

  1. buoyancy: a circle (2-D) and a box turned by 30 degrees submerged in water at rest feel
     rho g A upward (3 %), no force along x and no moment about their centre (circle: 1e-6 of the
     buoyancy; turned box: 5 %, the first-order error of faces that cut the cells);
  2. elastic bar on a structure: the bar of load_validation/bar.nml against a &structure box instead of
     the x_max wall: force plateau rho c A v0 and contact 2 L / c within 5 % of the exact values and of
     the wall run's;
  3. block on an incline (gravity tilted by 30 degrees, grid turned by 30 degrees): with friction
     mu = 0.3 the acceleration g (sin theta - mu cos theta) within 3 %, with slip g sin theta within 3 %,
     with mu = 0.6 >= tan theta the block stays (velocity below 2 % of what slip would give after
     0.4 s, the drift printed);
  4. ranks: a dam break with debris onto a column outside the initial active region (and a turned box)
     gives the same loads.csv on 1, 2 and 4 ranks (1e-10, check_loads' rule);
  5. restart: the same run stopped at max_steps and continued from a checkpoint writes loads.csv byte
     for byte as the uninterrupted run.
With --long (label validation, structures_validation): the buoyancy of the circle and the turned box at
h = 0.04, 0.02, 0.01 m (within 3 % at each) and of a sphere in 3-D at h = 0.05, 0.04, 1/30 m (the error
must shrink with h), the errors printed per resolution (docs/loads.md).

usage: check_structures.py <flotsam> <mpiexec> <tests/runs/scenes> [<scripts folder>] [--long]"""

import glob
import math
import os
import sys

import numpy as np
import pandas as pd

from flotsam_run import Checks, Flotsam, main_arguments
from check_loads import agreement, copy_scene

RHO, G = 1000.0, 9.81
SETTLED = 0.15         # buoyancy: the mean over SETTLED .. end_time (scene comments)


def read(directory, file):
    return pd.read_csv(os.path.join(directory, file + ".csv"), comment="#")


def run(checks, flotsam, scene, name, ranks, *arguments, timeout=1800):
    flotsam.remove(name)
    path = flotsam.scene(scene, name + ".nml", name)
    result = flotsam.run(path, ranks, *arguments, timeout=timeout)
    ok = checks.check(result.returncode == 0, f"{name}: run on {ranks} ranks", result.stderr[-2000:])
    return flotsam.path(name) if ok else None


def relative(measured, exact):
    return (measured - exact) / abs(exact)


# --- 1: buoyancy ---------------------------------------------------------------------------------------

BUOYANCY = {
    # scene: (structure, exact force, vertical column suffix, size for the moment scale)
    "buoyancy_circle": ("disc", RHO * G * math.pi * 0.2 ** 2, "fy", 0.2),
    "buoyancy_box": ("pontoon", RHO * G * 0.4 * 0.2, "fy", 0.2),
    "buoyancy_sphere": ("ball", RHO * G * 4.0 / 3.0 * math.pi * 0.2 ** 3, "fz", 0.2),
}


def buoyancy(checks, flotsam, scenes, scene, cell_size, ranks=2):
    """The mean loads of the structure over the settled rows; None if the run failed."""
    name = f"{scene}_{cell_size:.4f}".replace(".", "_")
    arguments = ["--set", f"&grid cell_size = {cell_size!r} /"]
    directory = run(checks, flotsam, os.path.join(scenes, "structures", scene + ".nml"), name, ranks, *arguments)
    if directory is None:
        return None
    loads = read(directory, "loads")
    structure = BUOYANCY[scene][0]
    settled = loads[loads["time"] > SETTLED * (1 + 1e-9)]
    return settled[[c for c in loads.columns if c.startswith(structure + "_")]].mean()


def check_buoyancy(checks, flotsam, scenes):
    for scene, sideways_tolerance in (("buoyancy_circle", 1e-6), ("buoyancy_box", 0.05)):
        structure, exact, up, size = BUOYANCY[scene]
        mean = buoyancy(checks, flotsam, scenes, scene, 0.04)
        if mean is None:
            continue
        error = relative(mean[f"{structure}_{up}"], exact)
        checks.check(abs(error) <= 0.03, f"{scene}: upward force {mean[f'{structure}_{up}']:.6g} N/m against "
                                          f"rho g A = {exact:.6g} N/m, error {error:+.2%} (tolerance 3 %, h = 0.04 m)")
        checks.check(abs(mean[f"{structure}_fx"]) <= sideways_tolerance * exact,
                     f"{scene}: force along x {mean[f'{structure}_fx']:.3g} N/m "
                     f"(tolerance {sideways_tolerance:g} of the buoyancy)")
        checks.check(abs(mean[f"{structure}_mz"]) <= sideways_tolerance * exact * size,
                     f"{scene}: moment about the centre {mean[f'{structure}_mz']:.3g} N m/m "
                     f"(tolerance {sideways_tolerance:g} x buoyancy x {size} m)")


def check_buoyancy_convergence(checks, flotsam, scenes):
    for scene, sizes in (("buoyancy_circle", (0.04, 0.02, 0.01)), ("buoyancy_box", (0.04, 0.02, 0.01)),
                         ("buoyancy_sphere", (0.05, 0.04, 1.0 / 30.0))):
        structure, exact, up, size = BUOYANCY[scene]
        errors = []
        for h in sizes:
            mean = buoyancy(checks, flotsam, scenes, scene, h)
            if mean is None:
                return
            errors.append(relative(mean[f"{structure}_{up}"], exact))
            sideways = max(abs(mean[c]) for c in mean.index if not c.endswith(up) and c.endswith(("fx", "fy", "fz")))
            moment = max(abs(mean[c]) for c in mean.index if c.endswith(("mx", "my", "mz")))
            print(f"     {scene}: h = {h:.4g} m (R/h = {size / h:.3g}): upward {mean[f'{structure}_{up}']:.6g} "
                  f"against {exact:.6g}, error {errors[-1]:+.2%}; sideways {sideways / exact:.1e}, "
                  f"moment {moment / (exact * size):.1e} of buoyancy x {size} m", flush=True)
        listed = ", ".join(f"{e:+.2%}" for e in errors)
        if scene == "buoyancy_sphere":
            # coarse in 3-D (R/h = 4 .. 6): a first-order error that must shrink with h
            checks.check(abs(errors[2]) < abs(errors[1]) < abs(errors[0]), f"{scene}: the error shrinks with h: {listed}")
        else:
            checks.check(max(abs(e) for e in errors) <= 0.03, f"{scene}: within 3 % at every h: {listed}")


# --- 2: the elastic bar -----------------------------------------------------------------------------------

def bar_contact(t, force, scale):
    """(plateau, duration) of a force history as check_load_validation.py measures them."""
    from check_load_validation import half_crossing, interval_mean
    rough = float(np.median(force[force > 0.25 * scale]))
    begin = half_crossing(t, force, 0.5 * rough, rising=True)
    end = half_crossing(t, force, 0.5 * rough, rising=False)
    duration = end - begin
    return interval_mean(t, force, begin + 0.2 * duration, end - 0.2 * duration), duration


def check_bar(checks, flotsam, scenes):
    plateau_exact, duration_exact = RHO * 100.0 * 0.1 * 1.0, 2.0 * 1.0 / 100.0
    measured = {}
    for label, scene, column in (("wall", os.path.join(scenes, "load_validation", "bar.nml"), "wall_fx"),
                                 ("structure", os.path.join(scenes, "structures", "bar.nml"), "pier_fx")):
        directory = run(checks, flotsam, scene, f"bar_{label}", 2)
        if directory is None:
            return
        loads = read(directory, "loads")
        measured[label] = bar_contact(loads["time"].to_numpy(), loads[column].to_numpy(), plateau_exact)
    (wall_plateau, wall_duration), (plateau, duration) = measured["wall"], measured["structure"]
    for what, value, exact, wall in (("plateau", plateau, plateau_exact, wall_plateau),
                                     ("contact duration", duration, duration_exact, wall_duration)):
        checks.check(abs(relative(value, exact)) <= 0.05 and abs(relative(value, wall)) <= 0.05,
                     f"bar on a structure: {what} {value:.6g} against exact {exact:.6g} "
                     f"({relative(value, exact):+.2%}) and the wall's {wall:.6g} ({relative(value, wall):+.2%}); "
                     "tolerance 5 %")


# --- 3: the incline ---------------------------------------------------------------------------------------

def check_incline(checks, flotsam, scenes):
    theta = math.radians(30.0)
    scene = os.path.join(scenes, "structures", "incline.nml")
    slip_speed = G * math.sin(theta) * 0.4
    for mu, condition in ((0.3, "friction"), (0.0, "slip"), (0.6, "friction")):
        name = f"incline_{condition}_{mu}".replace(".", "_")
        directory = run(checks, flotsam, scene, name, 2, "--set",
                        f"&structure condition = '{condition}', friction = {mu} /")
        if directory is None:
            continue
        bodies = read(directory, "bodies")
        t, v, x = (bodies[c].to_numpy() for c in ("time", "block_vx", "block_x"))
        window = t > 0.1
        acceleration = np.polyfit(t[window], v[window], 1)[0]
        if mu < math.tan(theta):
            exact = G * (math.sin(theta) - mu * math.cos(theta))
            checks.check(abs(relative(acceleration, exact)) <= 0.03,
                         f"incline, {condition} mu = {mu}: acceleration {acceleration:.5g} m/s^2 against "
                         f"g (sin - mu cos) = {exact:.5g} ({relative(acceleration, exact):+.2%}, tolerance 3 %)")
        else:
            checks.check(abs(v[-1]) <= 0.02 * slip_speed,
                         f"incline, mu = {mu} >= tan theta: the block stays: speed {v[-1]:.2e} m/s at "
                         f"{t[-1]:.2g} s (slip: {slip_speed:.3g} m/s), drift {x[-1] - x[0]:.2e} m, "
                         f"fitted acceleration {acceleration:.2e} m/s^2")


# --- 4 and 5: ranks and restart ------------------------------------------------------------------------

def check_ranks(checks, flotsam, scenes):
    scene = os.path.join(scenes, "structures", "column_flow.nml")
    runs = {}
    for ranks in (1, 2, 4):
        directory = run(checks, flotsam, scene, f"column_flow_{ranks}", ranks)
        if directory is not None:
            runs[ranks] = directory
    if 2 not in runs:
        return None
    loads = read(runs[2], "loads")
    checks.check(loads["column_fx"].max() > 10.0,
                 f"column_flow: the flow reaches the column (largest column_fx "
                 f"{loads['column_fx'].max():.4g} N/m; ramp_fx {loads['ramp_fx'].abs().max():.4g} N/m)")
    for ranks in (1, 4):
        if ranks in runs:
            agreement(checks, "loads", loads, read(runs[ranks], "loads"), f"column_flow: {ranks} ranks against 2")
    return runs[2]


def check_restart(checks, flotsam_path, mpiexec, scenes):
    template = os.path.join(scenes, "structures", "column_flow.nml")
    full = Flotsam(flotsam_path, mpiexec, "restart_full")
    split = Flotsam(flotsam_path, mpiexec, "restart_split")
    for flotsam in (full, split):
        flotsam.remove("out")
    with open(template) as f:
        text = f.read().replace("output_dir = 'column_flow'", "output_dir = 'out'")
    for directory in (full.workdir, split.workdir):
        with open(os.path.join(directory, "template.nml"), "w") as f:
            f.write(text)
    copy_scene(os.path.join(full.workdir, "template.nml"), full.workdir, "scene.nml")
    result = full.run("scene.nml", 2)
    if not checks.check(result.returncode == 0, "restart: the uninterrupted run", result.stderr[-2000:]):
        return
    checkpoints = sorted(glob.glob(full.path("out", "checkpoints", "checkpoint_*.h5")))
    steps = int(read(full.path("out"), "diagnostics")["step"].iloc[-1])
    # a checkpoint after the water reached the column (t > 0.13 s), stopped 10 steps later
    import h5py
    chosen = None
    for path in checkpoints:
        with h5py.File(path) as f:
            step, time = int(f.attrs["step"]), float(f.attrs["time"])
        if 0.13 < time and step < steps - 20:
            chosen = (os.path.basename(path), step)
            break
    if not checks.check(chosen is not None, "restart: a checkpoint after the water reached the column"):
        return
    name, step = chosen
    copy_scene(os.path.join(split.workdir, "template.nml"), split.workdir, "scene.nml",
               f"\n   max_steps = {step + 10}")
    result = split.run("scene.nml", 2)
    if not checks.check(result.returncode == 0, f"restart: the run stopped at step {step + 10}", result.stderr[-2000:]):
        return
    result = split.run("scene.nml", 2, "--restart", os.path.join("out", "checkpoints", name),
                       "--set", f"&run max_steps = {10 ** 9} /")
    if not checks.check(result.returncode == 0, f"restart: continued from step {step}", result.stderr[-2000:]):
        return
    rows = {}
    for label, flotsam in (("full", full), ("split", split)):
        with open(flotsam.path("out", "loads.csv")) as f:
            rows[label] = [line for line in f.read().splitlines() if not line.startswith("#")]
    checks.check(rows["full"] == rows["split"] and len(rows["full"]) > 10,
                 f"restart: loads.csv rows byte for byte those of the uninterrupted run ({len(rows['full'])} lines, "
                 f"continued from step {step})", f"{len(rows['split'])} lines")


def main():
    flotsam_path, mpiexec, scenes, rest = main_arguments()
    long = "--long" in rest
    checks = Checks()
    flotsam = Flotsam(flotsam_path, mpiexec, "output")
    if long:
        check_buoyancy_convergence(checks, flotsam, scenes)
    else:
        check_buoyancy(checks, flotsam, scenes)
        check_bar(checks, flotsam, scenes)
        check_incline(checks, flotsam, scenes)
        check_ranks(checks, flotsam, scenes)
        check_restart(checks, flotsam_path, mpiexec, scenes)
    return checks.summary()


if __name__ == "__main__":
    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    raise SystemExit(main())
