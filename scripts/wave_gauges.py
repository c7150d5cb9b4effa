#!/usr/bin/env python3
"""The regular waves a run's piston made, as its level gauges read them (docs/validation.md, "Regular waves
from a piston"; the theory in docs/theory.md section 3.8).

usage: scripts/wave_gauges.py <output folder> [--wall NAME] [--start S] [--end S] [--csv FILE] [--check]
       (installed: flotsam-wave-gauges)

Reads the run's resolved scene.nml (the `&wall` or `&structure` with motion = 'regular_wave': its height H,
period T, depth h, order, ramp and start; `&gravity`; the `&gauge` groups of kind 'level') and gauges.csv.
Per level gauge, at distance x from the paddle along its stroke, over a window of whole periods from
t_s + ramp + x / c_g + 2 T (the middle of the ramp travels at the group velocity c_g; two periods more
for the wave train to settle) to --end (default: the last row), the least-squares fit of
eta = m + sum_n a_n cos(n w t + phi_n), n = 1, 2, 3, with the frequency w that fits best (within 10 % of
the paddle's):

  height              2 a1: crest to trough of a second-order Stokes wave (the second harmonic adds the
                      same to crest and trough); the level gauge's particle noise averages out of the
                      fit, where a zero-crossing analysis would count its wiggles as waves
  period              2 pi / w
  a2, a3              against the bound Stokes second harmonic (H^2 k / 16) cosh kh (2 + cosh 2kh) / sinh^3 kh:
                      a free second harmonic (a first-order paddle's) beats with it along the flume
  mean_level          m, the mean surface over the window above the still water level h

and over all the gauges, in the window common to them, the second harmonic's complex amplitude at each
fitted as B exp(-2ikx) + F exp(-i k2 x): the bound harmonic B (against Stokes') and the free one F that a
first-order paddle also makes (Madsen's second-order stroke removes it), with what neither explains.
The first harmonic over the gauges likewise as A exp(-ikx) + R exp(ikx) (Mansard & Funke 1980's least
squares, with any number of gauges from 3): the incident and the reflected wave and the reflection
coefficient |R| / |A|, over --start .. --end when given (a window after the far end's reflection has
arrived; default: the common window as for the second harmonic).

Prints a table and (--csv) writes it (read with pandas.read_csv(path, comment='#')). --check: exit status 1
unless the height is within 5 % of H and the period within 1 % of T at every gauge (issue 54's criteria).
Exit status 2 on a folder without a regular wave or level gauges.
"""

import argparse
import math
import os
import re
import sys

HEIGHT_TOLERANCE = 0.05
PERIOD_TOLERANCE = 0.01


def fail(message):
    print(f"wave_gauges.py: error: {message}", file=sys.stderr)
    sys.exit(2)


def scene_groups(path, group):
    """The `&group` blocks of a resolved scene.nml (one variable per line) as {variable: text}."""
    text = re.sub(r"!.*", "", open(path, encoding="utf-8").read())
    blocks = []
    for match in re.finditer(r"^\s*&" + group + r"\b(.*?)^\s*/", text, re.S | re.M | re.I):
        values = {}
        for item in re.finditer(r"^\s*(\w+)\s*=\s*(.+?)\s*,?\s*$", match.group(1), re.M):
            values[item.group(1).lower()] = item.group(2).strip()
        blocks.append(values)
    return blocks


def numbers(text):
    return [float(v) for v in re.split(r"[,\s]+", text.strip()) if v]


def word(text):
    """A keyword's value (compared without case)."""
    return text.strip().strip("'\"").lower()


def name_of(text):
    """A name's value (as the CSV columns spell it)."""
    return text.strip().strip("'\"")


def biesel(kh):
    """Biesel's piston transfer function H / S = 2 (cosh 2kh - 1) / (sinh 2kh + 2kh) (2 beyond kh = 20)."""
    kh = min(kh, 20.0)
    return 4 * math.sinh(kh)**2 / (math.sinh(2 * kh) + 2 * kh)


def wavenumber(omega, depth, g):
    """The root of omega^2 = g k tanh(k h) (Newton from Eckart's approximation)."""
    k = omega**2 / g / math.sqrt(math.tanh(omega**2 / g * depth))
    for _ in range(50):
        f = g * k * math.tanh(k * depth) - omega**2
        slope = g * math.tanh(k * depth) + (g * k * depth / math.cosh(k * depth)**2 if k * depth < 20 else 0.0)
        k -= f / slope
        if abs(f) <= 1e-14 * omega**2:
            break
    return k


