#!/usr/bin/env python3
"""Plot the load series of a Flotsam run: wall loads, gauge readings and solid-body motion.

usage: scripts/plot_loads.py <output folder> [--out DIR] [--show-walls name,...] [--cutoff HZ]

Reads whichever of loads.csv, gauges.csv and bodies.csv the run wrote (a file exists only if the scene
has walls, gauges or solid bodies; docs/output.md) and writes, into the output folder or DIR:

  loads.png   per wall the force components against time, and the moments in a second panel. Walls
              whose force and moment stay exactly zero throughout (an unused side of the box) are left
              out and named in the figure and on stdout; so are components that stay exactly zero.
  gauges.png  one panel per kind of gauge: pressure, water level, velocity.
  bodies.png  per solid body: trajectory of the centroid, its velocity, rotation and the resultant
              force on it.

--show-walls name,...  draw only these walls (drawn even if their load is zero throughout).
--cutoff HZ            the forces and pressures are drawn as the rows (thin) and low-passed as a sensor
                       of that bandwidth sees them (bold; zero-phase, default 200 Hz: docs/loads.md,
                       scripts/load_report.py); 0: the rows only.

The units in the axis labels are those of the files' '# units:' comment line (2-D runs: per metre of
depth, N/m; 3-D: N). Prints the paths of the pictures written, and the peak values. Exit status 2 if
the folder holds none of the three files (or a wall of --show-walls does not exist).

Needs matplotlib and numpy (Debian: python3-matplotlib), and scipy for the filtered series (python3-scipy;
without it the rows alone are drawn, and said). If the python3 first on PATH lacks them (a
pyenv or venv one), the script runs itself again with Debian's /usr/bin/python3. The files are plain CSV with '#' comment lines after the header row, so
pandas.read_csv(path, comment='#') reads them as well.
"""

import argparse
import functools
import os
import re
import sys

FILES = ("loads", "gauges", "bodies")
#: the low-pass of the bold series (set from --cutoff in main; 0: none)
CUTOFF_HZ = [0.0]
# Line styles tell the components of one wall / body apart; colours tell the walls apart.
COMPONENT_STYLES = {"x": "-", "y": "--", "z": "-."}


class Series:
    """One of the CSV files: column names, the '#' comment lines and the rows as columns of floats."""

    def __init__(self, path):
        import numpy as np
        self.path = path
        self.comments = []
        rows = []
        with open(path, encoding="utf-8") as file:
            header = file.readline().strip()
            for line in file:
                line = line.strip()
                if not line:
                    continue
                if line.startswith("#"):
                    self.comments.append(line.lstrip("#").strip())
                else:
                    rows.append([float(value) for value in line.split(",")])
        self.names = header.split(",")
        if not self.names or self.names[0] != "time":
            raise ValueError(f"{path}: the first column is not 'time' (header: {header[:80]!r})")
        for number, row in enumerate(rows):
            if len(row) != len(self.names):
                raise ValueError(f"{path}: row {number + 1} has {len(row)} values for {len(self.names)} columns")
        data = np.array(rows, dtype=float).reshape(len(rows), len(self.names))
        self.columns = {name: data[:, k] for k, name in enumerate(self.names)}
        self.units = signals_module(filtering=False).parse_units(self.comments)
        self.per_depth = any("per metre of depth" in comment for comment in self.comments)

    def __len__(self):
        return len(self.columns["time"])

    def __contains__(self, name):
        return name in self.columns

    def __getitem__(self, name):
        return self.columns[name]

    def unit(self, suffix, fallback=""):
        return self.units.get(suffix, fallback)

    def scene(self):
        for comment in self.comments:
            match = re.search(r"from scene (.+)$", comment)
            if match:
                return match.group(1).strip()
        return ""


