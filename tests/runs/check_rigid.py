#!/usr/bin/python3
"""Rigid bodies (`&material model = 'rigid'`, issue 18, item 3; docs/theory.md section 3.7), in whole runs:

  1. a rigid box dropped on the floor (2-D) with a fixed step: before it lands its centroid and velocity
     follow the step's exact sequence v_n = -g n dt, y_n = y_0 - g dt^2 n (n + 1) / 2 to round-off (and
     y_0 - g t^2 / 2 within g dt t / 2); at rest the floor carries its weight M g within 0.5 % and it lies
     on the floor (bottom at y = 0 within 1e-9 m); on 1, 2 and 4 ranks bodies.csv and loads.csv agree
     (check_loads.py's tolerances); with USL and with APIC it rests on the floor under its weight too;
  2. the same in 3-D, turned 20 degrees so an edge lands first: at rest the floor carries M g within
     0.5 %, on 1 and 2 ranks;
  3. a box spinning and drifting in a vacuum (2-D): angle = omega t and velocity unchanged to round-off;
     a box of three different edges tumbling in 3-D: its angular momentum sum m (x - c) x v from the
     fields files stays what it was to round-off (relative 1e-12), its kinetic energy within 1 %;
  4. a floating rigid block (scenes/rigid/floating_rigid.nml, its first 0.3 s, standard MPM water) on 1
     and 2 ranks: bodies.csv and gauges.csv agree (check_loads.py's tolerances);
  4b. a rigid block on a turned &structure incline with Coulomb friction: acceleration g (sin - mu cos)
     within 1e-6 (mu = 0.3, and slip), at rest for mu = 0.6 > tan 30 degrees;
  5. &contact: a rigid box and an elastic block meeting off-centre in a vacuum keep the total momentum
     (1e-12 of either's), do not overlap, stop each other and turn the rigid box;
  6. restart: the dropped box stopped mid-fall and continued from its checkpoint gives bodies.csv and
     loads.csv byte for byte;
  7. bad input: a rigid material given elastic constants or a stabilization, a 2-D angular velocity
     about x: one-line errors naming the file, the group and the
     variable, exit 2, no output folder.
With --long (label validation) instead: Archimedes, a rigid flat block released 2.5 cm above its
equilibrium in a FOAL1 tank (scenes/rigid/floating_rigid.nml) floats at the draft (rho_s / rho_f) H_b
within 2 % (mean over 2-6 s) with the fluid's resultant = its weight within 1 %, on 2 ranks.

usage: check_rigid.py <flotsam> <mpiexec> <tests/runs/scenes> <scripts folder> [--long]"""

import glob
import os

import h5py
import numpy as np

from check_loads import agreement, read
from flotsam_run import Checks, Flotsam, main_arguments

G = 9.81


def run(checks, flotsam, template, name, ranks, **run_values):
    flotsam.remove(name)
    path = flotsam.scene(template, name + ".nml", name, **run_values)
    result = flotsam.run(path, ranks)
    if checks.check(result.returncode == 0, f"{name}: run on {ranks} ranks", result.stderr[-2000:]):
        return flotsam.path(name)
    return None


