#!/usr/bin/python3
"""Validation of the load outputs (issue 13) against loads known exactly: loads.csv, gauges.csv and
bodies.csv of three short runs (scenes in tests/runs/scenes/load_validation/, each set-up explained in
its comments):

1. jet.nml: a water jet (&inlet, H = 0.2 m, v = 2 m/s, gravity off) hits the x_max wall normally and
   leaves along it through the open top and bottom of the grid. The mean wall force over 0.8 .. 4.0 s
   (after the transient) is rho v^2 H = 800 N/m within 3 %.
   Its wall_pressure gauges (one cell of wall each, 0.05-0.2 m off the axis) read the free-streamline
   solution of a jet hitting a plate within 10 % (the one on the axis is printed: the stagnation node takes
   less than its share, its neighbours more).
1b. corner_sheet.nml: a 5 cm sheet at 2 m/s along the floor turns up the wall (gravity off): the wall
   force rho v^2 delta = 200 N/m within 3 %, and its wall_pressure gauges 15-100 mm above the floor the
   mirrored free-streamline solution within 10 %; the particle gauges at the same points are printed
   (they read 0.4-0.7 of it: the constraint stops part of the fluid without a pressure).
2. bar.nml: a linear elastic bar (nu = 0, plane strain: c = sqrt(E / rho) = 100 m/s; L = 1 m, A = 0.1 m)
   hits the x_max slip wall at v0 = 1 m/s. The force plateau is rho c A v0 = 10 kN/m within 5 %, the
   contact (full width at half the plateau) lasts 2 L / c = 20 ms within 5 %, and the bar leaves the
   wall (no force afterwards: the wall is unilateral) with a centroid speed within 10 % of v0.
3. floating_block.nml: a 0.4 m x 0.4 m block of rho_s = 500 kg/m^3 released 5 cm above its equilibrium
   in water at rest. Averaged over 2 .. 6 s its draft (level gauges 0.3 m on either side minus the
   block's bottom) is (rho_s / rho_f) H_b = 0.2 m within 2 %, and the resultant force of the water on
   it (bodies.csv block_fy) is its weight M g within 1 % (the net force, gravity included, tends to 0).

Each check prints the measured value, the expected one and the relative error, and each run draws a PNG
(matplotlib, Agg) into the figures folder (--figures, default: the working directory):
load_validation_jet.png, load_validation_corner.png, load_validation_bar.png, load_validation_floating.png.
About 1-2 minutes on 2 cores in the Release build (the floating block is most of it).
The floating block's scene lists how its draft depends on the resolution and the time window.

usage: check_load_validation.py <flotsam> <mpiexec> <tests/runs/scenes> [<scripts folder>]
                                [--figures DIR] [--ranks N] [--only jet,bar,floating]"""

import argparse
import os
import sys
import time

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402

from flotsam_run import Checks, Flotsam  # noqa: E402

# The scenes' numbers (keep in step with tests/runs/scenes/load_validation/*.nml).
JET = dict(rho=1000.0, v=2.0, H=0.2, window=(0.8, 4.0), stagnation_pressure=0.5 * 1000.0 * 2.0 ** 2,
           axis=0.7, wall_gauges={"w_up_05": 0.05, "w_down_05": 0.05, "w_up_10": 0.1, "w_up_20": 0.2})
CORNER = dict(rho=1000.0, v=2.0, delta=0.05, window=(0.5, 0.8),
              wall_gauges={"w_015": 0.015, "w_030": 0.030, "w_060": 0.060, "w_100": 0.100})
BAR = dict(rho=1000.0, E=1.0e7, L=1.0, A=0.1, v0=1.0)
BLOCK = dict(rho_s=500.0, rho_f=1000.0, B=0.4, H=0.4, g=9.81, window=(2.0, 6.0))

TOLERANCE = dict(jet=0.03, plateau=0.05, duration=0.05, rebound=0.10, draft=0.02, weight=0.01, wall_pressure=0.10)


