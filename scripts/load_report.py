#!/usr/bin/env python3
"""The design values of a Flotsam run's loads: per series the raw and the sensor-filtered peak, the impulse
of the event, its rise and decay times, and when each happens (docs/loads.md, "Peaks as a sensor sees them").

usage: scripts/load_report.py <output folder> [--cutoff HZ] [--threshold FRACTION] [--out DIR] [--no-plot]
       (installed: flotsam-load-report)

Reads whichever of loads.csv, panels.csv and gauges.csv the run wrote: every force and moment column of
loads.csv, every column of panels.csv, the _pressure columns of gauges.csv. Per series:

  peak_raw, peak_raw_time              the largest |value| of the rows (signed) and when
  peak_filtered, peak_filtered_time    the same after a zero-phase Butterworth low-pass at --cutoff
                                       (default 200 Hz; why: docs/loads.md)
  event_start, event_end               around the filtered peak, where the filtered signal crosses
                                       --threshold (default 0.1) of the peak
  rise_time, decay_time                peak - start, end - peak [s]
  impulse                              the integral of the rows from event_start to event_end (exact for the
                                       interval means of loads.csv, panels.csv and wall_pressure gauges)

Rows that are interval means are placed at the centre of their interval (the times in the report). Writes
<out>/load_report.csv (read with pandas.read_csv(path, comment='#')) and <out>/load_report.png (per file
and unit, the series with the largest filtered peaks, raw and filtered, the event shaded); replaces a
previous report there and says so. Exit status 2 on a folder without those files or bad arguments.
Needs numpy, scipy and matplotlib (Debian: python3-scipy python3-matplotlib).
"""

import argparse
import os
import sys


def find_signals_module():
    """load_signals.py beside this script (a checkout) or in <prefix>/share/flotsam/python (installed)."""
    here = os.path.dirname(os.path.realpath(__file__))
    for folder in (here, os.path.join(here, os.pardir, "share", "flotsam", "python")):
        if os.path.isfile(os.path.join(folder, "load_signals.py")):
            sys.path.insert(0, os.path.abspath(folder))
            return
    fail("cannot find load_signals.py beside the script or in <prefix>/share/flotsam/python")


def fail(message):
    print(f"load_report: error: {message}", file=sys.stderr)
    sys.exit(2)


class CsvFile:
    """A run's CSV: header, '#' comments, columns of floats."""

    def __init__(self, path):
        import numpy as np
        self.path = path
        self.comments, rows = [], []
        with open(path, encoding="utf-8") as file:
            self.names = file.readline().strip().split(",")
            for line in file:
                line = line.strip()
                if line.startswith("#"):
                    self.comments.append(line.lstrip("#").strip())
                elif line:
                    rows.append([float(value) for value in line.split(",")])
        if self.names[0] != "time":
            raise ValueError(f"{path}: the first column is not 'time'")
        data = np.array(rows, dtype=float).reshape(len(rows), len(self.names))
        self.columns = {name: data[:, k] for k, name in enumerate(self.names)}

    def scene(self):
        import re
        for comment in self.comments:
            match = re.search(r"from scene (.+?)( \(resolved.*)?$", comment)
            if match:
                return match.group(1).strip()
        return ""


def series_of(name, csv):
    """(column, unit, interval means?) of the series the report covers in file `name`."""
    import load_signals
    units = load_signals.parse_units(csv.comments)
    chosen = []
    for column in csv.names[1:]:
        suffix = "_" + column.rsplit("_", 1)[-1]
        if name == "gauges":
            if not column.endswith("_pressure"):
                continue
            # a wall_pressure gauge has no _samples column and is an interval mean; a fluid one is a sample
            means = column[: -len("_pressure")] + "_samples" not in csv.names
        else:
            means = True
        chosen.append((column, units.get(suffix, ""), means))
    return chosen


def impulse_unit(unit):
    return f"{unit} s" if unit else "s"


def write_report(path, rows, scene, cutoff, threshold, notes):
    existed = os.path.exists(path)
    header = ["file", "series", "unit", "peak_raw", "peak_raw_time", "peak_filtered", "peak_filtered_time",
              "cutoff_hz", "event_start", "event_end", "rise_time", "decay_time", "impulse", "impulse_unit"]
    with open(path + ".tmp", "w", encoding="utf-8") as out:
        out.write(",".join(header) + "\n")
        out.write(f"# load_report.csv: design values of the loads of run {scene or '?'} (scripts/load_report.py; "
                  "docs/loads.md, 'Peaks as a sensor sees them')\n")
        out.write(f"# filtered: zero-phase Butterworth low-pass, order 4, cutoff {cutoff:g} Hz (per series: "
                  f"cutoff_hz); event: around the filtered peak, above {threshold:g} of it\n")
        out.write("# units: times s; peak_* as the series' unit; impulse as impulse_unit; rows that are interval "
                  "means are placed at the centre of their interval\n")
        for note in notes:
            out.write(f"# note: {note}\n")
        for row in rows:
            out.write(",".join(row) + "\n")
    os.replace(path + ".tmp", path)
    return existed