def prefixed(values, unit):
    """Values and unit scaled to kilo/mega for readable ticks (N/m -> kN/m, Pa -> kPa)."""
    import numpy as np
    largest = float(np.nanmax(np.abs(values))) if np.size(values) else 0.0
    if not unit or not re.match(r"^(N|Pa)\b", unit) or largest < 1.0e4:
        return 1.0, unit
    if largest >= 1.0e7:
        return 1.0e-6, "M" + unit
    return 1.0e-3, "k" + unit


def label(text, unit):
    return f"{text} [{unit}]" if unit else text


def names_with(series, suffix):
    """Names (in column order) of the entities with a column <name><suffix>."""
    return [column[: -len(suffix)] for column in series.names[1:] if column.endswith(suffix)]


def all_zero(series, columns):
    import numpy as np
    return all(not np.any(series[column]) for column in columns if column in series)


def scene_title(series, what):
    scene = series.scene()
    depth = "; 2-D: per metre of depth" if series.per_depth else ""
    return f"{what}{depth}" + (f"\n{scene}" if scene else "")


def peak(times, values):
    """(time, value) of the largest |value|."""
    import numpy as np
    k = int(np.argmax(np.abs(values)))
    return float(times[k]), float(values[k])


@functools.lru_cache(maxsize=None)
def signals_module(filtering=True):
    """scripts/load_signals.py (beside this script, or in <prefix>/share/flotsam/python when installed),
    found once. With `filtering`: None if scipy is missing (the rows are then drawn alone)."""
    here = os.path.dirname(os.path.realpath(__file__))
    for folder in (here, os.path.join(here, os.pardir, "share", "flotsam", "python")):
        if os.path.isfile(os.path.join(folder, "load_signals.py")):
            if os.path.abspath(folder) not in sys.path:
                sys.path.insert(0, os.path.abspath(folder))
            break
    else:
        fail("cannot find load_signals.py beside the script or in <prefix>/share/flotsam/python")
    import load_signals
    if filtering:
        try:
            import scipy.signal  # noqa: F401
        except ImportError:
            return None
    return load_signals


def draw(axis, times, values, style, colour, name, means=True):
    """A series as its rows (thin) and, with a cutoff, low-passed (bold, labelled); the rows alone (labelled)
    otherwise. `means`: the rows are interval means (placed at their intervals' centres when filtered)."""
    signals = signals_module() if CUTOFF_HZ[0] > 0.0 else None
    if signals is None:
        axis.plot(times, values, style, color=colour, linewidth=1.0, label=name)
        return
    centres = signals.sample_times(times, means)
    filtered, _ = signals.low_pass(centres, values, CUTOFF_HZ[0])
    axis.plot(times, values, style, color=colour, linewidth=0.6, alpha=0.4)
    axis.plot(centres, filtered, style, color=colour, linewidth=1.4, label=name)


def filter_note():
    """What the bold lines are, for a figure's notes."""
    if CUTOFF_HZ[0] <= 0.0:
        return "rows as written"
    if signals_module() is None:
        return "rows as written (no scipy: python3-scipy draws them low-passed too)"
    return (f"thin: the rows; bold: low-passed at {CUTOFF_HZ[0]:g} Hz (zero phase), as a sensor of that bandwidth "
            "sees them;\nscripts/load_report.py gives their peaks, impulse, rise and decay")


# --- loads.png ----------------------------------------------------------------------------------------

