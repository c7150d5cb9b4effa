#!/usr/bin/python3
"""scripts/compare_experiment.py against runs whose answer is known (no flotsam run; a few seconds):
gauges.csv files made from the measurements themselves, exact, scaled, delayed, plus one of an unknown
layout. What must come out:

1. the measurement itself: every 10 ms mean ratio 1, every arrival difference 0, every NMAE 0, and
   --check passes (Lobovsky pressures and levels, SPHERIC Test 2);
2. the Lobovsky pressures times 1.3: every ratio 1.3, and --check fails (sensor 1 within 20 %) with exit 1;
3. the Lobovsky pressures 20 ms late: sensor 1's arrival 0.020 s late (to the 1 ms resolution of the
   arrival) and the peak ratio 1 (the same event, later);
4. the Lobovsky levels times 1.05: NMAE 5 %; the scatter row of H2 equals the NMAE of its two measured
   series computed here directly;
5. a data file of unknown layout: exit 2 and a message naming the file.

usage: check_compare_experiment.py <repository root>"""

import os
import subprocess
import sys
import tempfile

import numpy as np
import pandas as pd

from flotsam_run import Checks

GRAVITY, RHO, DEPTH = 9.81, 1000.0, 0.3
DATA = {
    "pressure": "tests/data/experiments/lobovsky2014_h300_pressure.csv",
    "levels": "tests/data/experiments/lobovsky2014_h300_levels.csv",
    "spheric": "tests/data/experiments/spheric_test2_kleefsman2005.csv",
}


def lobovsky_series(root, kind):
    """The measured Lobovsky series as a run's gauges would hold them: time [s], p1.. [Pa] or H1.. [m]."""
    table = pd.read_csv(os.path.join(root, DATA[kind]), comment="#")
    time = table["t_star"].to_numpy() * np.sqrt(DEPTH / GRAVITY)
    columns = {}
    if kind == "pressure":
        for sensor in ("p1", "p2", "p3", "p4"):
            columns[f"{sensor}_pressure"] = table[f"{sensor}_star"].to_numpy() * RHO * GRAVITY * DEPTH
    else:
        for gauge in ("H1", "H2", "H3", "H4"):
            series = [table[c].to_numpy() for c in table.columns if c.startswith(f"{gauge}_")]
            columns[f"{gauge}_level"] = np.mean(series, axis=0) * DEPTH
    return time, columns


def write_run(folder, time, columns):
    os.makedirs(folder, exist_ok=True)
    pd.DataFrame({"time": time, **columns}).to_csv(os.path.join(folder, "gauges.csv"), index=False)
    return folder


def compare(root, folder, kind, *options):
    command = [sys.executable, os.path.join(root, "scripts", "compare_experiment.py"), folder,
               os.path.join(root, DATA.get(kind, kind))] + list(options)
    return subprocess.run(command, capture_output=True, text=True)


def table_of(root, folder, kind, scratch):
    path = os.path.join(scratch, "table.csv")
    result = compare(root, folder, kind, "--csv", path)
    return result, (pd.read_csv(path, comment="#") if result.returncode == 0 else None)


def rows(table, quantity_prefix):
    return table[table.quantity.str.startswith(quantity_prefix)]


