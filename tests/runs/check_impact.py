#!/usr/bin/env python3
"""The impact of an elastic block on a rigid wall against wave theory, at three resolutions (issue 52,
item 5; docs/contact.md, "The impact of an elastic block"). The scene, tests/runs/scenes/impact/
block_on_wall.nml, says the theory: a block of length L, height A, density rho, at speed v stops against
the wall under uniaxial strain (stress rho c_P v), relaxes to the plane-strain bar plateau rho c A v for
2 L / c, and leaves again at v (impulse 2 m v).

At h = 10, 5 and 2.5 mm, from loads.csv (rows every 50 us):
  * the plateau (median of the rows above half the peak) within 5 % of rho c A v, its duration within
    10 % of 2 L / c, the impulse within 5 % of 2 m v;
  * the peak of the rows, and the peak low-passed at 2 kHz (scripts/load_report.py's filter), within
    10 % of the uniaxial-strain value rho c_P A v;
  * converged: the filtered peaks of the three resolutions within 3 % of each other; the impulse's change
    from h to h/2 smaller than from 2h to h (it falls below 2 m v as a finer grid resolves the block's
    vibration modes that keep part of the energy after it leaves: a block of L / A = 1.5 is no 1-D bar).
"""
import math
import os
import sys

import numpy as np
import pandas as pd

from flotsam_run import Checks, Flotsam, main_arguments

RHO, E, NU = 500.0, 5.0e6, 0.25
LENGTH, HEIGHT, SPEED = 0.15, 0.1, 3.0
C_BAR = math.sqrt(E / ((1 - NU ** 2) * RHO))
C_P = math.sqrt(E * (1 - NU) / ((1 + NU) * (1 - 2 * NU)) / RHO)
PLATEAU, FRONT = RHO * C_BAR * HEIGHT * SPEED, RHO * C_P * HEIGHT * SPEED
DURATION, IMPULSE = 2 * LENGTH / C_BAR, 2 * RHO * LENGTH * HEIGHT * SPEED


def measures(folder, signals):
    loads = pd.read_csv(os.path.join(folder, "loads.csv"), comment="#")
    t, f = loads["time"].to_numpy(), loads["x_max_fx"].to_numpy()
    widths = np.diff(np.concatenate([[0.0], t]))
    on = f > 0.5 * f.max()
    event = signals.Event(t, f, True, 2000.0)
    return {"plateau": float(np.median(f[on])), "duration": float(widths[on].sum()), "impulse": float((f * widths).sum()),
            "peak": float(f.max()), "filtered": event.peak}


def main():
    flotsam_path, mpiexec, scenes, rest = main_arguments()
    sys.path.insert(0, os.path.abspath(rest[0]))
    import load_signals
    checks = Checks()
    flotsam = Flotsam(flotsam_path, mpiexec, "impact")
    template = os.path.join(scenes, "impact", "block_on_wall.nml")
    print(f"theory: plateau rho c A v = {PLATEAU:.0f} N/m (c = {C_BAR:.1f} m/s) for 2 L / c = {DURATION * 1e3:.2f} ms, "
          f"front rho c_P A v = {FRONT:.0f} N/m (c_P = {C_P:.1f} m/s), impulse 2 m v = {IMPULSE:.1f} N s/m")
    found = {}
    for h in ("0.01", "0.005", "0.0025"):
        name = f"block_h{h}"
        flotsam.remove(name)
        with open(template) as f:
            text = f.read().replace("cell_size = 0.005", f"cell_size = {h}")
        source = flotsam.path(name + "_template.nml")
        with open(source, "w") as f:
            f.write(text)
        result = flotsam.run(flotsam.scene(source, name + ".nml", name), 2)
        if not checks.check(result.returncode == 0, f"h = {h} m: run", result.stderr[-1500:]):
            continue
        m = found[h] = measures(flotsam.path(name), load_signals)
        label = f"h = {h} m"
        checks.check(abs(m["plateau"] / PLATEAU - 1) <= 0.05, f"{label}: plateau {m['plateau']:.0f} N/m against "
                     f"rho c A v = {PLATEAU:.0f} ({m['plateau'] / PLATEAU - 1:+.1%}, tolerance 5 %)")
        checks.check(abs(m["duration"] / DURATION - 1) <= 0.10, f"{label}: above half the peak for "
                     f"{m['duration'] * 1e3:.2f} ms against 2 L / c = {DURATION * 1e3:.2f} ms "
                     f"({m['duration'] / DURATION - 1:+.1%}, tolerance 10 %)")
        checks.check(abs(m["impulse"] / IMPULSE - 1) <= 0.05, f"{label}: impulse {m['impulse']:.2f} N s/m against "
                     f"2 m v = {IMPULSE:.1f} ({m['impulse'] / IMPULSE - 1:+.1%}, tolerance 5 %)")
        for key, what in (("peak", "peak of the rows"), ("filtered", "peak low-passed at 2 kHz")):
            checks.check(abs(m[key] / FRONT - 1) <= 0.10, f"{label}: {what} {m[key]:.0f} N/m against rho c_P A v = "
                         f"{FRONT:.0f} ({m[key] / FRONT - 1:+.1%}, tolerance 10 %)")
    if len(found) == 3:
        filtered = [m["filtered"] for m in found.values()]
        impulses = [m["impulse"] for m in found.values()]
        spread = (max(filtered) - min(filtered)) / np.median(filtered)
        checks.check(spread <= 0.03, f"converged: the filtered peaks at three h within {spread:.1%} of each other "
                     f"({', '.join(f'{v:.0f}' for v in filtered)} N/m; tolerance 3 %)")
        first, second = abs(impulses[1] - impulses[0]), abs(impulses[2] - impulses[1])
        checks.check(second < first, f"converging: the impulse changes by {first:.2f} then {second:.2f} N s/m "
                     f"({', '.join(f'{v:.2f}' for v in impulses)} N s/m at h = 10, 5, 2.5 mm)")
    return checks.summary()


if __name__ == "__main__":
    raise SystemExit(main())