def free_streamline_pressure(distance, width, rho, v):
    """Wall pressure of a 2-D jet of `width` hitting a plate normally, at `distance` from its axis
    (Milne-Thomson's free-streamline solution): p = rho v^2 (1 - s^2) / 2 with s the speed along the wall
    over v, distance = (2 width / pi) (artanh s + arctan s); solved for s by bisection."""
    lo, hi = 0.0, 1.0 - 1e-15
    for _ in range(200):
        s = 0.5 * (lo + hi)
        if 2.0 * width / np.pi * (np.arctanh(s) + np.arctan(s)) < distance:
            lo = s
        else:
            hi = s
    s = 0.5 * (lo + hi)
    return 0.5 * rho * v * v * (1.0 - s * s)


def check_wall_gauges(checks, name, gauges, window, expected, tolerance):
    """Each wall-pressure gauge's mean over the window against its expected pressure."""
    inside = (gauges["time"] > window[0]) & (gauges["time"] <= window[1])
    for gauge, value in expected.items():
        compare(checks, f"{name}: {gauge} (wall pressure)", float(gauges[f"{gauge}_pressure"][inside].mean()),
                value, tolerance, "Pa")


def compare(checks, name, measured, expected, tolerance, unit):
    """Print measured, expected and relative error; pass when the error is within the tolerance."""
    error = (measured - expected) / abs(expected)
    print(f"     {name}: measured {measured:.6g} {unit}, expected {expected:.6g} {unit}, "
          f"relative error {error:+.2%} (tolerance {tolerance:.0%})", flush=True)
    return checks.check(abs(error) <= tolerance, name,
                        f"measured {measured:.6g}, expected {expected:.6g}, error {error:+.2%}")


def read_series(directory, name):
    return pd.read_csv(os.path.join(directory, name), comment="#")


def interval_mean(times, values, start, end):
    """Mean over (start, end] of a series whose rows are means over the interval since the previous row
    (loads.csv, bodies.csv forces): weighted by the interval lengths, so it is the impulse / time."""
    t = np.asarray(times, dtype=float)
    widths = np.diff(np.concatenate(([0.0], t)))
    inside = (t > start) & (t <= end)
    return float(np.sum(np.asarray(values, dtype=float)[inside] * widths[inside]) / np.sum(widths[inside]))


def run_scene(checks, flotsam, scenes, scene, output, ranks):
    flotsam.remove(output)
    path = flotsam.scene(os.path.join(scenes, scene), scene, output)
    start = time.time()
    result = flotsam.run(path, ranks, "--overwrite", timeout=3600)
    seconds = time.time() - start
    ok = checks.check(result.returncode == 0, f"{scene}: run on {ranks} ranks ({seconds:.0f} s)",
                      result.stderr[-2000:])
    return flotsam.path(output) if ok else None


def run_for_loads(checks, flotsam, scenes, scene, output, ranks):
    """Run a scene; its loads.csv and gauges.csv, or None if the run failed."""
    directory = run_scene(checks, flotsam, scenes, scene, output, ranks)
    if directory is None:
        return None
    return read_series(directory, "loads.csv"), read_series(directory, "gauges.csv")