def plot(path, reports, scene, plt, per_panel=6):
    """One panel per (file, unit): the series with the largest |filtered peak|, raw thin, filtered bold,
    the event shaded."""
    groups = {}
    for report in reports:
        groups.setdefault((report["file"], report["unit"]), []).append(report)
    figure, axes = plt.subplots(len(groups), 1, figsize=(9, 3.2 * len(groups)), squeeze=False)
    for axis, ((file, unit), members) in zip(axes[:, 0], groups.items()):
        members = sorted(members, key=lambda r: -abs(r["event"].peak))[:per_panel]
        for k, report in enumerate(members):
            event, colour = report["event"], f"C{k % 10}"
            axis.plot(event.times, event.values, color=colour, linewidth=0.6, alpha=0.45)
            axis.plot(event.times, event.filtered, color=colour, linewidth=1.4,
                      label=f"{report['series']} (filtered peak {event.peak:.4g} at {event.peak_time:.4g} s)")
            axis.axvspan(event.start, event.end, color=colour, alpha=0.06)
            axis.plot([event.peak_time], [event.peak], "o", color=colour, markersize=4)
        axis.axhline(0.0, color="0.6", linewidth=0.6)
        axis.set_ylabel(f"{file}.csv [{unit}]" if unit else f"{file}.csv")
        axis.grid(True, alpha=0.3)
        axis.legend(fontsize=7, loc="best")
    axes[-1, 0].set_xlabel("time [s]")
    cutoff = reports[0]["event"].cutoff if reports else 0.0
    axes[0, 0].set_title(f"Loads, raw (thin) and low-passed at {cutoff:g} Hz (bold); events shaded\n{scene}",
                         fontsize=10)
    figure.tight_layout()
    figure.savefig(path, dpi=120)
    plt.close(figure)


def main():
    parser = argparse.ArgumentParser(description="Peaks, impulse, rise and decay of a Flotsam run's loads.",
                                     epilog="See the docstring of scripts/load_report.py and docs/loads.md.")
    parser.add_argument("folder", help="output folder of a run (&run output_dir)")
    parser.add_argument("--cutoff", type=float, default=None, metavar="HZ",
                        help="low-pass cutoff [Hz] (default 200: docs/loads.md)")
    parser.add_argument("--threshold", type=float, default=None, metavar="FRACTION",
                        help="an event is where the filtered signal exceeds this fraction of its peak (default 0.1)")
    parser.add_argument("--out", metavar="DIR", help="folder for load_report.csv and .png (default: the output folder)")
    parser.add_argument("--no-plot", action="store_true", help="write load_report.csv only")
    arguments = parser.parse_args()
    if not os.path.isdir(arguments.folder):
        fail(f"no folder {arguments.folder}")
    find_signals_module()
    import load_signals
    load_signals.reexec_with_debian_python(__file__, ("numpy", "scipy.signal", "matplotlib"),
                                           "FLOTSAM_REPORT_REEXEC", fail)
    cutoff = load_signals.DEFAULT_CUTOFF_HZ if arguments.cutoff is None else arguments.cutoff
    threshold = load_signals.DEFAULT_THRESHOLD if arguments.threshold is None else arguments.threshold
    if not cutoff > 0.0:
        fail(f"--cutoff must be > 0 Hz, got {cutoff:g}")
    if not 0.0 < threshold < 1.0:
        fail(f"--threshold must lie in (0, 1), got {threshold:g}")
    present = [name for name in ("loads", "panels", "gauges")
               if os.path.isfile(os.path.join(arguments.folder, f"{name}.csv"))]
    if not present:
        fail(f"{arguments.folder} holds none of loads.csv, panels.csv, gauges.csv")
    out_dir = arguments.out or arguments.folder
    os.makedirs(out_dir, exist_ok=True)

    reports, rows, notes, scene = [], [], set(), ""
    for name in present:
        try:
            csv = CsvFile(os.path.join(arguments.folder, f"{name}.csv"))
        except (OSError, ValueError) as error:
            fail(str(error))
        scene = scene or csv.scene()
        if len(csv.columns["time"]) == 0:
            notes.add(f"{name}.csv has no rows yet")
            continue
        for column, unit, means in series_of(name, csv):
            event = load_signals.Event(csv.columns["time"], csv.columns[column], means, cutoff, threshold)
            if event.note:
                notes.add(event.note)
            reports.append({"file": name, "series": column, "unit": unit, "event": event})
            rows.append([name, column, unit] + [repr(float(v)) for v in (
                event.raw_peak, event.raw_peak_time, event.peak, event.peak_time, event.cutoff, event.start,
                event.end, event.rise, event.decay, event.impulse)] + [impulse_unit(unit)])
    if not reports:
        fail(f"{arguments.folder}: no rows to report on")
    path = os.path.join(out_dir, "load_report.csv")
    replaced = write_report(path, rows, scene, cutoff, threshold, sorted(notes))
    print(f"{path}" + (" (replaced the previous report)" if replaced else ""))
    for note in sorted(notes):
        print(f"load_report: note: {note}")
    if not arguments.no_plot:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        picture = os.path.join(out_dir, "load_report.png")
        plot(picture, reports, scene, plt)
        print(picture)


if __name__ == "__main__":
    main()