def plot_loads(series, out_dir, shown_walls, plt):
    import numpy as np
    walls = names_with(series, "_fx")
    force_axes = [a for a in "xyz" if any(f"{w}_f{a}" in series for w in walls)]
    moment_axes = [a for a in "xyz" if any(f"{w}_m{a}" in series for w in walls)]
    if shown_walls is not None:
        unknown = [w for w in shown_walls if w not in walls]
        if unknown:
            fail(f"--show-walls: no wall {', '.join(unknown)} in {series.path} (walls: {', '.join(walls)})")
        drawn = [w for w in walls if w in shown_walls]
        skipped = []
    else:
        drawn, skipped = [], []
        for wall in walls:
            columns = [f"{wall}_f{a}" for a in force_axes] + [f"{wall}_m{a}" for a in moment_axes]
            (skipped if all_zero(series, columns) else drawn).append(wall)

    time = series["time"]
    colours = wall_colours(walls)
    force_unit = series.unit("_fx", "N/m" if series.per_depth else "N")
    moment_unit = series.unit("_mz", "N m/m" if series.per_depth else "N m")
    forces = [series[f"{w}_f{a}"] for w in drawn for a in force_axes]
    moments = [series[f"{w}_m{a}"] for w in drawn for a in moment_axes if f"{w}_m{a}" in series]
    force_scale, force_unit = prefixed(np.concatenate(forces) if forces else [], force_unit)
    moment_scale, moment_unit = prefixed(np.concatenate(moments) if moments else [], moment_unit)

    figure, (force_axis, moment_axis) = plt.subplots(2, 1, sharex=True, figsize=(9, 7.5),
                                                     gridspec_kw={"height_ratios": [3, 2]})
    zero_components = []
    for wall in drawn:
        for a in force_axes:
            column = f"{wall}_f{a}"
            if shown_walls is None and all_zero(series, [column]):
                zero_components.append(column)
                continue
            draw(force_axis, time, force_scale * series[column], COMPONENT_STYLES[a], colours[wall],
                 f"{wall} $F_{a}$")
        for a in moment_axes:
            column = f"{wall}_m{a}"
            if column not in series:
                continue
            if shown_walls is None and all_zero(series, [column]):
                zero_components.append(column)
                continue
            style = "-" if len(moment_axes) == 1 else COMPONENT_STYLES[a]   # 2-D: M_z alone, solid
            moment_axis.plot(time, moment_scale * series[column], style, color=colours[wall],
                             linewidth=1.0, label=f"{wall} $M_{a}$")
    force_axis.set_ylabel(label("force on the wall", force_unit))
    moment_axis.set_ylabel(label("moment", moment_unit))
    moment_axis.set_xlabel(label("time", series.unit("time", "s")))
    for axis in (force_axis, moment_axis):
        axis.axhline(0.0, color="0.6", linewidth=0.6)
        axis.grid(True, alpha=0.3)
        if axis.get_legend_handles_labels()[0]:
            axis.legend(fontsize=8, loc="best", ncol=2 if len(drawn) > 3 else 1)
    notes = ["mean force over each row's interval, exerted by the material on the wall (world frame)", filter_note()]
    if skipped:
        notes.append("left out (zero load throughout): " + ", ".join(skipped))
    if zero_components:
        notes.append("not drawn (zero throughout): " + ", ".join(zero_components))
    moment_axis.text(0.0, -0.22 - 0.0, "\n".join(notes), transform=moment_axis.transAxes, fontsize=7.5,
                     va="top", color="0.3")
    force_axis.set_title(scene_title(series, "Wall loads"), fontsize=10)
    figure.tight_layout()
    path = os.path.join(out_dir, "loads.png")
    figure.savefig(path, dpi=120)
    plt.close(figure)

    for wall in skipped:
        print(f"plot_loads: wall {wall}: zero load throughout, left out of loads.png")
    for wall in drawn:
        magnitude = np.sqrt(sum(series[f"{wall}_f{a}"] ** 2 for a in force_axes))
        if np.any(magnitude):
            t, value = peak(time, magnitude)
            print(f"plot_loads: wall {wall}: peak |F| = {value:.6g} {series.unit('_fx', '')} at t = {t:.4g} s")
    return path


def wall_colours(names):
    palette = ["tab:red", "tab:blue", "tab:green", "tab:purple", "tab:orange", "tab:brown", "tab:pink",
               "tab:olive", "tab:cyan", "tab:gray"]
    return {name: palette[k % len(palette)] for k, name in enumerate(names)}


# --- gauges.png ---------------------------------------------------------------------------------------