def check_jet(checks, flotsam, scenes, ranks, figures):
    print("--- jet on a wall", flush=True)
    series = run_for_loads(checks, flotsam, scenes, "jet.nml", "jet", ranks)
    if series is None:
        return
    loads, gauges = series
    start, end = JET["window"]
    expected = JET["rho"] * JET["v"] ** 2 * JET["H"]
    force = interval_mean(loads["time"], loads["wall_fx"], start, end)
    compare(checks, "jet: mean wall force rho v^2 H", force, expected, TOLERANCE["jet"], "N/m")
    side = interval_mean(loads["time"], loads["wall_fy"], start, end)
    print(f"     (info) jet: mean wall force along the wall {side:.3g} N/m (0: a slip wall takes no tangential force)", flush=True)
    inside = (gauges["time"] > start) & (gauges["time"] <= end)
    pressure = float(gauges["p_stag_pressure"][inside].mean())
    print(f"     (info, not checked) jet: stagnation pressure gauge {pressure:.0f} Pa, rho v^2 / 2 = "
          f"{JET['stagnation_pressure']:.0f} Pa ({pressure / JET['stagnation_pressure'] - 1:+.1%})", flush=True)
    check_wall_gauges(checks, "jet", gauges, JET["window"],
                      {g: free_streamline_pressure(y, JET["H"], JET["rho"], JET["v"]) for g, y in JET["wall_gauges"].items()},
                      TOLERANCE["wall_pressure"])
    axis = float(gauges["w_axis_pressure"][inside].mean())
    print(f"     (info, not checked) jet: wall pressure on the axis {axis:.0f} Pa against rho v^2 / 2 = "
          f"{JET['stagnation_pressure']:.0f} Pa ({axis / JET['stagnation_pressure'] - 1:+.1%}: the stagnation "
          "node takes less than its share, its neighbours more; docs/loads.md)", flush=True)

    figure, axes = plt.subplots(figsize=(7, 4))
    axes.step(loads["time"], loads["wall_fx"], where="pre", lw=0.8, label="wall_fx (mean over each row's interval)")
    axes.axhline(expected, color="k", ls="--", lw=1, label=r"$\rho v^2 H$ = %.0f N/m" % expected)
    axes.hlines(force, start, end, color="C3", lw=2, label=f"mean over {start}-{end} s: {force:.1f} N/m")
    axes.axhspan(expected * (1 - TOLERANCE["jet"]), expected * (1 + TOLERANCE["jet"]), color="0.85", zorder=0)
    peak = float(loads["wall_fx"].max())
    if peak > 2.5 * expected:       # the water hammer of the jet's head: clipped, its value written
        axes.set_ylim(-0.05 * expected, 2.5 * expected)
        axes.text(float(loads["time"][loads["wall_fx"].idxmax()]), 2.4 * expected, f" impact peak {peak:.0f} N/m",
                  va="top", fontsize=8)
    axes.set_xlabel("time [s]")
    axes.set_ylabel("force on the wall [N/m]")
    axes.set_title("Jet on a wall: H = 0.2 m, v = 2 m/s, gravity off")
    axes.legend(loc="lower right", fontsize=8)
    save(figure, figures, "load_validation_jet.png")


def half_crossing(times, values, level, rising):
    """Time at which the series (values at the midpoints of the row intervals) crosses level, by linear
    interpolation; the first rising or the last falling crossing."""
    t = np.asarray(times, dtype=float)
    middle = t - 0.5 * np.diff(np.concatenate(([0.0], t)))
    f = np.asarray(values, dtype=float)
    above = f > level
    if rising:
        k = int(np.argmax(above))
        i, j = k - 1, k
    else:
        k = len(f) - 1 - int(np.argmax(above[::-1]))
        i, j = k, k + 1
    return middle[i] + (level - f[i]) * (middle[j] - middle[i]) / (f[j] - f[i])


