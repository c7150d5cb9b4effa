#!/usr/bin/python3
"""Put a run's gauges beside a flume experiment's measurements.

usage: scripts/compare_experiment.py <output folder> <data file> [--plot FILE] [--csv FILE] [--check]
                                     [--times t1,t2,...] [--label TEXT]

<data file> is one of the measured series of the workplace's data/experiments folder; the script knows
them by their columns:

  SPHERIC Test 2 (Kleefsman et al. 2005; columns time, P1..P8, H1..H4; s, Pa, m): pressure sensors on
  the box and water-level gauges. The run's gauges of the same names are compared
  (inputs/validation/spheric_test2.nml names them so).
  Lobovsky et al. 2014, H = 300 mm (columns t_star, p1_star, ...): t* = t sqrt(g/H), p* = p/(rho g H);
  converted to s and Pa with H = 0.3 m, g = 9.81 m/s2, rho = 1000 kg/m3. The run's gauges p1, p2, p3,
  p4 are compared (inputs/validation/lobovsky_h300.nml).
  Lobovsky et al. 2014, H = 300 mm, water levels (columns t_star, H1_etsin01_star, H2_etsin01_star,
  H2_etsin02_star, ...; level* = h/H): the run's level gauges H1 ... H4 are compared with the mean of a
  gauge's series; the NMAE between its two series (the measurement's own scatter) is reported beside.

For every sensor the run has, it reports (one row per sensor and quantity):
  arrival      first time the 10 ms running mean exceeds the threshold (pressure 300 Pa, level 5 mm:
               above the measurements' noise of about +-100 Pa and 1 mm);
  mean@t       10 ms means (t - 5 ms .. t + 5 ms) at the given times (--times; each data set has its own
               default: the times of the checks below);
  peak         the largest 1 ms mean within 50 ms after the arrival (the first impact; the measurement is
               averaged over 1 ms bins first, so that both are seen through the same window);
  nmae         water levels only: the normalised mean absolute error over 0 .. 1.5 s (or to the end of the
               shorter series) of the 10 ms means, mean |sim - exp| / mean |exp|, both on a 1 ms grid;
  scatter      where a gauge was measured twice: the NMAE of one series against the other.
and the ratio or difference against the measurement. --csv writes the table (pandas.read_csv reads it),
--plot one panel per sensor, simulation against measurement (both as 10 ms running means, the raw run
faintly).

--check applies the acceptance criteria of issue 50 (docs/validation.md, "Against flume experiments") and
exits 1 if one fails:
  SPHERIC Test 2: P1 arrival within 0.02 s of the measured; P1-P4 10 ms means at 0.5, 0.6, 0.8, 1.0 s within
  20 %; H2 and H4 NMAE over 0-1.5 s within 10 %; P7 below 200 Pa before 1.0 s (dry until the measured
  wetting).
  Lobovsky H = 300 mm: the 10 ms means at five times in the plateau 0.45-0.70 s (0.475, 0.525, 0.575,
  0.625, 0.675 s) within 20 % at sensor 1 and 25 % at sensors 2 and 3; the first-impact peak at sensor 1
  within a factor 2 of the measured event's (the peaks of repeated dam breaks scatter widely, the file is
  one event: docs/validation.md says why a factor 2).
  Lobovsky H = 300 mm, water levels: H1-H4 NMAE over 0-1.0 s within 10 % (the criterion of the SPHERIC
  levels).
Exit status 2 for unusable input (a missing file, a data file of unknown layout, no sensor in common).
Needs Debian's python3-numpy, python3-pandas and python3-matplotlib.
"""

import argparse
import os
import re
import sys

try:
    import numpy as np
    import pandas as pd
except ImportError:
    if sys.executable != "/usr/bin/python3" and os.path.exists("/usr/bin/python3"):
        os.execv("/usr/bin/python3", ["/usr/bin/python3"] + sys.argv)
    sys.exit("compare_experiment.py: needs numpy and pandas (Debian: python3-numpy python3-pandas)")

GRAVITY = 9.81
WATER_DENSITY = 1000.0
LOBOVSKY_DEPTH = 0.3
PRESSURE_THRESHOLD = 300.0     # Pa: arrival of a pressure sensor
LEVEL_THRESHOLD = 0.005        # m: arrival of a level gauge
MEAN_WINDOW = 0.010            # s: the 10 ms means
PEAK_BIN = 0.001               # s: the bins both series are averaged over before the peak
PEAK_SEARCH = 0.050            # s after the arrival in which the first-impact peak is taken
NMAE_WINDOW = (0.0, 1.5)       # s
LOBOVSKY_LEVEL_WINDOW = (0.0, 1.0)   # s: the scene's length (the reflected bore comes back after it)
LEVEL_COLUMN = re.compile(r"(H\d)_\w+_star")   # Lobovsky's levels: gauge, then the series' label


