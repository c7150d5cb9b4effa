#!/usr/bin/python3
"""The accuracy-per-cost summary of issue 16 (docs/speed-accuracy.md) from the studies' results.csv files:

    scripts/study inputs/studies/transfer_shape_tank.study --jobs 2
    scripts/study inputs/studies/transfer_shape_dam_break.study --jobs 2
    scripts/study inputs/studies/transfer_shape_floating_block.study --jobs 2
    scripts/study inputs/studies/transfer_shape_wall_peak.study --jobs 2
    scripts/speed_accuracy.py [--studies output/studies] [--figure docs/figures/speed_accuracy_pareto.png]

Prints one Markdown table, a row per velocity transfer x shape function x scheme (2 particles per cell
and direction, the cheaper of the two densities the studies run; 3 x 3 is in the studies' results.csv),
with the cost (particle-steps per second per core on the dam break, and the wall time of the 45-degree
tank) and the accuracy of each scene; a case that blew up reads 'blew up'. Then the far wall's peak
force against cell size (FOAL1). Draws one figure: accuracy against wall time for each scene, the
Pareto-optimal cases joined. A missing study is skipped (its columns read '-')."""

import argparse
import os

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402

TRANSFERS = [("flip_pic", "FLIP/PIC"), ("apic", "APIC")]
SHAPES = ["linear", "bspline2"]
SCHEMES = ["none", "C0", "FOAL1", "NB"]


def read(studies, name):
    path = os.path.join(studies, name, "results.csv")
    return pd.read_csv(path) if os.path.exists(path) else None


def pick(frame, **where):
    """The rows of `frame` whose columns equal the given values (column names with spaces as '__')."""
    if frame is None:
        return None
    rows = frame
    for key, value in where.items():
        column = key.replace("__", " ").replace("_COLON_", ":")
        rows = rows[rows[column] == value]
    return rows


def value(rows, column, digits, percent=False):
    """One cell: the value of the single row, 'blew up' if that run blew up, '-' if there is none."""
    if rows is None or len(rows) != 1:
        return "-"
    row = rows.iloc[0]
    if row["outcome"] not in ("finished", "max_steps"):
        return "blew up"
    number = row.get(column, np.nan)
    if pd.isna(number):
        return "-"
    return f"{number:+.{digits}f} %" if percent else f"{number:.{digits}f}"


def table(studies):
    tank = read(studies, "transfer_shape_tank")
    dam = read(studies, "transfer_shape_dam_break")
    block = read(studies, "transfer_shape_floating_block")
    print("| transfer | shape function | scheme | M particle-steps/s (dam break) | tank 45°: wall s | tank 0°: pressure error | "
          "tank 45°: h_cm drift | tank 45°: pressure error | tank 45°: wall force error | dam break front, slip: "
          "mean / early error | dam break front, no-slip: mean / early error | floating block 10 s: surface [m] | "
          "floating block: pressure noise |")
    print("|" + "---|" * 13)
    for transfer, label in TRANSFERS:
        for shape in SHAPES:
            for scheme in SCHEMES:
                common = {"run__transfer": transfer, "grid__shape_function": shape}
                t0 = pick(tank, **common, material__stabilization=scheme, body__particles_per_cell=2,
                          grid__rotation=0.0)
                t45 = pick(tank, **common, material__stabilization=scheme, body__particles_per_cell=2,
                           grid__rotation=45.0)
                slip = pick(dam, **common, material__stabilization=scheme, box_walls__y_min="slip",
                            body__particles_per_cell=2)
                noslip = pick(dam, **common, material__stabilization=scheme, box_walls__y_min="no_slip",
                              body__particles_per_cell=2)
                fb = pick(block, **common, material_COLON_water__stabilization=scheme) if scheme != "none" else None
                rate = "-"
                if slip is not None and len(slip) == 1 and slip.iloc[0]["outcome"] == "finished":
                    rate = f"{slip.iloc[0]['particle_steps_per_second_per_core'] / 1e6:.2f}"
                front = [value(r, "surge_front_error_percent", 1) + " / " + value(r, "surge_front_early_error_percent", 1)
                         if value(r, "surge_front_error_percent", 1) not in ("blew up", "-") else
                         value(r, "surge_front_error_percent", 1) for r in (slip, noslip)]
                print(f"| {label} | {shape} | {scheme} | {rate} | {value(t45, 'wall_seconds', 1)} | "
                      f"{value(t0, 'pressure_rms_error_relative', 3)} | {value(t45, 'h_cm_drift_percent', 2, True)} | "
                      f"{value(t45, 'pressure_rms_error_relative', 3)} | {value(t45, 'load_error_percent', 2, True)} | "
                      f"{front[0]} | {front[1]} | {value(fb, 'surface_level', 3)} | "
                      f"{value(fb, 'pressure_rms_error_relative', 3)} |")