def check_bar(checks, flotsam, scenes, ranks, figures):
    print("--- elastic bar on a rigid wall", flush=True)
    directory = run_scene(checks, flotsam, scenes, "bar.nml", "bar", ranks)
    if directory is None:
        return
    loads = read_series(directory, "loads.csv")
    bodies = read_series(directory, "bodies.csv")
    c = np.sqrt(BAR["E"] / BAR["rho"])
    plateau_expected = BAR["rho"] * c * BAR["A"] * BAR["v0"]
    duration_expected = 2.0 * BAR["L"] / c
    t = loads["time"].to_numpy()
    force = loads["wall_fx"].to_numpy()
    if not checks.check(force.max() > 0.5 * plateau_expected, "bar: the bar hits the wall",
                        f"largest wall force {force.max():.4g} N/m"):
        return
    # the plateau: first a rough one (the median of the rows above a quarter of the expected force),
    # then the contact at half of it, then the mean over the middle 60 % of the contact
    rough = float(np.median(force[force > 0.25 * plateau_expected]))
    begin = half_crossing(t, force, 0.5 * rough, rising=True)
    end = half_crossing(t, force, 0.5 * rough, rising=False)
    duration = end - begin
    plateau = interval_mean(t, force, begin + 0.2 * duration, end - 0.2 * duration)
    compare(checks, "bar: force plateau rho c A v0", plateau, plateau_expected, TOLERANCE["plateau"], "N/m")
    compare(checks, "bar: contact duration 2 L / c (full width at half the plateau)", duration, duration_expected,
            TOLERANCE["duration"], "s")
    # after the contact the wall lets the bar go: from shortly after the end of the contact (the last
    # particles leave the wall within a few rows) the force is 0 for good, and the centroid moves at a
    # constant velocity
    touching = np.nonzero(force != 0.0)[0]
    released = t[touching[-1]]
    free = t > released
    checks.check(released - end <= 0.1 * duration_expected and free.sum() >= 10,
                 "bar: no wall force after the contact (unilateral wall: it lets the bar go)",
                 f"last wall force at {released * 1e3:.2f} ms, contact ended at {end * 1e3:.2f} ms, "
                 f"{free.sum()} rows after it")
    after = bodies["time"].to_numpy() > released
    rebound = -float(bodies["bar_vx"][after].mean())
    compare(checks, "bar: rebound speed (centroid, after the contact) = v0", rebound, BAR["v0"], TOLERANCE["rebound"],
            "m/s")
    impulse = interval_mean(t, force, 0.0, t[-1]) * t[-1]
    mass = BAR["rho"] * BAR["L"] * BAR["A"]
    print(f"     (info) bar: wall impulse {impulse:.4g} N s/m, momentum change of the bar "
          f"{mass * (BAR['v0'] + rebound):.4g} N s/m", flush=True)

    figure, (top, bottom) = plt.subplots(2, 1, figsize=(7, 6), sharex=True)
    top.step(t * 1e3, force / 1e3, where="pre", lw=1, label="wall_fx")
    top.axhline(plateau_expected / 1e3, color="k", ls="--", lw=1, label=r"$\rho c A v_0$ = %.0f kN/m" %
                (plateau_expected / 1e3))
    top.hlines(plateau / 1e3, (begin + 0.2 * duration) * 1e3, (end - 0.2 * duration) * 1e3, color="C3", lw=2,
               label=f"plateau {plateau / 1e3:.2f} kN/m")
    top.annotate("", xy=(end * 1e3, 0.5 * rough / 1e3), xytext=(begin * 1e3, 0.5 * rough / 1e3),
                 arrowprops=dict(arrowstyle="<->", color="C2"))
    top.text(0.5 * (begin + end) * 1e3, 0.5 * rough / 1e3 * 0.8, f"contact {duration * 1e3:.2f} ms "
             f"(2L/c = {duration_expected * 1e3:.0f} ms)", ha="center", va="top", fontsize=8, color="C2")
    top.set_ylabel("force on the wall [kN/m]")
    top.legend(loc="upper right", fontsize=8)
    top.set_title("Elastic bar on a rigid wall: L = 1 m, c = 100 m/s, v0 = 1 m/s")
    bottom.plot(bodies["time"] * 1e3, bodies["bar_vx"], lw=1, label="bar_vx (centroid)")
    bottom.axhline(-BAR["v0"], color="k", ls="--", lw=1, label=r"$-v_0$")
    bottom.set_xlabel("time [ms]")
    bottom.set_ylabel("velocity [m/s]")
    bottom.legend(loc="upper right", fontsize=8)
    save(figure, figures, "load_validation_bar.png")


