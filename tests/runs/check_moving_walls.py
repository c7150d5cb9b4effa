#!/usr/bin/python3
"""Moving walls (`&wall motion`, issue 18) in whole runs: a piston wavemaker.

1. Solitary wave: inputs/solitary_wave.nml (a flume of depth h = 0.1 m, the piston at x = 0 moved by
   Goring's stroke for a wave of height A, level gauges at x = 0.5, 1.0, 1.5 m: 10 depths apart).
   At each gauge a sech^2 pulse a sech^2((t - t_c) / tau) is fitted to the water level over the part
   above A/4 (a, t_c, tau free): a is the crest height, t_c its arrival.
     - speed: the slope of x against t_c over the gauges (least squares) is c = sqrt(g (h + A)) within 3 %;
     - height: a at x = 1.5 m is within 10 % of a at x = 0.5 m (10 depths of travel);
     - profile: the RMS of (eta - A sech^2(k c (t - t_c))) / A over k c |t - t_c| <= 3 (eta > 0.01 A)
       at x = 1.0 m, the exact pulse of the nominal A placed at the measured crest time, is printed
       (and must be below 15 %).
   Each run prints its numbers; --figures draws the gauges' levels against the exact pulse.
2. Wavemaker force: tests/runs/scenes/moving_walls/piston.nml, a piston pushed at a constant speed U
   into water h deep (a 'table' motion of two rows) makes a bore; after the start-up the force on the
   piston is rho g h1^2 / 2, h1 the depth behind the bore from the shallow-water jump conditions
   (mass h1 (s - U) = h s, momentum), which is rho g h^2 / 2 + rho h1 U s: the hydrostatic force plus
   the momentum flux (docs/loads.md). Within 3 %.

3. Restart and ranks (default mode): the piston stopped at step 610 and continued from its step-600
   checkpoint writes loads.csv and gauges.csv byte for byte; 1 and 2 ranks agree to 1e-10.

Default (the default suite): the solitary wave A/h = 0.3 at 8 cells per depth with 2 x 2 particles per cell
(standard MPM with a 1 % PIC blend, flip_fraction = 0.99, the scene's: speed 3 %, height 10 %, profile), the
same with APIC on quadratic B-splines (healthy run, crest at 0.5 m within 10 % of A, profile), the piston,
restart and ranks. --long (label validation): the scene as it is (16 cells per depth, 3 x 3 particles per
cell) at A/h = 0.3, 0.2 and 0.1 (checked); printed only (2 x 2 particles per cell): A/h = 0.3 and 0.1 at
16 cells per depth, A/h = 0.3 with the default PIC blend (0.95), with C0 and FOAL1 at 8, APIC with bspline2
at A/h = 0.3 and 0.1 at 16 (the height loss per scheme). --wave runs only the waves it names (printed, the
scene's particles per cell), e.g. --wave 0.1,apic,bspline2,16 --wave 0.1,flip_pic,linear,32,0.99.

usage: check_moving_walls.py <flotsam> <mpiexec> <tests/runs/scenes> [<scripts folder>] [--long]
                             [--figures DIR] [--ranks N] [--analyse OUTPUT_FOLDER --ratio A/h]
                             [--wave A/h,TRANSFER,SHAPE,CELLS_PER_DEPTH[,FLIP_FRACTION] ...]"""

import argparse
import math
import os
import re
import sys
import time

import numpy as np
import pandas as pd

from flotsam_run import Checks, Flotsam

G, H, RHO = 9.81, 0.1, 1000.0
GAUGES = {"x05": 0.5, "x10": 1.0, "x15": 1.5}
TOLERANCE = dict(speed=0.03, height=0.10, profile=0.15, force=0.03)


def wave(ratio):
    """Nominal A, k, c of a solitary wave of height ratio * h."""
    a = ratio * H
    return a, math.sqrt(3.0 * a / (4.0 * H ** 3)), math.sqrt(G * (H + a))


