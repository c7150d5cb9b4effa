"""Load signals as a sensor sees them (docs/loads.md, "Peaks as a sensor sees them"): the rows of
loads.csv, panels.csv and gauges.csv low-passed by a zero-phase filter, and the peak, impulse, rise and
decay of the largest event. Used by scripts/load_report.py and scripts/plot_loads.py.

Rows of loads.csv, panels.csv and of wall_pressure gauges are means over the interval since the previous
row (docs/output.md): they are placed at the interval's centre, and their impulse over [a, b] is the exact
integral of that piecewise-constant signal. Rows of fluid gauges (pressure with `_samples`) are samples
at the row's time.

The filter: a Butterworth low-pass of order FILTER_ORDER run forward and backward (scipy.signal.sosfiltfilt:
zero phase, so a peak is not delayed; the amplitude response is the square of the one-way filter's, -6 dB
at the cutoff), on the rows resampled to their median spacing. DEFAULT_CUTOFF_HZ, and why: docs/loads.md.
"""

import os
import re
import sys

try:
    import numpy as np
except ImportError:          # reexec_with_debian_python can still run and find Debian's
    np = None

#: default low-pass cutoff [Hz] at the scene's scale (a lab flume): docs/loads.md says why
DEFAULT_CUTOFF_HZ = 200.0
#: an event is where the filtered signal exceeds this fraction of its peak, around the peak [R]
DEFAULT_THRESHOLD = 0.1
FILTER_ORDER = 4
#: a cutoff at or above this fraction of the rows' Nyquist frequency is lowered to it (the rows cannot
#: carry more; the report says so)
NYQUIST_FRACTION = 0.8


def reexec_with_debian_python(script, modules, flag, fail):
    """Run `script` again with /usr/bin/python3 when this python cannot import `modules` (a pyenv or venv
    python first on PATH) and Debian's may; `flag` (an environment variable) stops a second attempt,
    `fail(message)` reports what is missing."""
    import importlib
    try:
        for module in modules:
            importlib.import_module(module)
        return
    except ImportError as error:
        debian = "/usr/bin/python3"
        if os.path.realpath(sys.executable) != os.path.realpath(debian) and os.access(debian, os.X_OK) \
                and not os.environ.get(flag):
            os.environ[flag] = "1"
            os.execv(debian, [debian, os.path.abspath(script)] + sys.argv[1:])
        fail(f"{error} (Debian: apt-get install python3-numpy python3-scipy python3-matplotlib)")


def parse_units(comments):
    """{'time': 's', '_fx': 'N/m', '_mz': 'N m/m', ...} from a line such as
    'units: time s; _fx _fy _fz N/m; _mx _my _mz N m/m (2-D plane strain: per metre of depth)'."""
    units = {}
    for comment in comments:
        if not comment.lower().startswith("units:"):
            continue
        for part in comment.split(":", 1)[1].split(";"):
            part = re.sub(r"\(.*\)", "", part).strip()   # explanations in parentheses
            words = part.split()
            keys = []
            while words and (words[0].startswith("_") or words[0] == "time"):
                keys.append(words.pop(0))
            for key in keys:
                units[key] = " ".join(words)
    return units


def row_intervals(times, start=0.0):
    """The interval (t_prev, t] each row of an interval-mean file covers: the first from `start`."""
    times = np.asarray(times, dtype=float)
    previous = np.concatenate([[start], times[:-1]])
    return previous, times


def sample_times(times, means, start=0.0):
    """Where a row's value belongs: the centre of its interval for interval means, the row time for samples."""
    if not means:
        return np.asarray(times, dtype=float)
    previous, times = row_intervals(times, start)
    return 0.5 * (previous + times)


def effective_cutoff(times, cutoff):
    """(cutoff actually used [Hz], spacing of the resampled rows [s], note): the cutoff lowered to
    NYQUIST_FRACTION of the rows' Nyquist frequency if it is above it."""
    spacing = float(np.median(np.diff(times))) if len(times) > 1 else 0.0
    if spacing <= 0.0:
        return 0.0, spacing, "fewer than two rows: not filtered"
    limit = NYQUIST_FRACTION * 0.5 / spacing
    if cutoff >= limit:
        return limit, spacing, (f"cutoff {cutoff:g} Hz lowered to {limit:.4g} Hz ({NYQUIST_FRACTION} of the rows' "
                                f"Nyquist frequency; rows every {spacing:.3g} s: a smaller &run load_interval keeps more)")
    return cutoff, spacing, ""