class Wave:
    """The paddle's regular wave of the scene: H, T, h, order, ramp, start, paddle point and direction."""

    def __init__(self, scene, name):
        candidates = []
        for group in ("wall", "structure"):
            for block in scene_groups(scene, group):
                if word(block.get("motion", "'none'")) == "regular_wave" and (name is None or name_of(block["name"]) == name):
                    candidates.append((group, block))
        if not candidates:
            fail(f"{scene}: no &wall or &structure with motion = 'regular_wave'" + (f" named '{name}'" if name else ""))
        group, block = candidates[0]
        self.name = name_of(block["name"])
        self.height = float(block["wave_height"])
        self.period = float(block["wave_period"])
        self.depth = float(block["water_depth"])
        self.order = int(block.get("wave_order", "2"))
        self.ramp = float(block.get("ramp_time", "0"))
        self.start = float(block.get("motion_start", "0"))
        if group == "wall":
            self.point = numbers(block["point"])
            direction = numbers(block["normal"])
        else:
            self.point = numbers(block.get("centre", "0, 0, 0"))
            direction = numbers(block["motion_direction"])
        length = math.sqrt(sum(d * d for d in direction))
        self.direction = [d / length for d in direction]
        gravity = scene_groups(scene, "gravity")
        self.g = math.sqrt(sum(a * a for a in numbers(gravity[0]["acceleration"]))) if gravity else 9.81
        self.omega = 2 * math.pi / self.period
        self.k = wavenumber(self.omega, self.depth, self.g)
        kh = self.k * self.depth
        self.length = 2 * math.pi / self.k
        self.celerity = self.omega / self.k
        self.group_velocity = 0.5 * self.celerity * (1 + 2 * kh / math.sinh(2 * kh))
        self.bound_second = self.height**2 * self.k / 16 * math.cosh(kh) * (2 + math.cosh(2 * kh)) / math.sinh(kh)**3
        # the free second harmonic's wavenumber: (2 omega)^2 = g k2 tanh(k2 h)
        self.k2 = wavenumber(2 * self.omega, self.depth, self.g)
        self.beat_length = 2 * math.pi / abs(2 * self.k - self.k2)
        # the free second harmonic of a first-order paddle: what Madsen's stroke X2 sin 2wt cancels, the
        # wave that stroke alone makes, m1(k2 h) X2 (Biesel at 2 omega)
        x2 = self.height**2 / (32 * self.depth) * (3 * math.cosh(kh) / math.sinh(kh)**3 - 2 / biesel(kh))
        self.free_first_order = abs(x2) * biesel(self.k2 * self.depth)

    def distance(self, point):
        return sum((p - q) * d for p, q, d in zip(point, self.point, self.direction))


def harmonic_coefficients(tt, eta, omega):
    """Least squares of eta = m + sum_n (a_n cos n omega t + b_n sin n omega t), n = 1..3: the coefficients
    [m, a_1, b_1, a_2, b_2, a_3, b_3] and the sum of the squared residuals."""
    import numpy as np
    columns = [np.ones_like(tt)]
    for n in (1, 2, 3):
        columns += [np.cos(n * omega * tt), np.sin(n * omega * tt)]
    matrix = np.column_stack(columns)
    coefficients, *_ = np.linalg.lstsq(matrix, eta, rcond=None)
    return coefficients, float(np.sum((matrix @ coefficients - eta)**2))


def harmonic_fit(tt, eta, omega):
    """harmonic_coefficients as (m, the amplitudes of n = 1..3, residual)."""
    coefficients, residual = harmonic_coefficients(tt, eta, omega)
    return coefficients[0], [math.hypot(coefficients[2 * n - 1], coefficients[2 * n]) for n in (1, 2, 3)], residual


def analyse(t, level, wave, x, start, end):
    """The gauge's window, the frequency that fits it best and the harmonics at that frequency."""
    first = wave.start + wave.ramp + x / wave.group_velocity + 2 * wave.period if start is None else start
    last = t[-1] if end is None else end
    periods = math.floor((last - first) / wave.period + 1e-9)
    if periods < 2:
        return None
    last = first + periods * wave.period
    inside = (t >= first) & (t <= last)
    tt, eta = t[inside], level[inside] - wave.depth
    # the frequency: golden-section search of the residual within 10 % of the paddle's
    lo, hi = 0.9 * wave.omega, 1.1 * wave.omega
    ratio = (math.sqrt(5) - 1) / 2
    for _ in range(60):
        a, b = hi - ratio * (hi - lo), lo + ratio * (hi - lo)
        if harmonic_fit(tt, eta, a)[2] < harmonic_fit(tt, eta, b)[2]:
            hi = b
        else:
            lo = a
    omega = 0.5 * (lo + hi)
    mean, harmonics, _ = harmonic_fit(tt, eta, omega)
    return dict(start=first, end=last, periods=periods, height=2 * harmonics[0], period=2 * math.pi / omega,
                a1=harmonics[0], a2=harmonics[1], a3=harmonics[2], mean_level=float(mean))