def check_drop_2d(checks, flotsam, scenes):
    template = os.path.join(scenes, "rigid", "drop_2d.nml")
    runs = {ranks: run(checks, flotsam, template, f"drop_2d_np{ranks}", ranks) for ranks in (1, 2, 4)}
    if runs[1] is None:
        return None
    bodies, loads = read(runs[1], "bodies"), read(runs[1], "loads")
    t = bodies["time"].to_numpy()
    y, vy = bodies["box_y"].to_numpy(), bodies["box_vy"].to_numpy()
    dt, y0, mass = 1.0e-3, 0.4, 500.0 * 0.3 * 0.2
    steps = np.rint(t / dt)
    free = t < 0.2                                    # lands at 0.247 s; its contact looks one cell ahead
    exact_y = y0 - G * dt ** 2 * steps * (steps + 1) / 2
    fall = np.abs(y[free] - exact_y[free]).max()
    speed = np.abs(vy[free] + G * steps[free] * dt).max()
    checks.check(free.sum() > 30 and fall <= 1e-12 and speed <= 1e-12,
                 f"drop_2d: free fall follows the step's sequence y_0 - g dt^2 n (n + 1)/2, v = -g n dt: largest "
                 f"differences {fall:.1e} m, {speed:.1e} m/s ({free.sum()} rows)")
    analytic = np.abs(y[free] - (y0 - G * t[free] ** 2 / 2)).max()
    checks.check(analytic <= G * dt * 0.2 / 2 + 1e-12,
                 f"drop_2d: within {analytic:.1e} m of y_0 - g t^2/2 (at most g dt t / 2 = {G * dt * 0.1:.1e} m)")
    rest = t > 0.4
    force = -loads["floor_fy"].to_numpy()[rest].mean()
    checks.check(abs(force / (mass * G) - 1) <= 0.005,
                 f"drop_2d: at rest the floor carries {force:.4f} N/m, the weight M g = {mass * G:.4f} N/m "
                 f"({(force / (mass * G) - 1) * 100:+.2e} %)")
    bottom = np.abs(y[rest] - 0.1).max()
    checks.check(bottom <= 1e-9 and np.abs(vy[rest]).max() <= 1e-9,
                 f"drop_2d: it rests on the floor (centroid within {bottom:.1e} m of 0.1 m, |v| <= "
                 f"{np.abs(vy[rest]).max():.1e} m/s) after landing without a rebound (largest upward speed "
                 f"{max(vy[t > 0.247].max(), 0.0):.1e} m/s)")
    for ranks in (2, 4):
        if runs[ranks] is not None:
            for file in ("bodies", "loads"):
                agreement(checks, file, read(runs[1], file), read(runs[ranks], file), f"drop_2d: {ranks} ranks against 1")
    for variant, values in [("usl", {"update_scheme": "'USL'"}), ("apic", {"transfer": "'apic'"})]:
        directory = run(checks, flotsam, template, f"drop_2d_{variant}", 2, **values)
        if directory is None:
            continue
        other_loads, other = read(directory, "loads"), read(directory, "bodies")
        force = -other_loads["floor_fy"].to_numpy()[rest].mean()
        checks.check(abs(force / (mass * G) - 1) <= 0.005 and np.abs(other["box_y"].to_numpy()[rest] - 0.1).max() <= 1e-9,
                     f"drop_2d {variant}: at rest on the floor under {force:.4f} N/m (weight {mass * G:.4f})")
    return runs[2]


def check_drop_3d(checks, flotsam, scenes):
    template = os.path.join(scenes, "rigid", "drop_3d.nml")
    runs = {ranks: run(checks, flotsam, template, f"drop_3d_np{ranks}", ranks) for ranks in (1, 2)}
    if runs[1] is None:
        return
    loads, bodies = read(runs[1], "loads"), read(runs[1], "bodies")
    t = loads["time"].to_numpy()
    mass = 500.0 * 0.2 * 0.3 * 0.2
    rest = t > 0.6
    force = -loads["floor_fz"].to_numpy()[rest].mean()
    checks.check(abs(force / (mass * G) - 1) <= 0.005,
                 f"drop_3d: at rest the floor carries {force:.4f} N, the weight M g = {mass * G:.4f} N "
                 f"({(force / (mass * G) - 1) * 100:+.2e} %)")
    speed = np.abs(bodies[["box_vx", "box_vy", "box_vz"]].to_numpy()[bodies["time"].to_numpy() > 0.6]).max()
    checks.check(speed <= 1e-9, f"drop_3d: at rest after tipping onto its face (|v| <= {speed:.1e} m/s)")
    if runs[2] is not None:
        for file in ("bodies", "loads"):
            agreement(checks, file, read(runs[1], file), read(runs[2], file), "drop_3d: 2 ranks against 1")