def check_floating(checks, flotsam, scenes, ranks, figures):
    print("--- floating block", flush=True)
    directory = run_scene(checks, flotsam, scenes, "floating_block.nml", "floating_block", ranks)
    if directory is None:
        return
    bodies = read_series(directory, "bodies.csv")
    gauges = read_series(directory, "gauges.csv")
    if not checks.check(len(bodies) == len(gauges) and np.allclose(bodies["time"], gauges["time"], rtol=0, atol=0),
                        "floating: bodies.csv and gauges.csv share the row times"):
        return
    t = bodies["time"].to_numpy()
    level = 0.5 * (gauges["level_left_level"] + gauges["level_right_level"]).to_numpy()
    bottom = bodies["block_y"].to_numpy() - 0.5 * BLOCK["H"]
    draft = level - bottom
    start, end = BLOCK["window"]
    inside = (t > start) & (t <= end)
    expected_draft = BLOCK["rho_s"] / BLOCK["rho_f"] * BLOCK["H"]
    measured_draft = float(draft[inside].mean())
    compare(checks, f"floating: draft (mean over {start}-{end} s)", measured_draft, expected_draft,
            TOLERANCE["draft"], "m")
    weight = BLOCK["rho_s"] * BLOCK["B"] * BLOCK["H"] * BLOCK["g"]
    force = interval_mean(t, bodies["block_fy"], start, end)
    compare(checks, f"floating: force of the water on the block = M g (mean over {start}-{end} s)", force, weight,
            TOLERANCE["weight"], "N/m")
    print(f"     (info) floating: net force on the block incl. gravity {force - weight:+.3g} N/m; "
          f"draft over each second: " + ", ".join(
              f"{draft[(t > a) & (t <= a + 1)].mean():.4f}" for a in range(int(start), int(end))), flush=True)
    wall_level = gauges["level_wall_level"].to_numpy()
    kept = 1.0 + (expected_draft - 0.15) * BLOCK["B"] / 2.0     # released at draft 0.15 m in a 2 m wide tank
    print(f"     (info) floating: water level at the left wall {wall_level[0]:.4f} m at {t[0]:.2f} s, "
          f"{wall_level[-1]:.4f} m at {t[-1]:.2f} s ({kept:.3f} m if the water kept its volume; FOAL1's "
          f"crowding, docs/volume-conservation.md)", flush=True)

    figure, (top, bottom_axes) = plt.subplots(2, 1, figsize=(7, 6), sharex=True)
    top.plot(t, draft, lw=0.8, label="draft = level (gauges 0.3 m left/right) - block bottom")
    top.axhline(expected_draft, color="k", ls="--", lw=1, label=r"$(\rho_s/\rho_f) H_b$ = %.2f m" % expected_draft)
    top.axhspan(expected_draft * (1 - TOLERANCE["draft"]), expected_draft * (1 + TOLERANCE["draft"]), color="0.85",
                zorder=0)
    top.hlines(measured_draft, start, end, color="C3", lw=2, label=f"mean over {start}-{end} s: {measured_draft:.4f} m")
    top.set_ylabel("draft [m]")
    top.legend(loc="lower right", fontsize=8)
    top.set_title("Floating block: 0.4 m x 0.4 m, 500 kg/m$^3$, released 5 cm high")
    bottom_axes.plot(t, bodies["block_fy"] / weight, lw=0.6, label="block_fy / M g (mean over each row's interval)")
    running = pd.Series(bodies["block_fy"].to_numpy() / weight).rolling(50, center=True).mean()
    bottom_axes.plot(t, running, lw=1.5, color="C3", label="running mean over 0.5 s")
    bottom_axes.axhline(1.0, color="k", ls="--", lw=1)
    bottom_axes.set_ylim(0.5, 1.5)
    bottom_axes.set_xlabel("time [s]")
    bottom_axes.set_ylabel("force of the water / weight")
    bottom_axes.legend(loc="upper right", fontsize=8)
    save(figure, figures, "load_validation_floating.png")