def common_window(t, wave, distances, start=None, end=None):
    """The window of whole periods common to the gauges at `distances` (from after the ramp has passed
    the farthest, or `start`, to the last row or `end`): (first, last), None below 2 periods."""
    first = wave.start + wave.ramp + max(distances) / wave.group_velocity + 2 * wave.period if start is None else start
    periods = math.floor(((t[-1] if end is None else end) - first) / wave.period + 1e-9)
    if periods < 2:
        return None
    return first, first + periods * wave.period


def split_across(t, series, wave, distances, n, wavenumbers, window):
    """Each gauge's complex amplitude c(x) of exp(i n omega t) at the paddle's frequency over `window`,
    fitted as sum_j C_j exp(-i kappa_j x) for the given wavenumbers kappa_j: (|C_j|, the RMS of what they
    leave unexplained)."""
    import numpy as np
    inside = (t >= window[0]) & (t <= window[1])
    tt = t[inside]
    amplitudes = []
    for level in series:
        coefficients, _ = harmonic_coefficients(tt, level[inside] - wave.depth, wave.omega)
        amplitudes.append(coefficients[2 * n - 1] - 1j * coefficients[2 * n])
    x = np.asarray(distances)
    amplitudes = np.asarray(amplitudes)
    basis = np.column_stack([np.exp(-1j * kappa * x) for kappa in wavenumbers])
    solution, *_ = np.linalg.lstsq(basis, amplitudes, rcond=None)
    return [abs(c) for c in solution], float(np.sqrt(np.mean(np.abs(amplitudes - basis @ solution)**2)))


def second_harmonic_across(t, series, wave, distances):
    """The second harmonic over the gauges: B exp(-2ikx) + F exp(-i k2 x), the bound harmonic (travelling
    with the wave) and the free one (at its own wavenumber k2), with the RMS of what neither explains. None
    with fewer than 3 gauges or 2 periods."""
    window = common_window(t, wave, distances) if len(distances) >= 3 else None
    if window is None:
        return None
    (bound, free), residual = split_across(t, series, wave, distances, 2, [2 * wave.k, wave.k2], window)
    return dict(start=window[0], end=window[1], bound=bound, free=free, residual=residual, gauges=len(distances))