def fit_pulse(t, eta, amplitude):
    """Least-squares a sech^2((t - t_c) / tau) over the samples above amplitude/4 of the largest: a, t_c,
    tau. Gauss-Newton from the largest sample (no scipy needed)."""
    top = np.argmax(eta)
    keep = eta > 0.25 * eta[top]
    # the contiguous part around the crest
    lo, hi = top, top
    while lo > 0 and keep[lo - 1]:
        lo -= 1
    while hi < len(eta) - 1 and keep[hi + 1]:
        hi += 1
    ts, ys = t[lo:hi + 1], eta[lo:hi + 1]
    p = np.array([eta[top], t[top], max((ts[-1] - ts[0]) / 4.0, 1e-3)])
    for _ in range(50):
        s = (ts - p[1]) / p[2]
        sech2 = 1.0 / np.cosh(s) ** 2
        model = p[0] * sech2
        d_model = 2.0 * p[0] * sech2 * np.tanh(s) / p[2]
        jac = np.column_stack([sech2, d_model, d_model * s])
        step, *_ = np.linalg.lstsq(jac, ys - model, rcond=None)
        p = p + step
        if np.all(np.abs(step) < 1e-12 * np.maximum(1.0, np.abs(p))):
            break
    return p


def analyse_wave(directory, ratio):
    """The numbers of a solitary-wave run: per gauge the fitted crest, the speed, the height loss, the
    profile error."""
    amplitude, k, c = wave(ratio)
    gauges = pd.read_csv(os.path.join(directory, "gauges.csv"), comment="#")
    t = gauges["time"].to_numpy()
    result = dict(ratio=ratio, amplitude=amplitude, celerity=c, gauges={})
    theta0, r = 3.8, ratio
    t_mid = (theta0 + r * math.tanh(theta0)) / (k * c)
    x_mid = amplitude / (k * H) * math.tanh(theta0)
    for name, x in GAUGES.items():
        level = gauges[f"{name}_level"].to_numpy()
        still = np.median(level[t < 0.2])
        eta = level - still
        # the crest where the exact wave would be, +- 2 / (k c) (later splashes are not the wave)
        expected = t_mid + (x - x_mid) / c
        near = np.abs(t - expected) <= 2.0 / (k * c)
        a, t_c, tau = fit_pulse(t[near], eta[near], amplitude)
        window = np.abs(k * c * (t - t_c)) <= 3.0
        exact = amplitude / np.cosh(k * c * (t[window] - t_c)) ** 2
        rms = float(np.sqrt(np.mean((eta[window] - exact) ** 2)) / amplitude)
        result["gauges"][name] = dict(x=x, height=a, arrival=t_c, tau=tau, peak=float(eta[near].max()), rms=rms,
                                      still=still, expected=expected, t=t, eta=eta)
    xs = np.array([g["x"] for g in result["gauges"].values()])
    arrivals = np.array([g["arrival"] for g in result["gauges"].values()])
    slope = np.polyfit(arrivals, xs, 1)[0]
    result["speed"] = slope
    result["speed_error"] = slope / c - 1.0
    first, last = result["gauges"]["x05"], result["gauges"]["x15"]
    result["height_loss"] = 1.0 - last["height"] / first["height"]
    result["profile_rms"] = result["gauges"]["x10"]["rms"]
    # the speed the measured height would have
    mean_height = np.mean([g["height"] for g in result["gauges"].values()])
    result["speed_error_measured_height"] = slope / math.sqrt(G * (H + mean_height)) - 1.0
    return result


