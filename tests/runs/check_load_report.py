#!/usr/bin/env python3
"""scripts/load_report.py on series whose answers are known (issue 52; no flotsam run):

  1. A half-sine pulse (duration T = 40 ms, peak 1000 N/m) on white noise of 2 % of its peak, written as
     loads.csv rows every 0.1 ms that are interval means (as flotsam writes them): with the default cutoff
     (200 Hz) the filtered peak, the impulse of the event, its rise and its decay (where the filtered
     signal crosses 0.1 of the peak) are within 2 % of the half-sine's own: peak P, impulse
     (2 P T / pi) cos(pi t_s / T), rise = decay = T / 2 - t_s with t_s = T asin(0.1) / pi; the raw peak is
     higher (the noise on top).
  2. The same pulse in panels.csv (a pressure and a force column) and as a wall_pressure gauge in
     gauges.csv (no _samples column: an interval mean) gives the same values; a fluid pressure gauge (a
     sample, with _samples) is read as samples.
  3. A cutoff above what the rows carry is lowered and the report says so; the CSV reads with one pandas
     call, names its units, and a second run says it replaced the first report; --cutoff 0 and a folder
     without load files fail with exit status 2.
"""
import math
import os
import subprocess
import sys

import numpy as np
import pandas as pd

from flotsam_run import Checks

T, P, DT = 0.040, 1000.0, 1.0e-4
ONSET = 0.1                    # the pulse starts here [s]
RUN = 0.3                      # rows up to here [s]


def pulse_means(ends, start=0.0):
    """Interval means of P sin(pi (t - ONSET) / T) on ONSET .. ONSET + T (0 elsewhere), intervals ending at `ends`."""
    previous = np.concatenate([[start], ends[:-1]])

    def primitive(t):
        u = np.clip(t - ONSET, 0.0, T)
        return -P * T / math.pi * np.cos(math.pi * u / T)
    return (primitive(ends) - primitive(previous)) / (ends - previous)


def write_csv(path, header, comments, columns):
    with open(path, "w") as f:
        f.write(",".join(header) + "\n")
        for line in comments:
            f.write(f"# {line}\n")
        for row in zip(*columns):
            f.write(",".join(repr(float(v)) for v in row) + "\n")


def make_run(folder, noise):
    os.makedirs(folder, exist_ok=True)
    times = DT * np.arange(1, int(round(RUN / DT)) + 1)
    signal = pulse_means(times) + noise
    comments = ["written by a test from scene synthetic.nml", "units: time s; _fx _fy N/m (2-D plane strain: per metre of depth)"]
    write_csv(os.path.join(folder, "loads.csv"), ["time", "wall_fx", "wall_fy"], comments,
              [times, signal, np.zeros_like(times)])
    write_csv(os.path.join(folder, "panels.csv"), ["time", "band_pressure", "band_fx", "band_fy"],
              ["written by a test from scene synthetic.nml", "units: time s; _pressure Pa; _fx _fy _fz N/m"],
              [times, signal, -signal, np.zeros_like(times)])
    # a fluid gauge samples the pulse at the row times (not interval means)
    u = np.clip(times - ONSET, 0.0, T)
    sampled = P * np.sin(math.pi * u / T) + noise
    write_csv(os.path.join(folder, "gauges.csv"), ["time", "wp_pressure", "fluid_pressure", "fluid_samples"],
              ["written by a test from scene synthetic.nml", "units: time s; _pressure Pa; _samples count"],
              [times, signal, sampled, np.full_like(times, 12.0)])
    return times


def report(scripts, folder, *arguments):
    return subprocess.run([sys.executable, os.path.join(scripts, "load_report.py"), folder, *arguments],
                          capture_output=True, text=True, timeout=300)


def main():
    root = sys.argv[1]
    scripts = os.path.join(root, "scripts")
    checks = Checks()
    rng = np.random.default_rng(52)
    folder = os.path.abspath("synthetic")
    times = make_run(folder, rng.normal(0.0, 0.02 * P, int(round(RUN / DT))))
    result = report(scripts, folder)
    if not checks.check(result.returncode == 0, "load_report.py runs on the synthetic run", result.stderr[-2000:]):
        return checks.summary()
    table = pd.read_csv(os.path.join(folder, "load_report.csv"), comment="#")
    t_s = T * math.asin(0.1) / math.pi
    exact = {"peak_filtered": P, "impulse": 2 * P * T / math.pi * math.cos(math.pi * t_s / T),
             "rise_time": T / 2 - t_s, "decay_time": T / 2 - t_s, "peak_filtered_time": ONSET + T / 2}
    for series, sign in (("wall_fx", 1.0), ("band_pressure", 1.0), ("band_fx", -1.0), ("wp_pressure", 1.0)):
        row = table[table["series"] == series].iloc[0]
        for key, value in exact.items():
            expected = sign * value if key in ("peak_filtered", "impulse") else value
            # the peak's time against the pulse's duration, the rest relative to themselves
            scale = T if key == "peak_filtered_time" else abs(expected)
            error = abs(row[key] - expected) / scale
            checks.check(error <= 0.02, f"{series}: {key} {row[key]:.6g} against {expected:.6g} "
                         f"(error {error:.2%} of {'T' if key == 'peak_filtered_time' else 'itself'}, tolerance 2 %)")
        checks.check(abs(row["peak_raw"]) > abs(row["peak_filtered"]) * 1.02,
                     f"{series}: the raw peak {row['peak_raw']:.5g} carries the noise (above the filtered one)")
    fluid = table[table["series"] == "fluid_pressure"].iloc[0]
    checks.check(abs(fluid["peak_filtered_time"] - (ONSET + T / 2)) <= 0.02 * T,
                 f"fluid_pressure (samples at row times): filtered peak at {fluid['peak_filtered_time']:.5g} s, "
                 f"the pulse's top at {ONSET + T / 2:.5g} s")
    checks.check(abs(fluid["impulse"] / exact["impulse"] - 1) <= 0.02,
                 f"fluid_pressure: impulse {fluid['impulse']:.5g} against {exact['impulse']:.5g} (trapezoids)")
    checks.check(set(table["unit"]) >= {"N/m", "Pa"} and "N/m s" in set(table["impulse_unit"]),
                 "load_report.csv: units of the series and of the impulse")
    checks.check(os.path.getsize(os.path.join(folder, "load_report.png")) > 10000, "load_report.png written")
    checks.check("lowered" not in result.stdout, "200 Hz is within what rows every 0.1 ms carry")

    again = report(scripts, folder, "--cutoff", "20000", "--no-plot")
    checks.check(again.returncode == 0 and "replaced the previous report" in again.stdout and
                 "lowered to 4000 Hz" in again.stdout,
                 "a second report says it replaced the first; a cutoff above the rows' reach is lowered, said",
                 again.stdout + again.stderr)
    bad = report(scripts, folder, "--cutoff", "0")
    checks.check(bad.returncode == 2 and "--cutoff must be > 0" in bad.stderr, "--cutoff 0: exit 2 with a message",
                 bad.stderr)
    os.makedirs("empty", exist_ok=True)
    empty = report(scripts, os.path.abspath("empty"))
    checks.check(empty.returncode == 2 and "holds none of" in empty.stderr, "a folder without load files: exit 2",
                 empty.stderr)
    return checks.summary()


if __name__ == "__main__":
    raise SystemExit(main())
