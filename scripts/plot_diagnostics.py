#!/usr/bin/python3
"""Plot the diagnostics of a Flotsam run (diagnostics.csv) against time: kinetic energy, equivalent
water height h_eq, maximum particle speed and time step, in one PNG (docs/output.md).

usage: scripts/plot_diagnostics.py <output folder or diagnostics.csv> [-o picture.png] [--show]

Needs Debian's python3-matplotlib and python3-numpy (run with /usr/bin/python3 if another python comes
first on PATH)."""

import argparse
import os
import sys

import matplotlib

PANELS = [  # column, label
    ("kinetic_energy", "kinetic energy [J]"),
    ("h_eq", "equivalent height h_eq [m]"),
    ("max_speed", "max particle speed [m/s]"),
    ("dt", "time step [s]"),
]


def read_columns(path):
    import numpy as np
    data = np.genfromtxt(path, delimiter=",", names=True)
    return np.atleast_1d(data)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("run", help="output folder of a run, or its diagnostics.csv")
    parser.add_argument("-o", "--output", help="PNG to write (default: <output folder>/diagnostics.png)")
    parser.add_argument("--show", action="store_true", help="open a window instead of writing a file")
    arguments = parser.parse_args()

    path = arguments.run
    if os.path.isdir(path):
        path = os.path.join(path, "diagnostics.csv")
    if not os.path.exists(path):
        sys.exit(f"plot_diagnostics: no {path}")
    if not arguments.show:
        matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    data = read_columns(path)
    figure, axes = plt.subplots(len(PANELS), 1, sharex=True, figsize=(7, 2.2 * len(PANELS)))
    for axis, (column, label) in zip(axes, PANELS):
        axis.plot(data["time"], data[column], marker=".", markersize=3, linewidth=1)
        axis.set_ylabel(label)
        axis.grid(True, alpha=0.3)
    axes[-1].set_xlabel("time [s]")
    figure.suptitle(f"{os.path.abspath(path)}\n{int(data['particles'][-1])} particles at step "
                    f"{int(data['step'][-1])}", fontsize=9)
    figure.tight_layout()
    if arguments.show:
        plt.show()
    else:
        output = arguments.output or os.path.join(os.path.dirname(path), "diagnostics.png")
        figure.savefig(output, dpi=120)
        print(output)


if __name__ == "__main__":
    main()