def wall_peak(studies):
    peak = read(studies, "transfer_shape_wall_peak")
    if peak is None:
        return
    print()
    print("| transfer | shape function | cells per L | peak far-wall force [N/m] | wall s |")
    print("|---|---|---|---|---|")
    for transfer, label in TRANSFERS:
        for shape in SHAPES:
            for h in sorted(peak["grid cell_size"].unique(), reverse=True):
                rows = pick(peak, run__transfer=transfer, grid__shape_function=shape, grid__cell_size=h)
                print(f"| {label} | {shape} | {0.146 / h:.0f} | {value(rows, 'load_peak', 0)} | "
                      f"{value(rows, 'wall_seconds', 1)} |")


def pareto_front(cost, error):
    order = np.argsort(cost)
    front, best = [], np.inf
    for i in order:
        if error[i] < best:
            front.append(i)
            best = error[i]
    return front


def figure(studies, path):
    panels = [("transfer_shape_tank", "h_cm_drift_percent", "tank 45°: |h_cm drift| [%]", {"grid rotation": 45.0}),
              ("transfer_shape_tank", "pressure_rms_error_relative", "tank 45°: pressure error [ρgH]",
               {"grid rotation": 45.0}),
              ("transfer_shape_dam_break", "surge_front_error_percent", "dam break: front error [%]", {}),
              ("transfer_shape_floating_block", "pressure_rms_error_relative", "floating block: pressure noise", {})]
    fig, axes = plt.subplots(2, 2, figsize=(11, 8.5))
    colours = {("flip_pic", "linear"): "C0", ("flip_pic", "bspline2"): "C1", ("apic", "linear"): "C2",
               ("apic", "bspline2"): "C3"}
    for ax, (name, column, title, where) in zip(axes.flat, panels):
        frame = read(studies, name)
        ax.set_title(title, fontsize=10)
        if frame is None:
            continue
        for key, v in where.items():
            frame = frame[frame[key] == v]
        frame = frame[frame["outcome"].isin(["finished", "max_steps"])]
        cost = frame["wall_seconds"].to_numpy()
        error = np.maximum(np.abs(frame[column].to_numpy()), 1e-6)
        for (transfer, shape), colour in colours.items():
            mine = ((frame["run transfer"] == transfer) & (frame["grid shape_function"] == shape)).to_numpy()
            label = f"{dict(TRANSFERS)[transfer]} {shape}"
            ax.scatter(cost[mine], error[mine], s=18, color=colour, label=label)
        front = pareto_front(cost, error)
        ax.plot(cost[front], error[front], "k-", lw=0.8, label="Pareto front")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("wall time [s] (1 rank)")
    axes.flat[0].legend(fontsize=8)
    fig.suptitle("Accuracy against cost: velocity transfer x shape function (points: schemes, particles per cell, "
                 "floors)", fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    print(f"\nwrote {path}")


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--studies", default=os.path.join("output", "studies"))
    parser.add_argument("--figure", default=os.path.join("docs", "figures", "speed_accuracy_pareto.png"))
    args = parser.parse_args()
    table(args.studies)
    wall_peak(args.studies)
    figure(args.studies, args.figure)


if __name__ == "__main__":
    main()