def plot_gauges(series, out_dir, plt):
    import numpy as np
    time = series["time"]
    kinds = []
    pressure = names_with(series, "_pressure")
    level = names_with(series, "_level")
    velocity = names_with(series, "_vx")
    if pressure:
        kinds.append("pressure")
    if level:
        kinds.append("level")
    if velocity:
        kinds.append("velocity")
    if not kinds:
        print(f"plot_loads: {series.path}: no gauge columns, gauges.png not written")
        return None
    figure, axes = plt.subplots(len(kinds), 1, sharex=True, figsize=(9, 2.2 + 2.4 * len(kinds)), squeeze=False)
    axes = axes[:, 0]
    colours = wall_colours(pressure + level + velocity)
    for axis, kind in zip(axes, kinds):
        if kind == "pressure":
            values = [series[f"{g}_pressure"] for g in pressure]
            scale, unit = prefixed(np.concatenate(values), series.unit("_pressure", "Pa"))
            for g in pressure:
                # a wall_pressure gauge (no _samples) is an interval mean, a fluid one a sample
                draw(axis, time, scale * series[f"{g}_pressure"], "-", colours[g], g,
                     means=f"{g}_samples" not in series)
            axis.set_ylabel(label("pressure", unit))
        elif kind == "level":
            for g in level:
                axis.plot(time, series[f"{g}_level"], color=colours[g], linewidth=1.2, label=g)
            axis.set_ylabel(label("water level\nabove the gauge", series.unit("_level", "m")))
        else:
            for g in velocity:
                seen = series[f"{g}_samples"] > 0 if f"{g}_samples" in series else np.ones_like(time, bool)
                for a in "xyz":
                    column = f"{g}_v{a}"
                    if column in series:
                        values = np.where(seen, series[column], np.nan)   # no fluid there: no velocity
                        axis.plot(time, values, COMPONENT_STYLES[a], color=colours[g], linewidth=1.0,
                                  label=f"{g} $v_{a}$")
            axis.set_ylabel(label("fluid velocity", series.unit("_vx", "m/s")))
        axis.axhline(0.0, color="0.6", linewidth=0.6)
        axis.grid(True, alpha=0.3)
        axis.legend(fontsize=8, loc="best")
    axes[-1].set_xlabel(label("time", series.unit("time", "s")))
    axes[0].set_title(scene_title(series, "Gauges (pressure, level: 0 where the gauge sees no fluid; velocity: gap)"), fontsize=10)
    if pressure:
        axes[-1].text(0.0, -0.3, "pressure: " + filter_note(), transform=axes[-1].transAxes, fontsize=7.5,
                      va="top", color="0.3")
    figure.tight_layout()
    path = os.path.join(out_dir, "gauges.png")
    figure.savefig(path, dpi=120)
    plt.close(figure)
    for g in pressure:
        t, value = peak(time, series[f"{g}_pressure"])
        print(f"plot_loads: gauge {g}: peak pressure {value:.6g} {series.unit('_pressure', 'Pa')} at t = {t:.4g} s")
    for g in level:
        t, value = peak(time, series[f"{g}_level"])
        print(f"plot_loads: gauge {g}: highest level {value:.4g} {series.unit('_level', 'm')} at t = {t:.4g} s")
    for g in velocity:
        speed = np.sqrt(sum(series[f"{g}_v{a}"] ** 2 for a in "xyz" if f"{g}_v{a}" in series))
        if f"{g}_samples" in series:
            speed = np.where(series[f"{g}_samples"] > 0, speed, 0.0)
        t, value = peak(time, speed)
        print(f"plot_loads: gauge {g}: top speed {value:.4g} {series.unit('_vx', 'm/s')} at t = {t:.4g} s")
    return path


# --- bodies.png ---------------------------------------------------------------------------------------