def fields(directory):
    """Per fields file: time, mass, position, velocity of the particles."""
    result = []
    for path in sorted(glob.glob(os.path.join(directory, "fields", "fields_*.h5"))):
        with h5py.File(path) as f:
            result.append((float(f.attrs["time"]), f["particles/mass"][()], f["particles/position"][()],
                           f["particles/velocity"][()]))
    return result


def check_spin(checks, flotsam, scenes):
    directory = run(checks, flotsam, os.path.join(scenes, "rigid", "spin_2d.nml"), "spin_2d", 2)
    if directory is not None:
        bodies = read(directory, "bodies")
        t = bodies["time"].to_numpy()
        angle = np.abs(bodies["box_angle"].to_numpy() - 3.0 * t).max()
        drift = max(np.abs(bodies["box_vx"].to_numpy() - 0.1).max(), np.abs(bodies["box_vy"].to_numpy()).max())
        checks.check(angle <= 1e-12 and drift <= 1e-12,
                     f"spin_2d: angle = omega t within {angle:.1e} rad, velocity unchanged within {drift:.1e} m/s "
                     f"({len(t)} rows, {t[-1]:.2f} s)")
    directory = run(checks, flotsam, os.path.join(scenes, "rigid", "spin_3d.nml"), "spin_3d", 2)
    if directory is None:
        return
    momenta, energies = [], []
    for _, m, x, v in fields(directory):
        c = (m[:, None] * x).sum(0) / m.sum()
        momenta.append((m[:, None] * np.cross(x - c, v)).sum(0))
        energies.append(0.5 * (m * (v ** 2).sum(1)).sum())
    momenta, energies = np.array(momenta), np.array(energies)
    change = np.abs(momenta - momenta[0]).max() / np.linalg.norm(momenta[0])
    energy = np.abs(energies / energies[0] - 1).max()
    checks.check(len(momenta) >= 5 and change <= 1e-12,
                 f"spin_3d: angular momentum {np.round(momenta[0], 6)} kept to {change:.1e} (relative) over "
                 f"{len(momenta)} outputs")
    checks.check(energy <= 0.01, f"spin_3d: kinetic energy within {energy * 100:.2f} % (the rotation update is "
                                 "explicit: energy is not conserved exactly)")


def check_floating_ranks(checks, flotsam, scenes):
    """The floating block's first 0.3 s with standard MPM water. With FOAL1 the runs part after about
    0.01 s: its oscillation test is a yes/no decision per cell that round-off can flip, and the rigid
    projection spreads the round-off of the ranks' shared-node sums over all of the body's nodes."""
    template = os.path.join(scenes, "rigid", "floating_rigid.nml")
    runs = {}
    for ranks in (1, 2):
        name = f"floating_np{ranks}"
        flotsam.remove(name)
        path = flotsam.scene(template, name + ".nml", name, end_time="0.3")
        result = flotsam.run(path, ranks, "--set", "&material name = 'water', stabilization = 'none' /")
        if checks.check(result.returncode == 0, f"{name}: run on {ranks} ranks", result.stderr[-2000:]):
            runs[ranks] = flotsam.path(name)
    if len(runs) < 2:
        return
    for file in ("bodies", "gauges"):
        agreement(checks, file, read(runs[1], file), read(runs[2], file), "floating (0.3 s): 2 ranks against 1")


def check_incline(checks, flotsam, scenes):
    scene = os.path.join(scenes, "rigid", "incline.nml")
    theta = np.radians(30.0)
    for mu, condition in ((0.3, "friction"), (0.0, "slip"), (0.6, "friction")):
        name = f"incline_{condition}_{mu}".replace(".", "_")
        flotsam.remove(name)
        path = flotsam.scene(scene, name + ".nml", name)
        result = flotsam.run(path, 2, "--set", f"&structure condition = '{condition}', friction = {mu} /")
        if not checks.check(result.returncode == 0, f"{name}: run on 2 ranks", result.stderr[-2000:]):
            continue
        bodies = read(flotsam.path(name), "bodies")
        t, v = bodies["time"].to_numpy(), bodies["block_vx"].to_numpy()
        window = t > 0.1
        acceleration = np.polyfit(t[window], v[window], 1)[0]
        lifted = np.abs(bodies["block_vy"].to_numpy()).max()
        if mu < np.tan(theta):
            exact = G * (np.sin(theta) - mu * np.cos(theta))
            checks.check(abs(acceleration / exact - 1) <= 1e-6 and lifted <= 1e-9,
                         f"incline, {condition} mu = {mu}: acceleration {acceleration:.7g} m/s^2 against g (sin - mu "
                         f"cos) = {exact:.7g} ({acceleration / exact - 1:+.1e}), normal speed <= {lifted:.1e} m/s")
        else:
            checks.check(np.abs(v).max() <= 1e-9, f"incline, mu = {mu} >= tan theta: it stays (speed <= "
                                                  f"{np.abs(v).max():.1e} m/s)")