def main():
    root = os.path.abspath(sys.argv[1])
    checks = Checks()
    with tempfile.TemporaryDirectory() as scratch:
        # 1. the measurement itself
        for kind in ("pressure", "levels"):
            time, columns = lobovsky_series(root, kind)
            folder = write_run(os.path.join(scratch, f"exact_{kind}"), time, columns)
            result, table = table_of(root, folder, kind, scratch)
            if not checks.check(table is not None, f"{kind}: the exact run is compared", result.stderr[-1000:]):
                continue
            means = rows(table, "mean@")["comparison"].to_numpy()
            checks.check(np.allclose(means[np.isfinite(means)], 1.0, atol=1e-9) and np.isfinite(means).sum() > 10,
                         f"{kind}: every 10 ms mean ratio of the measurement against itself is 1 ({len(means)} of them)")
            checks.check(np.allclose(rows(table, "arrival")["comparison"], 0.0, atol=1e-12),
                         f"{kind}: every arrival difference is 0")
            if kind == "levels":
                checks.check(np.allclose(table[table.quantity == "nmae"]["comparison"], 0.0, atol=1e-12),
                             "levels: every NMAE is 0")
            verdict = compare(root, folder, kind, "--check")
            checks.check(verdict.returncode == 0, f"{kind}: --check passes on the measurement itself",
                         verdict.stdout[-1500:])
        spheric = pd.read_csv(os.path.join(root, DATA["spheric"]), comment="#")
        columns = {f"{c}_{'level' if c.startswith('H') else 'pressure'}": spheric[c].to_numpy()
                   for c in spheric.columns if c != "time"}
        folder = write_run(os.path.join(scratch, "exact_spheric"), spheric["time"].to_numpy(), columns)
        verdict = compare(root, folder, "spheric", "--check")
        checks.check(verdict.returncode == 0, "spheric: --check passes on the measurement itself", verdict.stdout[-1500:])

        # 2. scaled pressures
        time, columns = lobovsky_series(root, "pressure")
        folder = write_run(os.path.join(scratch, "scaled"), time, {k: 1.3 * v for k, v in columns.items()})
        result, table = table_of(root, folder, "pressure", scratch)
        if checks.check(table is not None, "pressure x 1.3: compared", result.stderr[-1000:]):
            means = rows(table, "mean@")["comparison"].to_numpy()
            checks.check(np.allclose(means, 1.3, rtol=1e-9), "pressure x 1.3: every 10 ms mean ratio is 1.3")
        verdict = compare(root, folder, "pressure", "--check")
        checks.check(verdict.returncode == 1 and "FAIL: p1 10 ms mean at 0.475 s within 20 %" in verdict.stdout,
                     "pressure x 1.3: --check fails sensor 1 and exits 1", f"exit {verdict.returncode}")

        # 3. delayed pressures
        folder = write_run(os.path.join(scratch, "delayed"), time + 0.020, columns)
        result, table = table_of(root, folder, "pressure", scratch)
        if checks.check(table is not None, "pressure 20 ms late: compared", result.stderr[-1000:]):
            delay = float(table[(table.sensor == "p1") & (table.quantity == "arrival")]["comparison"].iloc[0])
            peak = float(table[(table.sensor == "p1") & (table.quantity == "peak")]["comparison"].iloc[0])
            checks.check(abs(delay - 0.020) <= 0.001, f"pressure 20 ms late: sensor 1 arrives {delay:.4f} s late")
            checks.check(abs(peak - 1.0) <= 0.02, f"pressure 20 ms late: first-peak ratio {peak:.3f} (the same event)")

        # 4. scaled levels; the scatter of H2
        time, columns = lobovsky_series(root, "levels")
        folder = write_run(os.path.join(scratch, "levels_scaled"), time, {k: 1.05 * v for k, v in columns.items()})
        result, table = table_of(root, folder, "levels", scratch)
        if checks.check(table is not None, "levels x 1.05: compared", result.stderr[-1000:]):
            errors = table[table.quantity == "nmae"]["comparison"].to_numpy()
            checks.check(np.allclose(errors, 0.05, atol=2e-3), f"levels x 1.05: NMAE {', '.join(f'{e:.4f}' for e in errors)}")
            measured = pd.read_csv(os.path.join(root, DATA["levels"]), comment="#")
            t = measured["t_star"].to_numpy() * np.sqrt(DEPTH / GRAVITY)
            grid = np.arange(0.0, 1.0, 0.001)
            a, b = (np.interp(grid, t, measured[c].to_numpy()) for c in ("H2_etsin01_star", "H2_etsin02_star"))
            direct = np.mean(np.abs(a - b)) / np.mean(np.abs(b))   # without the 10 ms means: close, not equal
            scatter = float(table[(table.sensor == "H2") & (table.quantity == "scatter")]["comparison"].iloc[0])
            checks.check(abs(scatter - direct) <= 0.1 * direct,
                         f"levels: H2's scatter {scatter:.4f} against {direct:.4f} computed directly")

        # 5. unknown layout
        odd = os.path.join(scratch, "odd.csv")
        pd.DataFrame({"t": [0.0, 1.0], "x": [0.0, 1.0]}).to_csv(odd, index=False)
        verdict = compare(root, os.path.join(scratch, "exact_pressure"), odd)
        checks.check(verdict.returncode == 2 and "odd.csv" in verdict.stderr,
                     "a data file of unknown layout: exit 2, the file named", verdict.stderr[-500:])
    return checks.summary()


if __name__ == "__main__":
    raise SystemExit(main())