class Experiment:
    """A measured data set: name, series (time in s, sensors in Pa or m) and its checks."""

    def __init__(self, name, series, pressures, levels, times, checks, scatter=None, nmae_window=NMAE_WINDOW):
        self.name = name
        self.series = series
        self.pressures = pressures
        self.levels = levels
        self.times = times
        self.checks = checks
        self.scatter = scatter or {}   # sensor -> NMAE between two measurements of it
        self.nmae_window = nmae_window


def read_experiment(path):
    table = pd.read_csv(path, comment="#")
    columns = set(table.columns)
    if {"time", "P1", "H4"} <= columns:
        pressures = [f"P{k}" for k in range(1, 9) if f"P{k}" in columns]
        levels = [f"H{k}" for k in range(1, 5) if f"H{k}" in columns]
        return Experiment("SPHERIC Test 2 (Kleefsman et al. 2005)", table[["time"] + pressures + levels],
                          pressures, levels, [0.5, 0.6, 0.8, 1.0], spheric_checks)
    if {"t_star", "p1_star"} <= columns:
        series = pd.DataFrame({"time": table["t_star"] * np.sqrt(LOBOVSKY_DEPTH / GRAVITY)})
        pressures = []
        for column in table.columns:
            if column.endswith("_star") and column != "t_star":
                name = column[:-len("_star")]
                series[name] = table[column] * WATER_DENSITY * GRAVITY * LOBOVSKY_DEPTH
                pressures.append(name)
        return Experiment("Lobovsky et al. 2014, H = 300 mm", series, pressures, [],
                          [0.475, 0.525, 0.575, 0.625, 0.675], lobovsky_checks)
    if "t_star" in columns and any(LEVEL_COLUMN.fullmatch(column) for column in columns):
        return read_lobovsky_levels(table)
    raise ValueError(f"{path}: unknown layout (columns {', '.join(table.columns[:6])} ...): "
                     "expected SPHERIC Test 2 (time, P1..P8, H1..H4) or Lobovsky 2014 (t_star, p1_star, ...)")


def read_lobovsky_levels(table):
    """Lobovsky's levels: one or two series per gauge (H<k>_<series>_star), compared with their mean."""
    time = table["t_star"].to_numpy() * np.sqrt(LOBOVSKY_DEPTH / GRAVITY)
    series = pd.DataFrame({"time": time})
    gauges = {}
    for column in table.columns:
        match = LEVEL_COLUMN.fullmatch(column)
        if match:
            gauges.setdefault(match.group(1), []).append(table[column].to_numpy() * LOBOVSKY_DEPTH)
    scatter = {}
    for gauge, measured in sorted(gauges.items()):
        series[gauge] = np.mean(measured, axis=0)
        if len(measured) == 2:
            scatter[gauge] = nmae(time, measured[0], time, measured[1], LOBOVSKY_LEVEL_WINDOW)
    return Experiment("Lobovsky et al. 2014, H = 300 mm, water levels", series, [], sorted(gauges),
                      [0.4, 0.5, 0.6, 0.8], lobovsky_level_checks, scatter, LOBOVSKY_LEVEL_WINDOW)


def read_run(folder):
    path = os.path.join(folder, "gauges.csv")
    table = pd.read_csv(path, comment="#")
    values = {}
    for column in table.columns:
        for suffix in ("_pressure", "_level"):
            if column.endswith(suffix):
                values[column[:-len(suffix)]] = table[column].to_numpy()
    return table["time"].to_numpy(), values


def window_mean(t, y, centre, width=MEAN_WINDOW):
    inside = (t >= centre - width / 2) & (t < centre + width / 2)
    return float(np.mean(y[inside])) if inside.any() else float("nan")


def running_mean(t, y, width=MEAN_WINDOW):
    """The mean over t - width/2 .. t + width/2 at every sample (cumulative sums; any sampling)."""
    total = np.concatenate([[0.0], np.cumsum(y)])
    lo = np.searchsorted(t, t - width / 2, side="left")
    hi = np.searchsorted(t, t + width / 2, side="left")
    hi = np.maximum(hi, lo + 1)
    return (total[hi] - total[lo]) / (hi - lo)


def arrival(t, y, threshold):
    above = np.nonzero(running_mean(t, y) > threshold)[0]
    return float(t[above[0]]) if above.size else float("nan")


def binned(t, y, width=PEAK_BIN):
    index = np.floor(t / width).astype(np.int64)
    frame = pd.DataFrame({"bin": index, "y": y}).groupby("bin")["y"].mean()
    return (frame.index.to_numpy() + 0.5) * width, frame.to_numpy()