def plot_bodies(series, out_dir, plt):
    import numpy as np
    bodies = names_with(series, "_vx")
    if not bodies:
        print(f"plot_loads: {series.path}: no body columns, bodies.png not written")
        return None
    three_d = any(f"{b}_rx" in series for b in bodies)
    axes_used = [a for a in "xyz" if any(f"{b}_v{a}" in series for b in bodies)]
    time = series["time"]
    colours = wall_colours(bodies)
    time_label = label("time", series.unit("time", "s"))

    figure = plt.figure(figsize=(11, 8))
    if three_d:
        path_axis = figure.add_subplot(2, 2, 1, projection="3d")
    else:
        path_axis = figure.add_subplot(2, 2, 1)
    velocity_axis = figure.add_subplot(2, 2, 2)
    rotation_axis = figure.add_subplot(2, 2, 3, sharex=velocity_axis)
    force_axis = figure.add_subplot(2, 2, 4, sharex=velocity_axis)

    length_unit = series.unit("_x", "m")
    for b in bodies:
        x, y = series[f"{b}_x"], series[f"{b}_y"]
        if three_d:
            z = series[f"{b}_z"]
            path_axis.plot(x, y, z, color=colours[b], linewidth=1.2, label=b)
            path_axis.scatter([x[0]], [y[0]], [z[0]], color=colours[b], marker="o")
            path_axis.scatter([x[-1]], [y[-1]], [z[-1]], color=colours[b], marker="s")
        else:
            path_axis.plot(x, y, color=colours[b], linewidth=1.2, label=b)
            path_axis.plot(x[0], y[0], "o", color=colours[b], markersize=6, markerfacecolor="white")
            path_axis.plot(x[-1], y[-1], "s", color=colours[b], markersize=6)
            # a few time marks along the path
            for k in np.linspace(0, len(time) - 1, 6).astype(int)[1:-1]:
                path_axis.annotate(f"{time[k]:.2g} s", (x[k], y[k]), fontsize=7, color="0.3",
                                   xytext=(3, 3), textcoords="offset points")
        for a in axes_used:
            column = f"{b}_v{a}"
            if column in series:
                velocity_axis.plot(time, series[column], COMPONENT_STYLES[a], color=colours[b], linewidth=1.0,
                                   label=f"{b} $v_{a}$")
        if three_d:
            for a in "xyz":
                column = f"{b}_r{a}"
                if column in series:
                    rotation_axis.plot(time, series[column], COMPONENT_STYLES[a], color=colours[b],
                                       linewidth=1.0, label=f"{b} $r_{a}$")
        elif f"{b}_angle" in series:
            rotation_axis.plot(time, series[f"{b}_angle"], color=colours[b], linewidth=1.0, label=b)

    forces = [series[f"{b}_f{a}"] for b in bodies for a in axes_used if f"{b}_f{a}" in series]
    force_scale, force_unit = prefixed(np.concatenate(forces) if forces else [],
                                       series.unit("_fx", "N/m" if series.per_depth else "N"))
    for b in bodies:
        for a in axes_used:
            column = f"{b}_f{a}"
            if column in series:
                force_axis.plot(time, force_scale * series[column], COMPONENT_STYLES[a], color=colours[b],
                                linewidth=1.0, label=f"{b} $F_{a}$")

    if three_d:
        path_axis.set_xlabel(label("x", length_unit))
        path_axis.set_ylabel(label("y", length_unit))
        path_axis.set_zlabel(label("z", length_unit))
    else:
        path_axis.set_xlabel(label("x", length_unit))
        path_axis.set_ylabel(label("y", length_unit))
        path_axis.set_aspect("equal", adjustable="datalim")
        path_axis.grid(True, alpha=0.3)
    path_axis.set_title("centroid path (o start, \u25a0 end)", fontsize=9)
    velocity_axis.set_ylabel(label("centroid velocity", series.unit("_vx", "m/s")))
    rotation_axis.set_ylabel(label("rotation vector" if three_d else "rotation angle (ccw)",
                                   series.unit("_rx" if three_d else "_angle", "rad")))
    force_axis.set_ylabel(label("resultant force on the body\n(fluid, walls, bodies)", force_unit))
    for axis in (velocity_axis, rotation_axis, force_axis):
        axis.axhline(0.0, color="0.6", linewidth=0.6)
        axis.grid(True, alpha=0.3)
        axis.set_xlabel(time_label)
    for axis in (path_axis, velocity_axis, rotation_axis, force_axis):
        if axis.get_legend_handles_labels()[0]:
            axis.legend(fontsize=8, loc="best")
    figure.suptitle(scene_title(series, "Solid bodies"), fontsize=10)
    figure.tight_layout()
    path = os.path.join(out_dir, "bodies.png")
    figure.savefig(path, dpi=120)
    plt.close(figure)
    for b in bodies:
        speed = np.sqrt(sum(series[f"{b}_v{a}"] ** 2 for a in axes_used if f"{b}_v{a}" in series))
        t, value = peak(time, speed)
        print(f"plot_loads: body {b}: top speed {value:.4g} {series.unit('_vx', 'm/s')} at t = {t:.4g} s")
    return path