def low_pass(times, values, cutoff):
    """The values low-passed at `cutoff` [Hz] with zero phase, at the same times, and a note (empty, or
    what was changed). Times need not be evenly spaced: the rows are resampled to their median spacing,
    filtered, and read back at their own times."""
    from scipy import signal
    times = np.asarray(times, dtype=float)
    values = np.asarray(values, dtype=float)
    used, spacing, note = effective_cutoff(times, cutoff)
    if used <= 0.0 or len(times) < 3 * (FILTER_ORDER + 1):
        return values.copy(), note or "too few rows to filter: not filtered"
    count = int(round((times[-1] - times[0]) / spacing)) + 1
    even = times[0] + spacing * np.arange(count)
    resampled = np.interp(even, times, values)
    sections = signal.butter(FILTER_ORDER, used, fs=1.0 / spacing, output="sos")
    filtered = signal.sosfiltfilt(sections, resampled)
    return np.interp(times, even, filtered), note


def cumulative_impulse(times, values, means, start=0.0):
    """(times, integral of the signal from `start` to them): exact for interval means (a row's value over
    its whole interval), trapezoidal for samples."""
    times = np.asarray(times, dtype=float)
    values = np.asarray(values, dtype=float)
    if means:
        previous, ends = row_intervals(times, start)
        knots = np.concatenate([[start], ends])
        integral = np.concatenate([[0.0], np.cumsum(values * (ends - previous))])
        return knots, integral
    integral = np.concatenate([[0.0], np.cumsum(0.5 * (values[1:] + values[:-1]) * np.diff(times))])
    return times, integral


def crossing(times, values, level, index, step):
    """The time where `values` (positive at `index`) falls below `level` going from `index` in direction
    `step` (-1: back, +1: forward), by linear interpolation; the first or last time if it never does."""
    k = index
    while 0 <= k + step < len(values):
        if values[k + step] < level:
            a, b = values[k + step], values[k]
            fraction = (b - level) / (b - a) if b != a else 0.0
            return times[k] + fraction * (times[k + step] - times[k])
        k += step
    return times[k]


def top_time(times, aligned, k, top=0.9):
    """When a peak (at index k of the positive `aligned`) happens: the vertex of the least-squares parabola
    through the samples around k above `top` of it, if there are 4 or more and the vertex lies among them;
    else the time of sample k. On a flat-topped pulse the largest sample wanders with the noise left after
    the filter; the parabola through the top averages it out [R]."""
    level = top * aligned[k]
    first, last = k, k
    while first > 0 and aligned[first - 1] >= level:
        first -= 1
    while last < len(aligned) - 1 and aligned[last + 1] >= level:
        last += 1
    if last - first + 1 < 4:
        return float(times[k])
    t = times[first:last + 1]
    centre = 0.5 * (t[0] + t[-1])
    a, b, _ = np.polyfit(t - centre, aligned[first:last + 1], 2)
    if a >= 0.0:
        return float(times[k])
    vertex = centre - b / (2.0 * a)
    return float(vertex) if t[0] <= vertex <= t[-1] else float(times[k])


class Event:
    """The largest event of one series: raw and filtered peak, impulse, rise and decay (docs/loads.md)."""

    def __init__(self, times, values, means, cutoff=DEFAULT_CUTOFF_HZ, threshold=DEFAULT_THRESHOLD, start=0.0):
        self.times = sample_times(times, means, start)
        self.values = np.asarray(values, dtype=float)
        self.filtered, self.note = low_pass(self.times, self.values, cutoff)
        self.cutoff, _, _ = effective_cutoff(self.times, cutoff)
        self.threshold = threshold
        k = int(np.argmax(np.abs(self.values)))
        self.raw_peak, self.raw_peak_time = float(self.values[k]), float(self.times[k])
        k = int(np.argmax(np.abs(self.filtered)))
        self.peak = float(self.filtered[k])
        sign = 1.0 if self.peak >= 0.0 else -1.0
        aligned = sign * self.filtered
        self.peak_time = top_time(self.times, aligned, k)
        level = threshold * abs(self.peak)
        if self.peak == 0.0:
            self.start = self.end = self.peak_time
        else:
            self.start = float(crossing(self.times, aligned, level, k, -1))
            self.end = float(crossing(self.times, aligned, level, k, +1))
        knots, integral = cumulative_impulse(times, values, means, start)
        self.impulse = float(np.interp(self.end, knots, integral) - np.interp(self.start, knots, integral))
        self.rise = self.peak_time - self.start
        self.decay = self.end - self.peak_time