def first_peak(t, y, start):
    if not np.isfinite(start):
        return float("nan"), float("nan")
    centres, means = binned(t, y)
    inside = (centres >= start - PEAK_BIN) & (centres <= start + PEAK_SEARCH)
    if not inside.any():
        return float("nan"), float("nan")
    k = np.argmax(np.where(inside, means, -np.inf))
    return float(means[k]), float(centres[k])


def nmae(t_sim, y_sim, t_exp, y_exp, window=NMAE_WINDOW):
    """Over the window, cut at the end of the shorter series (no extrapolation)."""
    grid = np.arange(window[0], min(window[1], t_sim[-1], t_exp[-1]), PEAK_BIN)
    sim = np.interp(grid, t_sim, running_mean(t_sim, y_sim))
    exp = np.interp(grid, t_exp, running_mean(t_exp, y_exp))
    return float(np.mean(np.abs(sim - exp)) / np.mean(np.abs(exp)))


def compare(experiment, t_run, run, times):
    """The table of quantities: sensor, quantity, simulation, measurement, comparison."""
    rows = []
    t_exp = experiment.series["time"].to_numpy()
    for sensor in experiment.pressures + experiment.levels:
        if sensor not in run:
            continue
        y_sim, y_exp = run[sensor], experiment.series[sensor].to_numpy()
        level = sensor in experiment.levels
        unit = "m" if level else "Pa"
        threshold = LEVEL_THRESHOLD if level else PRESSURE_THRESHOLD
        a_sim, a_exp = arrival(t_run, y_sim, threshold), arrival(t_exp, y_exp, threshold)
        rows.append((sensor, "arrival", "s", a_sim, a_exp, a_sim - a_exp))
        for t in times:
            s, e = window_mean(t_run, y_sim, t), window_mean(t_exp, y_exp, t)
            rows.append((sensor, f"mean@{t:g}", unit, s, e, s / e if e != 0 else float("nan")))
        if level:
            value = nmae(t_run, y_sim, t_exp, y_exp, experiment.nmae_window)
            rows.append((sensor, "nmae", "-", value, 0.0, value))
            if sensor in experiment.scatter:
                rows.append((sensor, "scatter", "-", float("nan"), experiment.scatter[sensor],
                             experiment.scatter[sensor]))
        else:
            p_sim, _ = first_peak(t_run, y_sim, a_sim)
            p_exp, _ = first_peak(t_exp, y_exp, a_exp)
            rows.append((sensor, "peak", unit, p_sim, p_exp, p_sim / p_exp if p_exp else float("nan")))
    return pd.DataFrame(rows, columns=["sensor", "quantity", "unit", "simulation", "measurement", "comparison"])


def value(table, sensor, quantity, column="comparison"):
    row = table[(table.sensor == sensor) & (table.quantity == quantity)]
    return float(row[column].iloc[0]) if len(row) else float("nan")


def spheric_checks(table, t_run, run):
    checks = [("P1 arrival within 0.02 s", abs(value(table, "P1", "arrival")) <= 0.02,
               f"{value(table, 'P1', 'arrival', 'simulation'):.3f} s against {value(table, 'P1', 'arrival', 'measurement'):.3f} s")]
    for sensor in ("P1", "P2", "P3", "P4"):
        for t in (0.5, 0.6, 0.8, 1.0):
            ratio = value(table, sensor, f"mean@{t:g}")
            checks.append((f"{sensor} 10 ms mean at {t:g} s within 20 %", abs(ratio - 1) <= 0.2, f"ratio {ratio:.3f}"))
    checks += level_checks(table, ("H2", "H4"), "0-1.5 s")
    if "P7" in run:
        before = t_run < 1.0
        top = float(np.max(running_mean(t_run, run["P7"])[before])) if before.any() else float("nan")
        checks.append(("P7 below 200 Pa before 1.0 s (10 ms means)", top < 200.0, f"largest {top:.0f} Pa"))
    return checks


def lobovsky_checks(table, t_run, run):
    checks = []
    for sensor, tolerance in (("p1", 0.20), ("p2", 0.25), ("p3", 0.25)):
        for t in (0.475, 0.525, 0.575, 0.625, 0.675):
            ratio = value(table, sensor, f"mean@{t:g}")
            checks.append((f"{sensor} 10 ms mean at {t:g} s within {100 * tolerance:.0f} %",
                           abs(ratio - 1) <= tolerance, f"ratio {ratio:.3f}"))
    ratio = value(table, "p1", "peak")
    checks.append(("p1 first-impact peak within a factor 2", 0.5 <= ratio <= 2.0, f"ratio {ratio:.3f}"))
    return checks