# --- main ---------------------------------------------------------------------------------------------

def fail(message):
    print(f"plot_loads: error: {message}", file=sys.stderr)
    sys.exit(2)


def main():
    parser = argparse.ArgumentParser(
        description="Plot loads.csv, gauges.csv and bodies.csv of a Flotsam run to PNG.",
        epilog="See the docstring of scripts/plot_loads.py and docs/output.md.")
    parser.add_argument("folder", help="output folder of a run (&run output_dir)")
    parser.add_argument("--out", metavar="DIR", help="folder for the PNGs (default: the output folder)")
    parser.add_argument("--show-walls", metavar="NAME,...",
                        help="draw only these walls of loads.csv (comma separated)")
    parser.add_argument("--cutoff", type=float, default=200.0, metavar="HZ",
                        help="draw forces and pressures also low-passed at this cutoff (default 200; 0: rows only)")
    arguments = parser.parse_args()
    if arguments.cutoff < 0.0:
        fail(f"--cutoff must be >= 0 Hz, got {arguments.cutoff:g}")
    CUTOFF_HZ[0] = arguments.cutoff

    folder = arguments.folder
    if not os.path.isdir(folder):
        fail(f"no folder {folder}")
    present = {name: os.path.join(folder, f"{name}.csv") for name in FILES
               if os.path.isfile(os.path.join(folder, f"{name}.csv"))}
    if not present:
        fail(f"{folder} holds none of loads.csv, gauges.csv, bodies.csv (the scene has no walls, gauges "
             "or solid bodies, or the run has not started)")
    shown_walls = None
    if arguments.show_walls is not None:
        shown_walls = [name.strip() for name in arguments.show_walls.split(",") if name.strip()]
        if "loads" not in present:
            fail(f"--show-walls: {folder} has no loads.csv (the scene has no walls)")
        with open(present["loads"], encoding="utf-8") as file:
            walls = [column[:-3] for column in file.readline().strip().split(",") if column.endswith("_fx")]
        unknown = [name for name in shown_walls if name not in walls]
        if unknown:
            fail(f"--show-walls: no wall {', '.join(unknown)} in {present['loads']} (walls: {', '.join(walls)})")
    out_dir = arguments.out or folder
    os.makedirs(out_dir, exist_ok=True)

    signals_module(filtering=False).reexec_with_debian_python(__file__, ("numpy", "matplotlib"),
                                                              "FLOTSAM_PLOT_REEXEC", fail)
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    written = []
    for name, path in present.items():
        try:
            series = Series(path)
        except (OSError, ValueError) as error:
            fail(str(error))
        if len(series) == 0:
            print(f"plot_loads: {path} has no rows yet, {name}.png not written")
            continue
        if name == "loads":
            written.append(plot_loads(series, out_dir, shown_walls, plt))
        elif name == "gauges":
            written.append(plot_gauges(series, out_dir, plt))
        else:
            written.append(plot_bodies(series, out_dir, plt))
    for path in written:
        if path:
            print(path)


if __name__ == "__main__":
    main()