def check_collision(checks, flotsam, scenes):
    directory = run(checks, flotsam, os.path.join(scenes, "rigid", "collide.nml"), "collide", 2)
    if directory is None:
        return
    bodies = read(directory, "bodies")
    mass = 500.0 * 0.3 * 0.2
    momentum = mass * (bodies["left_vx"].to_numpy() + bodies["right_vx"].to_numpy())
    momentum_y = mass * (bodies["left_vy"].to_numpy() + bodies["right_vy"].to_numpy())
    worst = max(np.abs(momentum).max(), np.abs(momentum_y).max()) / (mass * 0.5)
    gap = (bodies["right_x"].to_numpy() - 0.15) - (bodies["left_x"].to_numpy() + 0.15)
    after = bodies["time"].to_numpy() > 0.45
    checks.check(worst <= 1e-12, f"collide: total momentum kept to {worst:.1e} of either body's")
    checks.check(gap.min() >= 0.0, f"collide: no overlap (smallest gap {gap.min():.4f} m)")
    checks.check(np.abs(bodies["left_vx"].to_numpy()[after]).max() < 0.05 and
                 np.abs(bodies["left_angle"].to_numpy()[-1]) > 0.01,
                 f"collide: the block stops the rigid box (|vx| <= {np.abs(bodies['left_vx'].to_numpy()[after]).max():.3f} "
                 f"m/s after 0.45 s, from 0.5) and turns it ({bodies['left_angle'].to_numpy()[-1]:.3f} rad)")


def check_restart(checks, flotsam, scenes, whole):
    template = os.path.join(scenes, "rigid", "drop_2d.nml")
    name = "drop_2d_split"
    flotsam.remove(name)
    path = flotsam.scene(template, name + ".nml", name, checkpoint_interval_steps=100, max_steps=250)
    result = flotsam.run(path, 2)
    if not checks.check(result.returncode == 0, "restart: the box stopped at step 250 (mid-fall)",
                        result.stderr[-2000:]):
        return
    checkpoint = None
    for candidate in glob.glob(flotsam.path(name, "checkpoints", "checkpoint_*.h5")):
        with h5py.File(candidate) as f:
            if int(f.attrs["step"]) == 200:
                checkpoint = os.path.relpath(candidate, flotsam.workdir)
    if not checks.check(checkpoint is not None, "restart: a checkpoint at step 200"):
        return
    path = flotsam.scene(template, name + "_continue.nml", name)
    result = flotsam.run(path, 2, "--restart", checkpoint)
    checks.check(result.returncode == 0, "restart: continued from step 200", result.stderr[-2000:])
    for file in ("bodies", "loads"):
        with open(os.path.join(whole, file + ".csv")) as f:
            expected = [line for line in f.read().splitlines() if not line.startswith("#")]
        with open(flotsam.path(name, file + ".csv")) as f:
            rows = [line for line in f.read().splitlines() if not line.startswith("#")]
        checks.check(rows == expected and len(rows) > 100,
                     f"restart: {file}.csv byte for byte the uninterrupted run's ({len(expected)} rows; through "
                     f"the landing at 0.247 s)", f"{len(rows)} rows")