def reflection_across(t, series, wave, distances, start=None, end=None):
    """The first harmonic over the gauges as an incident and a reflected wave, A exp(-ikx) + R exp(ikx)
    (Mansard & Funke 1980's least squares, with any number of gauges at least 3): their amplitudes and the
    reflection coefficient |R| / |A|. None with fewer than 3 gauges or 2 periods."""
    window = common_window(t, wave, distances, start, end) if len(distances) >= 3 else None
    if window is None:
        return None
    (incident, reflected), residual = split_across(t, series, wave, distances, 1, [wave.k, -wave.k], window)
    return dict(start=window[0], end=window[1], incident=incident, reflected=reflected,
                coefficient=reflected / incident, residual=residual, gauges=len(distances))


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("folder")
    parser.add_argument("--wall", default=None, help="the paddle's name (default: the first regular_wave)")
    parser.add_argument("--start", type=float, default=None, help="the window's start at every gauge [s]")
    parser.add_argument("--end", type=float, default=None, help="the window's end [s] (default: the last row)")
    parser.add_argument("--csv", default=None, help="write the table here")
    parser.add_argument("--check", action="store_true")
    arguments = parser.parse_args()
    import pandas as pd
    scene = os.path.join(arguments.folder, "scene.nml")
    gauges_csv = os.path.join(arguments.folder, "gauges.csv")
    for path in (scene, gauges_csv):
        if not os.path.isfile(path):
            fail(f"{path}: no such file (a run's output folder has scene.nml and gauges.csv)")
    wave = Wave(scene, arguments.wall)
    levels = [(name_of(g["name"]), numbers(g["point"])) for g in scene_groups(scene, "gauge") if word(g["kind"]) == "level"]
    if not levels:
        fail(f"{scene}: no &gauge of kind 'level'")
    data = pd.read_csv(gauges_csv, comment="#")
    t = data["time"].to_numpy()
    print(f"paddle '{wave.name}': H = {wave.height:g} m, T = {wave.period:g} s, h = {wave.depth:g} m, order "
          f"{wave.order}: kh = {wave.k * wave.depth:.3f}, L = {wave.length:.4f} m, c = {wave.celerity:.4f} m/s, "
          f"c_g = {wave.group_velocity:.4f} m/s, bound second harmonic {1000 * wave.bound_second:.3f} mm")
    rows, ok = [], True
    print(f"{'gauge':>8} {'x [m]':>7} {'window [s]':>15} {'Ts':>5} {'H [m]':>8} {'H err':>7} {'T [s]':>7} "
          f"{'T err':>7} {'a1 [mm]':>8} {'a2 [mm]':>8} {'a3 [mm]':>8} {'mean [mm]':>9}")
    for name, point in levels:
        x = wave.distance(point)
        result = analyse(t, data[f"{name}_level"].to_numpy(), wave, x, arguments.start, arguments.end)
        if result is None:
            print(f"{name:>8} {x:7.3f}   (window shorter than two periods: not analysed)")
            continue
        height_error = result["height"] / wave.height - 1
        period_error = result["period"] / wave.period - 1
        ok = ok and abs(height_error) <= HEIGHT_TOLERANCE and abs(period_error) <= PERIOD_TOLERANCE
        print(f"{name:>8} {x:7.3f} {result['start']:7.2f}-{result['end']:7.2f} {result['periods']:5d} "
              f"{result['height']:8.5f} {100 * height_error:+6.2f}% {result['period']:7.4f} {100 * period_error:+6.2f}% "
              f"{1000 * result['a1']:8.3f} {1000 * result['a2']:8.3f} {1000 * result['a3']:8.3f} "
              f"{1000 * result['mean_level']:+9.2f}")
        rows.append([name, x, result["start"], result["end"], result["periods"], result["height"], height_error,
                     result["period"], period_error, result["a1"], result["a2"], result["a3"], result["mean_level"]])
    across = second_harmonic_across(t, [data[f"{name}_level"].to_numpy() for name, _ in levels], wave,
                                    [wave.distance(point) for _, point in levels])
    if across:
        print(f"second harmonic over the {across['gauges']} gauges ({across['start']:.2f}-{across['end']:.2f} s): "
              f"bound {1000 * across['bound']:.3f} mm (Stokes {1000 * wave.bound_second:.3f} mm), free "
              f"{1000 * across['free']:.3f} mm (a first-order paddle's by Madsen: {1000 * wave.free_first_order:.3f} mm; beat "
              f"length {wave.beat_length:.3f} m), unexplained "
              f"{1000 * across['residual']:.3f} mm RMS per gauge")
    reflection = reflection_across(t, [data[f"{name}_level"].to_numpy() for name, _ in levels], wave,
                                   [wave.distance(point) for _, point in levels], arguments.start, arguments.end)
    if reflection:
        print(f"first harmonic over the {reflection['gauges']} gauges ({reflection['start']:.2f}-{reflection['end']:.2f} s): "
              f"incident {1000 * reflection['incident']:.3f} mm, reflected {1000 * reflection['reflected']:.3f} mm, "
              f"reflection coefficient {reflection['coefficient']:.3f}, unexplained {1000 * reflection['residual']:.3f} mm "
              "RMS per gauge")
    if arguments.csv:
        header = ["gauge", "x", "window_start", "window_end", "periods", "height", "height_error", "period",
                  "period_error", "a1", "a2", "a3", "mean_level"]
        with open(arguments.csv + ".tmp", "w", encoding="utf-8") as out:
            out.write(",".join(header) + "\n")
            out.write(f"# wave_gauges.csv: the regular waves of paddle '{wave.name}' at the level gauges of run "
                      f"{os.path.abspath(arguments.folder)} (scripts/wave_gauges.py)\n")
            out.write(f"# target: H = {wave.height:g} m, T = {wave.period:g} s, h = {wave.depth:g} m, order {wave.order}; "
                      f"bound Stokes second harmonic {wave.bound_second:.6g} m\n")
            out.write("# units: x m (from the paddle along its stroke); window_start, window_end, period s; periods "
                      "count (whole periods in the window); height, a1, a2, a3, mean_level m (mean_level: above still water); *_error relative\n")
            if reflection:
                out.write(f"# first harmonic over the gauges ({reflection['start']:.6g}-{reflection['end']:.6g} s): "
                          f"incident {reflection['incident']:.6g} m, reflected {reflection['reflected']:.6g} m, "
                          f"reflection coefficient {reflection['coefficient']:.6g}\n")
            if across:
                out.write(f"# second harmonic over the gauges ({across['start']:.6g}-{across['end']:.6g} s): bound "
                          f"{across['bound']:.6g} m, free {across['free']:.6g} m, unexplained {across['residual']:.6g} m "
                          "RMS per gauge\n")
            for row in rows:
                out.write(",".join(str(v) if isinstance(v, str) else f"{v:.9g}" for v in row) + "\n")
        os.replace(arguments.csv + ".tmp", arguments.csv)
    if arguments.check:
        print(("PASS" if ok else "FAIL") + f": height within {100 * HEIGHT_TOLERANCE:g} % and period within "
              f"{100 * PERIOD_TOLERANCE:g} % at every gauge")
        return 0 if ok else 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