def level_checks(table, sensors, window):
    """Each level's NMAE within 10 % (the bound of both experiments' levels)."""
    checks = []
    for sensor in sensors:
        error = value(table, sensor, "nmae")
        checks.append((f"{sensor} NMAE over {window} within 10 %", error <= 0.10, f"{100 * error:.1f} %"))
    return checks


def lobovsky_level_checks(table, t_run, run):
    return level_checks(table, ("H1", "H2", "H3", "H4"), "0-1.0 s")


def plot(experiment, t_run, run, path, label):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    sensors = [s for s in experiment.pressures + experiment.levels if s in run]
    columns = 2 if len(sensors) > 4 else 1
    rows = (len(sensors) + columns - 1) // columns
    figure, axes = plt.subplots(rows, columns, figsize=(7 * columns, 2.3 * rows), sharex=True, squeeze=False)
    t_exp = experiment.series["time"].to_numpy()
    end = min(t_run[-1], t_exp[-1])
    # from a little before the first measured arrival: the still water before it says nothing
    arrivals = [arrival(t_exp, experiment.series[s].to_numpy(), LEVEL_THRESHOLD if s in experiment.levels
                        else PRESSURE_THRESHOLD) for s in sensors]
    start = max(0.0, np.nanmin(arrivals) - 0.1) if np.isfinite(arrivals).any() else 0.0
    for k, sensor in enumerate(sensors):
        axis = axes[k % rows, k // rows]
        scale, unit = (1.0, "m") if sensor in experiment.levels else (1e-3, "kPa")
        y_exp = experiment.series[sensor].to_numpy()
        axis.plot(t_run, scale * run[sensor], color="tab:blue", alpha=0.25, lw=0.6)
        axis.plot(t_exp, scale * running_mean(t_exp, y_exp), color="black", lw=1.5, label="measured (10 ms mean)")
        axis.plot(t_run, scale * running_mean(t_run, run[sensor]), color="tab:blue", lw=1.2,
                  label=f"{label} (10 ms mean)")
        axis.set_ylabel(f"{sensor} [{unit}]")
        axis.set_xlim(start, end)
        axis.grid(alpha=0.3)
    axes[0, 0].legend(fontsize=8, loc="upper right")
    for axis in axes[-1, :]:
        axis.set_xlabel("t [s]")
    figure.suptitle(experiment.name, fontsize=10)
    figure.tight_layout()
    figure.savefig(path, dpi=110)
    plt.close(figure)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("output", help="the run's output folder (with gauges.csv)")
    parser.add_argument("data", help="a measured series: SPHERIC Test 2 or Lobovsky 2014 (H = 300 mm)")
    parser.add_argument("--plot", help="write the comparison figure (PNG) here")
    parser.add_argument("--csv", help="write the table of quantities here")
    parser.add_argument("--times", help="comma-separated times of the 10 ms means [s] (default: the data set's)")
    parser.add_argument("--label", default="Flotsam", help="legend label of the run")
    parser.add_argument("--check", action="store_true", help="apply the acceptance criteria; exit 1 on a failure")
    args = parser.parse_args(argv)
    try:
        experiment = read_experiment(args.data)
        t_run, run = read_run(args.output)
    except (OSError, ValueError, KeyError) as error:
        print(f"compare_experiment.py: error: {error}", file=sys.stderr)
        return 2
    times = experiment.times if not args.times else [float(t) for t in args.times.split(",")]
    table = compare(experiment, t_run, run, times)
    if table.empty:
        print(f"compare_experiment.py: error: {args.output}/gauges.csv has none of the sensors "
              f"{', '.join(experiment.pressures + experiment.levels)}", file=sys.stderr)
        return 2
    print(f"{experiment.name}: {args.output}")
    with pd.option_context("display.width", 140, "display.max_rows", 500):
        print(table.to_string(index=False, float_format=lambda x: f"{x:.4g}"))
    if args.csv:
        # the header row first, then '#' lines (as Flotsam's own CSVs): pandas.read_csv(path, comment='#')
        lines = table.to_csv(index=False).splitlines()
        with open(args.csv, "w", encoding="utf-8") as file:
            file.write(lines[0] + "\n")
            file.write(f"# compare_experiment.py: {args.output} against {os.path.basename(args.data)} "
                       f"({experiment.name})\n# comparison = simulation / measurement; for arrival simulation - "
                       "measurement [s]; for nmae the NMAE itself\n")
            file.write("\n".join(lines[1:]) + "\n")
        print(f"wrote {args.csv}")
    if args.plot:
        plot(experiment, t_run, run, args.plot, args.label)
        print(f"wrote {args.plot}")
    if not args.check:
        return 0
    failed = 0
    for name, passed, detail in experiment.checks(table, t_run, run):
        print(f"{'PASS' if passed else 'FAIL'}: {name}: {detail}")
        failed += not passed
    print(f"{failed} of the checks failed" if failed else "all checks passed")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