def check_errors(checks, flotsam, scenes):
    template = os.path.join(scenes, "rigid", "drop_2d.nml")
    with open(template) as f:
        text = f.read()
    material = "&material name = 'crate', model = 'rigid', density = 500.0 /"
    body = "lower = 0.35, 0.3, upper = 0.65, 0.5,"
    cases = [
        ("rigid_elastic", text.replace(material, material[:-1] + "youngs_modulus = 1.0e9 /"),
         "group &material (1st, name 'crate'): variable youngs_modulus is not used by model 'rigid'"),
        ("rigid_foal1", text.replace(material, material[:-1] + "stabilization = 'FOAL1' /"),
         "group &material (1st, name 'crate'): variable stabilization must be 'none' for model 'rigid'"),
        ("spin_about_x", text.replace(body, body + " angular_velocity = 1.0, 0.0, 0.0,"),
         "variable angular_velocity turns a 2-D body about z only"),
    ]
    for name, scene, expected in cases:
        flotsam.remove(name)
        path = flotsam.path(name + ".nml")
        with open(path, "w") as f:
            f.write(scene.replace("output_dir = 'drop_2d'", f"output_dir = '{name}'"))
        result = flotsam.run(path, 2)
        errors = [line for line in result.stderr.splitlines() if "flotsam: error:" in line]
        checks.check(result.returncode == 2 and len(errors) == 1 and expected in errors[0] and
                     f"{name}.nml" in errors[0] and not os.path.exists(flotsam.path(name)),
                     f"bad input: {name} refused (exit 2, one line: ...{expected}...), no output folder",
                     f"exit {result.returncode}: {errors}")


def check_floating(checks, flotsam, scenes):
    directory = run(checks, flotsam, os.path.join(scenes, "rigid", "floating_rigid.nml"), "floating_rigid", 2)
    if directory is None:
        return
    bodies, gauges = read(directory, "bodies"), read(directory, "gauges")
    t = bodies["time"].to_numpy()
    level = 0.5 * (gauges["level_left_level"].to_numpy() + gauges["level_right_level"].to_numpy())
    draft = level - (bodies["block_y"].to_numpy() - 0.1)
    window = (t > 2.0) & (t <= 6.0)
    expected, weight = 0.5 * 0.2, 500.0 * 0.8 * 0.2 * G
    measured, force = draft[window].mean(), bodies["block_fy"].to_numpy()[window].mean()
    per_second = ", ".join(f"{draft[(t > a) & (t <= a + 1)].mean():.4f}" for a in range(6))
    checks.check(abs(measured / expected - 1) <= 0.02,
                 f"floating_rigid: draft {measured:.4f} m (mean over 2-6 s) against (rho_s/rho_f) H_b = {expected} m: "
                 f"{(measured / expected - 1) * 100:+.2f} % (per second: {per_second})")
    checks.check(abs(force / weight - 1) <= 0.01,
                 f"floating_rigid: the fluid's resultant {force:.2f} N/m against the weight {weight:.2f} N/m: "
                 f"{(force / weight - 1) * 100:+.3f} %")
    angle = np.abs(bodies["block_angle"].to_numpy()).max()
    checks.check(angle <= 0.05, f"floating_rigid: it floats upright (largest angle {angle:.2e} rad)")


def main():
    flotsam_path, mpiexec, scenes, options = main_arguments()
    checks = Checks()
    if "--long" in options:
        check_floating(checks, Flotsam(flotsam_path, mpiexec, "rigid_validation"), scenes)
        return checks.summary()
    flotsam = Flotsam(flotsam_path, mpiexec, "rigid")
    whole = check_drop_2d(checks, flotsam, scenes)
    check_drop_3d(checks, flotsam, scenes)
    check_spin(checks, flotsam, scenes)
    check_floating_ranks(checks, flotsam, scenes)
    check_incline(checks, flotsam, scenes)
    check_collision(checks, flotsam, scenes)
    if whole:
        check_restart(checks, flotsam, scenes, whole)
    check_errors(checks, flotsam, scenes)
    return checks.summary()


if __name__ == "__main__":
    raise SystemExit(main())
