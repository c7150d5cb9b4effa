"""Ensembles of random cases for scripts/study (docs/loads.md, "Ensembles of random debris"): the
random variables of a study file's [random] section, their samples, and the distribution of the peak
filtered force and impulse over the cases.

A [random] line is `<group>[:<entry>] <variable> = <distribution>`, the distribution one of
    uniform(low, high)        normal(mean, standard_deviation)        choice([a, b, ...])
with numbers or lists of numbers (one per component: a vector variable such as velocity). The variable
`shift` of a body moves it: its lower and upper (as the scene gives them) both shifted by the sample.
Case i's values come from numpy's default_rng([seed, i]), drawn in the order of the file: the same
seed gives the same cases, and case i does not depend on how many cases the study has.
"""

import ast
import math
import re

DISTRIBUTIONS = ("uniform", "normal", "choice")
#: the running median is steady when it stays within this fraction of the final median
STEADY_FRACTION = 0.05


def parse_distribution(text, where):
    """(name, arguments) of `uniform(a, b)`, `normal(m, s)` or `choice([...])`; ValueError naming `where`."""
    try:
        tree = ast.parse(text.strip(), mode="eval").body
    except SyntaxError:
        raise ValueError(f"{where}: expected uniform(low, high), normal(mean, sd) or choice([...]), got {text}")
    if not (isinstance(tree, ast.Call) and isinstance(tree.func, ast.Name) and tree.func.id in DISTRIBUTIONS):
        raise ValueError(f"{where}: expected uniform(low, high), normal(mean, sd) or choice([...]), got {text}")
    try:
        arguments = [ast.literal_eval(a) for a in tree.args]
    except ValueError:
        raise ValueError(f"{where}: the arguments must be numbers or lists of numbers, got {text}")
    name = tree.func.id
    if name == "choice":
        if len(arguments) != 1 or not isinstance(arguments[0], (list, tuple)) or not arguments[0]:
            raise ValueError(f"{where}: choice takes one non-empty list, got {text}")
    else:
        if len(arguments) != 2:
            raise ValueError(f"{where}: {name} takes two arguments, got {text}")
        a, b = (list(x) if isinstance(x, (list, tuple)) else [x] for x in arguments)
        if len(a) != len(b) or not all(isinstance(v, (int, float)) for v in a + b):
            raise ValueError(f"{where}: {name}'s two arguments must be numbers or lists of one length, got {text}")
        if name == "uniform" and any(hi < lo for lo, hi in zip(a, b)):
            raise ValueError(f"{where}: uniform(low, high) needs low <= high, got {text}")
        if name == "normal" and any(sd < 0 for sd in b):
            raise ValueError(f"{where}: normal(mean, sd) needs sd >= 0, got {text}")
    return name, arguments


def draw(rng, distribution):
    """One sample: a number, or a list for vector arguments."""
    name, arguments = distribution
    if name == "choice":
        options = arguments[0]
        return options[int(rng.integers(len(options)))]
    a, b = arguments
    vector = isinstance(a, (list, tuple))
    a, b = (list(a), list(b)) if vector else ([a], [b])
    if name == "uniform":
        values = [float(rng.uniform(low, high)) for low, high in zip(a, b)]
    else:
        values = [float(rng.normal(mean, sd)) for mean, sd in zip(a, b)]
    return values if vector else values[0]


def samples(variables, seed, count):
    """[[value per variable] for case 0 .. count - 1]: case i from default_rng([seed, i])."""
    import numpy as np
    return [[draw(np.random.default_rng([seed, i]), v["distribution"]) for v in variables] for i in range(count)]


def namelist_groups(text, group):
    """The `&group ... /` blocks of a namelist file as {variable: value text} (comments removed)."""
    text = re.sub(r"!.*", "", text)
    blocks = []
    for match in re.finditer(r"&" + group + r"\b(.*?)(?<![\w'\"])/", text, re.S | re.I):
        body, values = match.group(1), {}
        for item in re.finditer(r"(\w+)\s*=\s*(.*?)(?=,?\s*\w+\s*=|\s*$)", body, re.S):
            values[item.group(1).lower()] = item.group(2).strip().rstrip(",").strip()
        blocks.append(values)
    return blocks


def numbers(text):
    return [float(v) for v in re.split(r"[,\s]+", text.strip()) if v]


def shifted_box(scene_text, selector, selected):
    """(lower, upper) of the &body whose `selector` (material) is `selected`, for the shift of a body."""
    for block in namelist_groups(scene_text, "body"):
        if block.get(selector, "").strip("'\"") == selected:
            if "lower" not in block or "upper" not in block:
                raise ValueError(f"the &body of {selector} '{selected}' gives no lower and upper to shift")
            return numbers(block["lower"]), numbers(block["upper"])
    raise ValueError(f"the scene has no &body of {selector} '{selected}' to shift")


def steady_count(values, fraction=STEADY_FRACTION):
    """The number of cases after which the running median (of cases 1..n, in case order) stays within
    `fraction` of the median of all: n such that every n' >= n is within; len(values) if only the last is."""
    import numpy as np
    final = float(np.median(values))
    if final == 0.0:
        return len(values)
    count = len(values)
    for n in range(len(values), 0, -1):
        if abs(float(np.median(values[:n])) - final) > fraction * abs(final):
            break
        count = n
    return count


def summarise(rows, measures):
    """Per measure (column of rows): n, median, 10 % and 90 % quantiles, min, max and the steady count."""
    import numpy as np
    summary = []
    for measure in measures:
        values = [float(r[measure]) for r in rows if r.get(measure) not in (None, "", "nan")]
        values = [v for v in values if math.isfinite(v)]
        if not values:
            continue
        summary.append({"measure": measure, "cases": len(values), "median": float(np.median(values)),
                        "q10": float(np.quantile(values, 0.1)), "q90": float(np.quantile(values, 0.9)),
                        "min": min(values), "max": max(values),
                        "cases_for_steady_median": steady_count(values)})
    return summary


def box_plot(path, rows, measures, title, plt):
    """One box per measure (peaks in one panel, impulses in another), each case a dot."""
    groups = [("peak filtered force", [m for m in measures if m.endswith("_peak_filtered")]),
              ("impulse of the event", [m for m in measures if m.endswith("_impulse")])]
    groups = [(label, ms) for label, ms in groups if ms]
    figure, axes = plt.subplots(1, len(groups), figsize=(4.5 * len(groups), 4.5), squeeze=False)
    for axis, (label, members) in zip(axes[0], groups):
        data = [[float(r[m]) for r in rows if r.get(m) not in (None, "", "nan")] for m in members]
        axis.boxplot(data, whis=(10, 90), showfliers=False)
        for k, values in enumerate(data, start=1):
            axis.plot([k] * len(values), values, "o", color="C0", alpha=0.5, markersize=3)
        axis.set_xticks(range(1, len(members) + 1))
        axis.set_xticklabels([m.rsplit("_", 2)[0] if m.endswith("_peak_filtered") else m.rsplit("_", 1)[0]
                              for m in members], fontsize=8)
        axis.set_title(f"{label} (box: quartiles, whiskers 10-90 %)", fontsize=9)
        axis.set_ylabel("N s/m (2-D), N s (3-D)" if label.startswith("impulse") else "|F|: N/m (2-D), N (3-D)")
        axis.grid(True, alpha=0.3)
    figure.suptitle(title, fontsize=10)
    figure.tight_layout()
    figure.savefig(path, dpi=110)
    plt.close(figure)