def report_wave(checks, label, result, strict=True):
    r = result
    for name, g in r["gauges"].items():
        print(f"     {label} {name}: crest {g['height'] * 1e3:.2f} mm ({g['height'] / r['amplitude']:.3f} A; "
              f"highest sample {g['peak'] * 1e3:.2f} mm) at t = {g['arrival']:.4f} s, profile RMS "
              f"{g['rms']:.3f} A", flush=True)
    print(f"     {label}: speed {r['speed']:.4f} m/s against c = {r['celerity']:.4f} m/s ({r['speed_error']:+.2%}; "
          f"{r['speed_error_measured_height']:+.2%} against sqrt(g (h + a)) of the measured a); height "
          f"loss over 10 depths {r['height_loss']:+.2%}; profile RMS at x = 1 m {r['profile_rms']:.3f} A", flush=True)
    if strict:
        checks.check(abs(r["speed_error"]) <= TOLERANCE["speed"], f"{label}: speed within 3 %",
                     f"{r['speed_error']:+.2%}")
        checks.check(abs(r["height_loss"]) <= TOLERANCE["height"], f"{label}: height within 10 % over 10 depths",
                     f"{r['height_loss']:+.2%}")
        checks.check(r["profile_rms"] <= TOLERANCE["profile"], f"{label}: profile RMS below 15 % of A",
                     f"{r['profile_rms']:.3f}")


