#!/usr/bin/python3
"""The showcase inputs/debris_impact_3d.nml: the column's load, the container's motion and the water
levels and pressures of one run, in one figure, and the numbers of docs/showcase.md.

    scripts/debris_impact.py <run folder> [--png FILE]

Reads loads.csv ('column_f*', 'column_m*'), bodies.csv ('container_*'), gauges.csv (level and pressure
gauges) and run_summary.csv of the run, and prints the column's peak horizontal force and its time, the
container's impact (the row of bodies.csv where its x velocity drops most from one row to the next: the
column stops it), the water's force on the column just before, and the run's cost; draws the figure
(default <run>/debris_impact.png)."""

import argparse
import os

import matplotlib
import numpy as np
import pandas

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("run", help="output folder of a run of inputs/debris_impact_3d.nml")
    parser.add_argument("--png", help="picture to write (default: <run>/debris_impact.png)")
    arguments = parser.parse_args()
    run = arguments.run
    loads = pandas.read_csv(os.path.join(run, "loads.csv"), comment="#")
    bodies = pandas.read_csv(os.path.join(run, "bodies.csv"), comment="#")
    gauges = pandas.read_csv(os.path.join(run, "gauges.csv"), comment="#")

    t = loads["time"].to_numpy()
    force = np.hypot(loads["column_fx"], loads["column_fy"]).to_numpy()
    peak = int(np.argmax(force))
    row = float(np.median(np.diff(t)))
    # the impulse of the impact: a row is the mean force over its interval, so the peak of a contact
    # of a few steps depends on load_interval, the impulse does not
    near = np.abs(t - t[peak]) <= 0.01 + 1e-9
    impulse = (loads["column_fx"].to_numpy() * np.diff(np.concatenate([[0.0], t])))[near].sum()
    moment = np.hypot(loads["column_mx"], loads["column_my"]).to_numpy()
    tb = bodies["time"].to_numpy()
    vx = bodies["container_vx"].to_numpy()
    # impact: the container's largest loss of x velocity within one row (the column stops it)
    hit = int(np.argmin(np.diff(vx))) + 1
    print(f"{run}: column peak horizontal force {force[peak]:.1f} N (fx {loads['column_fx'][peak]:.1f} N) "
          f"at t = {t[peak]:.4f} s (rows of {row * 1000:.3g} ms); impulse within 10 ms of it {impulse:.2f} N s; "
          f"peak moment about its foot {moment.max():.1f} N m at t = {t[int(np.argmax(moment))]:.4f} s")
    print(f"  container: largest drop of v_x {vx[hit - 1]:+.3f} -> {vx[hit]:+.3f} m/s at t = {tb[hit]:.4f} s "
          f"(x = {bodies['container_x'][hit]:.3f} m); peak v_x {vx.max():.3f} m/s at t = {tb[int(np.argmax(vx))]:.3f} s")
    before = force[(t > tb[hit] - 0.1) & (t < tb[hit] - 0.01)]
    if before.size:
        print(f"  water alone on the column just before: {before.mean():.1f} N (mean over "
              f"{tb[hit] - 0.1:.3f} .. {tb[hit] - 0.01:.3f} s)")
    summary = os.path.join(run, "run_summary.csv")
    if os.path.exists(summary):
        cost = pandas.read_csv(summary, comment="#").iloc[0]
        print(f"  run: {int(cost['steps'])} steps, {cost['wall_seconds']:.0f} s wall time on {int(cost['ranks'])} ranks, "
              f"{cost['particle_steps_per_second_per_core']:.3g} particle-steps/s per core, "
              f"peak memory {cost['peak_memory_bytes_total'] / 2 ** 20:.0f} MiB (all ranks)")

    fig, axes = plt.subplots(5, 1, figsize=(7.5, 10.5), sharex=True,
                             gridspec_kw={"height_ratios": [2, 1, 1, 1, 1]})
    ax = axes[0]
    ax.plot(t, loads["column_fx"], lw=0.8, label="$F_x$ (along the flume)")
    ax.plot(t, loads["column_fy"], lw=0.8, label="$F_y$ (across)")
    ax.axvline(tb[hit], color="0.5", ls=":", lw=0.8)
    ax.set_ylabel("force on the column [N]")
    ax.legend(fontsize=8, loc="upper left")
    ax.set_title(f"debris_impact_3d: peak {force[peak]:.0f} N at t = {t[peak]:.3f} s "
                 f"(loads.csv rows of {row * 1000:.3g} ms)", fontsize=10)
    ax = axes[1]
    ax.plot(tb, vx, lw=0.8, label="$v_x$")
    ax.plot(tb, bodies["container_vz"], lw=0.8, label="$v_z$")
    ax.axvline(tb[hit], color="0.5", ls=":", lw=0.8)
    ax.set_ylabel("container\nvelocity [m/s]")
    ax.legend(fontsize=8, loc="upper left")
    ax = axes[2]
    ax.plot(tb, bodies["container_x"], lw=0.8, color="C2", label="x")
    ax.set_ylabel("container\ncentroid x [m]")
    right = ax.twinx()
    right.plot(tb, bodies["container_z"], lw=0.8, color="C3", label="z")
    right.set_ylabel("z [m]", color="C3")
    ax.axvline(tb[hit], color="0.5", ls=":", lw=0.8)
    ax = axes[3]
    for name in [c[:-len("_level")] for c in gauges.columns if c.endswith("_level")]:
        wet = gauges[f"{name}_samples"] > 0
        ax.plot(gauges["time"], np.where(wet, gauges[f"{name}_level"], 0.0), lw=0.8, label=name)
    ax.axvline(tb[hit], color="0.5", ls=":", lw=0.8)
    ax.set_ylabel("water level [m]")
    ax.legend(fontsize=8, loc="upper left")
    ax = axes[4]
    for name in [c[:-len("_pressure")] for c in gauges.columns if c.endswith("_pressure")]:
        wet = gauges[f"{name}_samples"] > 0
        ax.plot(gauges["time"], np.where(wet, gauges[f"{name}_pressure"], 0.0) / 1000, lw=0.8, label=name)
    ax.axvline(tb[hit], color="0.5", ls=":", lw=0.8)
    ax.set_ylabel("pressure [kPa]")
    ax.set_xlabel("time [s]")
    ax.legend(fontsize=8, loc="upper left")
    fig.tight_layout()
    png = arguments.png or os.path.join(run, "debris_impact.png")
    fig.savefig(png, dpi=110)
    print(f"  wrote {png}")


if __name__ == "__main__":
    main()