def check_corner(checks, flotsam, scenes, ranks, figures):
    print("--- sheet turning up a wall", flush=True)
    series = run_for_loads(checks, flotsam, scenes, "corner_sheet.nml", "corner_sheet", ranks)
    if series is None:
        return
    loads, gauges = series
    start, end = CORNER["window"]
    expected = CORNER["rho"] * CORNER["v"] ** 2 * CORNER["delta"]
    compare(checks, "corner: mean wall force rho v^2 delta", interval_mean(loads["time"], loads["wall_fx"], start, end),
            expected, TOLERANCE["jet"], "N/m")
    width = 2.0 * CORNER["delta"]        # mirrored in the floor: a jet twice as thick hitting a plate
    profile = {g: free_streamline_pressure(y, width, CORNER["rho"], CORNER["v"]) for g, y in CORNER["wall_gauges"].items()}
    check_wall_gauges(checks, "corner", gauges, CORNER["window"], profile, TOLERANCE["wall_pressure"])
    inside = (gauges["time"] > start) & (gauges["time"] <= end)
    for gauge, value in profile.items():
        particle = float(gauges[f"p_{gauge[2:]}_pressure"][inside].mean())
        print(f"     (info, not checked) corner: particle gauge p_{gauge[2:]} {particle:.0f} Pa, "
              f"{particle / value:.2f} of the wall's pressure {value:.0f} Pa", flush=True)

    heights = np.linspace(0.0, 0.2, 201)
    figure, axes = plt.subplots(figsize=(5, 5))
    axes.plot([free_streamline_pressure(y, width, CORNER["rho"], CORNER["v"]) for y in heights], heights, "k-",
              lw=1.2, label="free-streamline solution")
    for prefix, marker, label in (("w", "o", "wall_pressure gauges (the wall's constraint)"),
                                  ("p", "x", "pressure gauges (the particles next to the wall)")):
        values = [float(gauges[f"{prefix}_{g[2:]}_pressure"][inside].mean()) for g in profile]
        axes.plot(values, list(CORNER["wall_gauges"].values()), marker, ls="none", label=label)
    axes.set_xlabel("pressure on the wall [Pa]")
    axes.set_ylabel("height above the floor [m]")
    axes.set_title("Sheet turning up a wall: 5 cm, 2 m/s, no gravity", fontsize=9)
    axes.legend(fontsize=7)
    save(figure, figures, "load_validation_corner.png")


def save(figure, folder, name):
    os.makedirs(folder, exist_ok=True)
    path = os.path.join(folder, name)
    figure.tight_layout()
    figure.savefig(path, dpi=110)
    plt.close(figure)
    print(f"     figure: {path}", flush=True)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("flotsam")
    parser.add_argument("mpiexec")
    parser.add_argument("scenes", help="tests/runs/scenes (or its load_validation folder)")
    parser.add_argument("scripts", nargs="?", help="scripts folder (not used)")
    parser.add_argument("--figures", default=None, help="folder of the PNGs (default: the working directory)")
    parser.add_argument("--ranks", type=int, default=2, help="MPI ranks of each run (default 2)")
    parser.add_argument("--only", default="jet,corner,bar,floating",
                        help="comma-separated subset of jet, corner, bar, floating")
    arguments = parser.parse_args()

    scenes = os.path.abspath(arguments.scenes)
    if os.path.isdir(os.path.join(scenes, "load_validation")):
        scenes = os.path.join(scenes, "load_validation")
    figures = os.path.abspath(arguments.figures or os.getcwd())
    checks = Checks()
    flotsam = Flotsam(arguments.flotsam, arguments.mpiexec, "output")
    started = time.time()
    selected = arguments.only.split(",")
    unknown = set(selected) - {"jet", "corner", "bar", "floating"}
    if unknown:
        sys.exit(f"--only: unknown checks {sorted(unknown)}")
    for name, check in (("jet", check_jet), ("corner", check_corner), ("bar", check_bar), ("floating", check_floating)):
        if name not in selected:
            continue
        try:
            check(checks, flotsam, scenes, arguments.ranks, figures)
        except Exception as error:       # a missing column or file: count it, go on with the next run
            checks.check(False, f"{name}: reading the run's files", f"{type(error).__name__}: {error}")
    print(f"total {time.time() - started:.0f} s", flush=True)
    return checks.summary()


if __name__ == "__main__":
    raise SystemExit(main())