def draw_wave(result, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    amplitude, k, c = wave(result["ratio"])
    figure, axes = plt.subplots(figsize=(8, 3.5))
    for i, (name, g) in enumerate(result["gauges"].items()):
        axes.plot(g["t"], g["eta"] / amplitude, color=f"C{i}", lw=1, label=f"x = {g['x']} m")
        axes.plot(g["t"], 1.0 / np.cosh(k * c * (g["t"] - g["arrival"])) ** 2, color=f"C{i}", ls="--", lw=0.8)
    axes.set_xlabel("time [s]")
    axes.set_ylabel("eta / A")
    axes.set_title(f"solitary wave A/h = {result['ratio']}: gauges (solid), A sech$^2$ at the crest time (dashed)")
    axes.legend(fontsize=8)
    figure.tight_layout()
    figure.savefig(path, dpi=110)
    plt.close(figure)
    print(f"     figure: {path}", flush=True)


def run_wave(checks, flotsam, inputs, ranks, ratio, scheme, cell, figures, strict=True, flip=0.99, transfer="flip_pic",
             shape="linear", ppc=None):
    """The solitary wave of height ratio * h with the anti-locking `scheme` at cell size `cell`, the transfer
    `transfer` ('flip_pic' with flip_fraction `flip`, or 'apic'), the shape functions `shape` and `ppc` x `ppc`
    particles per cell (None: the scene's)."""
    amplitude, k, c = wave(ratio)
    # the crest reaches the last gauge at about the middle of the stroke plus its travel; 0.5 s more
    # shows its back
    stroke_half = (3.8 + ratio) / (k * c)
    end = round(stroke_half + 1.5 / c + 0.5, 2)
    blend = f"flip {flip:g}" if transfer == "flip_pic" else transfer
    particles = "" if ppc is None else f"_ppc{ppc}"
    name = f"solitary_{ratio:g}_{scheme}_{cell:g}_{blend.replace(' ', '')}_{shape}{particles}".replace(".", "p")
    flotsam.remove(name)
    run_values = dict(end_time=end, load_interval=0.002)
    if transfer == "flip_pic":
        run_values["flip_fraction"] = flip
    else:
        run_values["transfer"] = f"'{transfer}'"
    path = flotsam.scene(os.path.join(inputs, "solitary_wave.nml"), name + ".nml", name, **run_values)
    with open(path) as f:
        text = f.read()
    if transfer != "flip_pic":
        # APIC has no blend: the scene's flip_fraction goes
        text = re.sub(r"\n\s*flip_fraction\s*=\s*[0-9.eE+-]+", "", text)
    if ppc is not None:
        text = re.sub(r"particles_per_cell\s*=\s*[0-9]+", f"particles_per_cell = {ppc}", text)
    with open(path, "w") as f:
        f.write(text)
    start = time.time()
    process = flotsam.run(path, ranks, "--overwrite",
                          "--set", f"&material name = 'water', stabilization = '{scheme}' /",
                          "--set", f"&grid cell_size = {cell}, shape_function = '{shape}' /",
                          "--set", f"&wall name = 'paddle', wave_height = {amplitude:.6g} /", timeout=7200)
    seconds = time.time() - start
    label = f"A/h = {ratio:g}, {scheme}, {blend}, {shape}, h/{H / cell:.0f}" + ("" if ppc is None else f", {ppc}x{ppc}")
    if not checks.check(process.returncode == 0, f"{label}: run on {ranks} ranks ({seconds:.0f} s)",
                        process.stderr[-2000:]):
        return None
    result = analyse_wave(flotsam.path(name), ratio)
    report_wave(checks, label, result, strict)
    if figures:
        os.makedirs(figures, exist_ok=True)
        draw_wave(result, os.path.join(figures, f"solitary_wave_{ratio:g}_{scheme}_{transfer}_{shape}.png".replace("0.", "0")))
    print(f"     {label}: {seconds:.0f} s on {ranks} ranks", flush=True)
    return result


def bore(u):
    """Depth h1 behind the bore and its speed s that a piston at speed u makes in water H deep (shallow
    water): mass h1 (s - u) = H s, momentum rho h1 u s = rho g (h1^2 - H^2) / 2; bisection on
    2 u^2 h1^2 = g (h1 - H)^2 (h1 + H)."""
    lo, hi = H * (1.0 + 1e-12), 2.0 * H
    for _ in range(200):
        h1 = 0.5 * (lo + hi)
        if 2.0 * u ** 2 * h1 ** 2 - G * (h1 - H) ** 2 * (h1 + H) > 0.0:
            lo = h1
        else:
            hi = h1
    h1 = 0.5 * (lo + hi)
    return h1, h1 * u / (h1 - H)


def interval_mean(t, values, start, end):
    """Mean over (start, end] of a series whose rows are means over the interval since the previous row."""
    widths = np.diff(np.concatenate(([0.0], t)))
    inside = (t > start) & (t <= end)
    return float(np.sum(values[inside] * widths[inside]) / np.sum(widths[inside]))


def check_piston(checks, flotsam, scenes, ranks, figures, folder="moving_walls", table="piston.csv", label="piston",
                 gauge_x=0.3):
    """The piston of scenes/<folder>/piston.nml (its motion file `table`, relative to that folder): the
    mean force over 1-2 s against rho g h1^2 / 2, the level gauge `behind` at x = gauge_x."""
    folder = os.path.join(scenes, folder)
    flotsam.remove(label)
    path = flotsam.scene(os.path.join(folder, "piston.nml"), label + ".nml", label)
    with open(os.path.join(folder, table)) as source, open(flotsam.path("piston.csv"), "w") as copy:
        copy.write(source.read())
    start = time.time()
    process = flotsam.run(path, ranks, "--overwrite", timeout=3600)
    seconds = time.time() - start
    if not checks.check(process.returncode == 0, f"{label}: run on {ranks} ranks ({seconds:.0f} s)",
                        process.stderr[-2000:]):
        return
    u = 0.1
    h1, s = bore(u)
    exact = RHO * G * h1 ** 2 / 2.0
    loads = pd.read_csv(flotsam.path(label, "loads.csv"), comment="#")
    t = loads["time"].to_numpy()
    force = interval_mean(t, -loads["paddle_fx"].to_numpy(), 1.0, 2.0)
    gauges = pd.read_csv(flotsam.path(label, "gauges.csv"), comment="#")
    inside = (gauges["time"] > 1.0) & (gauges["time"] <= 2.0)
    depth = float(gauges["behind_level"][inside].mean())
    hydrostatic = RHO * G * H ** 2 / 2.0
    error = force / exact - 1.0
    print(f"     {label} U = {u} m/s: bore h1 = {h1:.6f} m (gauge at x = {gauge_x} m: {depth:.6f} m, "
          f"{depth / h1 - 1.0:+.2%}), s = {s:.5f} m/s; force over 1-2 s {force:.3f} N/m against rho g h1^2 / 2 = "
          f"rho g h^2 / 2 + rho h1 U s = {exact:.3f} N/m ({error:+.2%}); the part above the hydrostatic "
          f"{hydrostatic:.2f} N/m: {force - hydrostatic:.3f} against {exact - hydrostatic:.3f} N/m "
          f"({(force - hydrostatic) / (exact - hydrostatic) - 1.0:+.1%})", flush=True)
    checks.check(abs(error) <= TOLERANCE["force"], f"{label}: force within 3 % of rho g h1^2 / 2", f"{error:+.2%}")
    if figures:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        figure, axes = plt.subplots(figsize=(8, 3.5))
        axes.plot(t, -loads["paddle_fx"], lw=0.8, label="piston force (mean over each row's 10 ms)")
        axes.axhline(exact, color="k", ls="--", lw=1, label=f"rho g h1$^2$/2 = {exact:.2f} N/m")
        axes.axhline(hydrostatic, color="C2", ls=":", lw=1, label=f"rho g h$^2$/2 = {hydrostatic:.2f} N/m")
        axes.hlines(force, 1.0, 2.0, color="C3", lw=2, label=f"mean over 1-2 s: {force:.2f} N/m")
        axes.set_xlabel("time [s]")
        axes.set_ylabel("force [N/m]")
        axes.set_title("piston pushed at U = 0.1 m/s into water 0.1 m deep")
        axes.legend(fontsize=8)
        figure.tight_layout()
        path = os.path.join(figures, f"moving_walls_{label}.png")
        figure.savefig(path, dpi=110)
        plt.close(figure)
        print(f"     figure: {path}", flush=True)


def check_restart_and_ranks(checks, flotsam_path, mpiexec, scenes, folder="moving_walls", scene="piston.nml",
                            tables=("piston.csv",), end_time=0.6, interval=300, stop=610, label="piston"):
    """The piston to t = 0.6 s on 2 ranks, checkpoints every 300 steps; again stopped at step 610 and
    continued from the step-600 checkpoint: loads.csv and gauges.csv rows byte for byte; refused once the
    table changed. And the same on 1 rank: loads within 1e-10 relative (of the largest force). Another
    scene of scenes/<folder> likewise (`tables`: its motion files, relative to that folder;
    check_moving_structures.py)."""
    import glob
    import h5py
    folder = os.path.join(scenes, folder)
    checkpoint_step = stop // interval * interval
    runs = {}
    for name, ranks, extra in (("full", 2, ""), ("split", 2, f"\n   max_steps = {stop}"), ("one", 1, "")):
        flotsam = Flotsam(flotsam_path, mpiexec, f"restart_{label}_{name}")
        flotsam.remove("out")
        with open(os.path.join(folder, scene)) as f:
            text = f.read()
        text = re.sub(r"output_dir\s*=\s*'[^']*'", "output_dir = 'out'", text)
        start = text.index("&run")
        end = text.index("\n/", start)
        text = (text[:end] + f"\n   end_time = {end_time}\n   checkpoint_interval_steps = {interval}" + extra +
                text[end:])
        with open(flotsam.path("scene.nml"), "w") as f:
            f.write(text)
        for table in tables:
            with open(os.path.join(folder, table)) as source, \
                    open(flotsam.path(os.path.basename(table)), "w") as copy:
                copy.write(source.read())
        result = flotsam.run("scene.nml", ranks)
        if not checks.check(result.returncode == 0, f"{label} restart: the {name} run on {ranks} ranks",
                            result.stderr[-2000:]):
            return
        runs[name] = flotsam
    split = runs["split"]
    checkpoint = None
    for path in sorted(glob.glob(split.path("out", "checkpoints", "checkpoint_*.h5"))):
        with h5py.File(path) as f:
            if int(f.attrs["step"]) == checkpoint_step:
                checkpoint = os.path.relpath(path, split.workdir)
    if not checks.check(checkpoint is not None, f"{label} restart: a checkpoint at step {checkpoint_step}"):
        return
    with open(split.path("scene.nml")) as f:
        text = f.read().replace(f"\n   max_steps = {stop}", "")
    with open(split.path("continue.nml"), "w") as f:
        f.write(text)
    result = split.run("continue.nml", 2, "--restart", checkpoint)
    checks.check(result.returncode == 0, f"{label} restart: continued from step {checkpoint_step}",
                 result.stderr[-2000:])
    for file in ("loads", "gauges"):
        if not os.path.exists(runs["full"].path("out", file + ".csv")):
            continue
        rows = {}
        for name in ("full", "split"):
            with open(runs[name].path("out", file + ".csv")) as f:
                rows[name] = [line for line in f.read().splitlines() if not line.startswith("#")]
        checks.check(rows["full"] == rows["split"] and len(rows["full"]) > 10,
                     f"{label} restart: {file}.csv rows byte for byte ({len(rows['full'])} lines)",
                     f"{len(rows['split'])} lines against {len(rows['full'])}")
    # the table changes (a row appended that holds the last place a second longer: the same motion, other
    # numbers): a restart from the newest checkpoint (the continuation removed the older ones) is refused
    checkpoint = os.path.relpath(sorted(glob.glob(split.path("out", "checkpoints", "checkpoint_*.h5")))[-1],
                                 split.workdir)
    table = split.path(os.path.basename(tables[0]))
    with open(table) as f:
        original = f.read()
    last = [line for line in original.splitlines() if line.strip() and not line.startswith(("#", "t"))][-1]
    values = last.split(",")
    with open(table, "w") as f:
        f.write(original.rstrip("\n") + "\n" + ",".join([repr(float(values[0]) + 1.0)] + values[1:]) + "\n")
    result = split.run("continue.nml", 2, "--restart", checkpoint)
    with open(table, "w") as f:
        f.write(original)
    errors = [line for line in result.stderr.splitlines() if "flotsam: error:" in line]
    checks.check(result.returncode == 2 and len(errors) == 1 and "motion_checksum" in errors[0],
                 f"{label} restart: refused after the table changed (exit 2, one line naming motion_checksum)",
                 f"exit {result.returncode}: {errors}")
    two = pd.read_csv(runs["full"].path("out", "loads.csv"), comment="#")
    one = pd.read_csv(runs["one"].path("out", "loads.csv"), comment="#")
    scale = float(np.abs(two.drop(columns="time").to_numpy()).max())
    deviation = float(np.abs(two.drop(columns="time").to_numpy() - one.drop(columns="time").to_numpy()).max())
    checks.check(deviation <= 1e-10 * scale, f"{label} ranks: loads.csv on 1 and 2 ranks agree to "
                 f"{deviation / scale:.1e} of the largest force", f"{deviation / scale:.2e}")


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("flotsam", nargs="?")
    parser.add_argument("mpiexec", nargs="?")
    parser.add_argument("scenes", nargs="?", help="tests/runs/scenes")
    parser.add_argument("scripts", nargs="?", help="scripts folder (its sibling inputs/ has solitary_wave.nml)")
    parser.add_argument("--long", action="store_true")
    parser.add_argument("--figures", default=None)
    parser.add_argument("--ranks", type=int, default=2)
    parser.add_argument("--analyse", default=None, help="only analyse this solitary-wave output folder")
    parser.add_argument("--ratio", type=float, default=0.3)
    parser.add_argument("--only-wave", action="store_true", help="no piston run")
    parser.add_argument("--only-piston", action="store_true", help="no solitary-wave run")
    parser.add_argument("--wave", action="append", default=[],
                        help="only these solitary waves, printed (repeatable): A/h,transfer,shape,cells per depth"
                             "[,flip_fraction], e.g. 0.1,apic,bspline2,16")
    arguments = parser.parse_args()
    checks = Checks()
    if arguments.analyse:
        result = analyse_wave(arguments.analyse, arguments.ratio)
        report_wave(checks, os.path.basename(arguments.analyse.rstrip("/")), result)
        if arguments.figures:
            draw_wave(result, os.path.join(arguments.figures, "solitary_wave.png"))
        return checks.summary()
    flotsam = Flotsam(arguments.flotsam, arguments.mpiexec, "output")
    scripts = arguments.scripts or os.path.join(os.path.dirname(__file__), "..", "..", "scripts")
    inputs = os.path.abspath(os.path.join(scripts, "..", "inputs"))
    figures = os.path.abspath(arguments.figures) if arguments.figures else None
    scenes = os.path.abspath(arguments.scenes)
    started = time.time()
    if arguments.wave:
        for text in arguments.wave:
            fields = text.split(",")
            flip = float(fields[4]) if len(fields) > 4 else 0.99
            run_wave(checks, flotsam, inputs, arguments.ranks, float(fields[0]), "none", H / float(fields[3]), figures,
                     strict=False, flip=flip, transfer=fields[1], shape=fields[2])
        print(f"total {time.time() - started:.0f} s", flush=True)
        return checks.summary()
    if arguments.only_piston:
        pass
    elif arguments.long:
        # the scene's set-up (16 cells per depth, 3 x 3 particles per cell, flip_fraction 0.99): checked at
        # all three amplitudes of the issue
        for ratio in (0.3, 0.2, 0.1):
            run_wave(checks, flotsam, inputs, arguments.ranks, ratio, "none", 0.00625, figures)
        # printed, not checked (the height loss per scheme, docs/validation.md): 2 x 2 particles per cell at
        # A/h = 0.3 (9-10 % lost) and 0.1 (26 %), the default PIC blend, C0 and FOAL1 at 8 cells per depth,
        # APIC with quadratic B-splines at 16 (A/h = 0.3: 14 % lost; 0.1: 6 %)
        for ratio, scheme, flip, cell in ((0.3, "none", 0.99, 0.00625), (0.1, "none", 0.99, 0.00625),
                                          (0.3, "none", 0.95, 0.0125), (0.3, "C0", 0.95, 0.0125),
                                          (0.3, "FOAL1", 0.95, 0.0125)):
            run_wave(checks, flotsam, inputs, arguments.ranks, ratio, scheme, cell, None, strict=False, flip=flip, ppc=2)
        for ratio in (0.3, 0.1):
            run_wave(checks, flotsam, inputs, arguments.ranks, ratio, "none", 0.00625, None, strict=False,
                     transfer="apic", shape="bspline2", ppc=2)
    else:
        # 2 x 2 particles per cell (the scene has 3 x 3): at 8 cells per depth they keep the wave (8.5 % lost)
        # at less than half the cost, which the default suite needs
        run_wave(checks, flotsam, inputs, arguments.ranks, 0.3, "none", 0.0125, figures, ppc=2)
        # APIC with the moving wall, on quadratic B-splines (with linear ones APIC blows up where the paddle
        # lifts the free surface through a row of nodes, at any time step: docs/theory.md section 3.6): the run
        # stays healthy, the stroke makes the wave's height and the profile holds (at 8 cells per depth it
        # loses 18 % over 10 depths: printed)
        result = run_wave(checks, flotsam, inputs, arguments.ranks, 0.3, "none", 0.0125, None, strict=False,
                          transfer="apic", shape="bspline2", ppc=2)
        if result:
            crest = result["gauges"]["x05"]["height"] / result["amplitude"]
            checks.check(abs(crest - 1.0) <= TOLERANCE["height"], "APIC, bspline2: crest at x = 0.5 m within 10 % of A",
                         f"{crest:.3f} A")
            checks.check(result["profile_rms"] <= TOLERANCE["profile"], "APIC, bspline2: profile RMS below 15 % of A",
                         f"{result['profile_rms']:.3f}")
    if not arguments.only_wave:
        check_piston(checks, flotsam, scenes, arguments.ranks, figures)
        if not arguments.long:
            check_restart_and_ranks(checks, arguments.flotsam, arguments.mpiexec, scenes)
    print(f"total {time.time() - started:.0f} s", flush=True)
    return checks.summary()


if __name__ == "__main__":
    raise SystemExit(main())
