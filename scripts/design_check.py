#!/usr/bin/env python3
"""Design-code checks of a Flotsam run: the loads FEMA P-646 gives for the flow and debris the run itself
measured, printed beside the loads the run computed (docs/loads.md, "Design-code checks").

usage: scripts/design_check.py <output folder> --structure NAME [--level GAUGE --velocity GAUGE]
           [--breadth B] [--density RHO_S] [--drag C_D] [--surge-factor F] [--cutoff HZ]
           [--body NAME (--stiffness K | --youngs-modulus E --area A --length L) [--impact-coefficient C]]
           [--out FILE]

From gauges.csv (a 'level' or 'connected_level' gauge and a 'velocity' gauge upstream of the structure):
  momentum flux          (h u^2)(t) = level(t) * u(t)^2, u the velocity along the flow (x) while the velocity
                         gauge sees fluid (its _samples > 0); its maximum (h u^2)_max and when
  hydrodynamic force     F_d = 1/2 rho_s C_d B (h u^2)_max          FEMA P-646 (2012), eq. 6-5
  surge (impulsive)      F_s = 1.5 F_d                               FEMA P-646 (2012), eq. 6-7
From bodies.csv (a solid &body; its mass from the file's '# mass' line):
  debris impact          F_i = C u sqrt(k m), u the body's largest speed before the structure's filtered
                         peak, k the impact stiffness (given, or E A / L of the debris against a rigid
                         structure), C the impact coefficient (default 1.0: the elastic spring-mass peak;
                         FEMA P-646 adds factors for added mass and importance: docs/loads.md)
Beside them, from loads.csv: the structure's simulated force along the flow, its raw and filtered peak
(scripts/load_report.py's filter, --cutoff, default 200 Hz) and its mean over the time (h u^2) stays within
10 % of its maximum. Defaults: rho_s = 1100 kg/m^3 (water with sediment), C_d = 2.0, B = 1 m in 2-D (the
force per metre of depth) and required in 3-D. 2-D: forces per metre of depth, as the run writes them.
Writes the table to stdout and (--out) a CSV that pandas reads with comment='#'. Exit status 2 on bad
arguments or missing data.
"""

import argparse
import math
import os
import sys


def fail(message):
    print(f"design_check: error: {message}", file=sys.stderr)
    sys.exit(2)


def find_signals_module():
    here = os.path.dirname(os.path.realpath(__file__))
    for folder in (here, os.path.join(here, os.pardir, "share", "flotsam", "python")):
        if os.path.isfile(os.path.join(folder, "load_signals.py")):
            sys.path.insert(0, os.path.abspath(folder))
            return
    fail("cannot find load_signals.py beside the script or in <prefix>/share/flotsam/python")


def read_csv(folder, name):
    import pandas as pd
    path = os.path.join(folder, f"{name}.csv")
    if not os.path.isfile(path):
        fail(f"{folder} has no {name}.csv")
    with open(path, encoding="utf-8") as f:
        comments = [line.lstrip("#").strip() for line in f if line.startswith("#")]
    return pd.read_csv(path, comment="#"), comments


def gauges_of(frame, suffix):
    return [c[: -len(suffix)] for c in frame.columns if c.endswith(suffix)]


def pick(names, given, kind):
    if given is not None:
        if given not in names:
            fail(f"no {kind} gauge '{given}' in gauges.csv (there: {', '.join(names) or 'none'})")
        return given
    if len(names) != 1:
        fail(f"give --{kind} (gauges.csv has {len(names)} {kind} gauges: {', '.join(names) or 'none'})")
    return names[0]


def momentum_flux(gauges, level, velocity):
    """(times, h u^2) where the velocity gauge sees fluid (0 elsewhere)."""
    import numpy as np
    h = gauges[f"{level}_level"].to_numpy()
    u = gauges[f"{velocity}_vx"].to_numpy()
    seen = gauges[f"{velocity}_samples"].to_numpy() > 0 if f"{velocity}_samples" in gauges else np.ones_like(h, bool)
    return gauges["time"].to_numpy(), np.where(seen, h * u * u, 0.0)


def body_mass(comments, body):
    for comment in comments:
        if comment.startswith("mass"):
            for part in comment.split(":", 1)[1].split(";"):
                words = part.split()
                if len(words) == 2 and words[0] == body:
                    return float(words[1])
    fail(f"bodies.csv names no mass for body '{body}' (its '# mass' line; written by flotsam since issue 52)")


def main():
    parser = argparse.ArgumentParser(description="FEMA P-646 loads from a Flotsam run's gauges and bodies, "
                                     "beside its simulated loads.")
    parser.add_argument("folder")
    parser.add_argument("--structure", required=True, help="its name in loads.csv")
    parser.add_argument("--level", help="the level gauge (default: the only one)")
    parser.add_argument("--velocity", help="the velocity gauge (default: the only one)")
    parser.add_argument("--breadth", type=float, help="B [m], the structure's breadth across the flow (2-D: 1)")
    parser.add_argument("--density", type=float, default=1100.0, help="rho_s [kg/m^3] (default 1100)")
    parser.add_argument("--drag", type=float, default=2.0, help="C_d (default 2.0)")
    parser.add_argument("--surge-factor", type=float, default=1.5, help="F_s / F_d (default 1.5)")
    parser.add_argument("--cutoff", type=float, default=None, help="low-pass of the simulated peak [Hz] (default 200)")
    parser.add_argument("--body", help="a solid &body for the debris impact check")
    parser.add_argument("--stiffness", type=float, help="k [N/m; N/m per metre in 2-D]")
    parser.add_argument("--youngs-modulus", type=float, help="E of the debris [Pa]: k = E A / L")
    parser.add_argument("--area", type=float, help="A, the debris' section at the contact [m^2; m in 2-D]")
    parser.add_argument("--length", type=float, help="L, the debris' length along the impact [m]")
    parser.add_argument("--impact-coefficient", type=float, default=1.0, help="C of F_i = C u sqrt(k m) (default 1)")
    parser.add_argument("--out", help="also write the table as CSV here")
    arguments = parser.parse_args()
    if not os.path.isdir(arguments.folder):
        fail(f"no folder {arguments.folder}")
    find_signals_module()
    import load_signals
    load_signals.reexec_with_debian_python(__file__, ("numpy", "scipy.signal", "pandas"), "FLOTSAM_DESIGN_REEXEC", fail)
    import numpy as np

    loads, load_comments = read_csv(arguments.folder, "loads")
    column = f"{arguments.structure}_fx"
    if column not in loads:
        fail(f"loads.csv has no structure '{arguments.structure}' ({column})")
    two_d = f"{arguments.structure}_fz" not in loads
    breadth = arguments.breadth
    if breadth is None:
        if not two_d:
            fail("give --breadth B [m] (3-D: the structure's breadth across the flow)")
        breadth = 1.0
    unit = "N/m" if two_d else "N"
    cutoff = load_signals.DEFAULT_CUTOFF_HZ if arguments.cutoff is None else arguments.cutoff
    force = load_signals.Event(loads["time"], loads[column], True, cutoff)
    if force.note:
        print(f"design_check: note: {force.note}")

    rows = []   # (quantity, value, unit, how)
    gauges, _ = read_csv(arguments.folder, "gauges")
    level = pick(gauges_of(gauges, "_level"), arguments.level, "level")
    velocity = pick(gauges_of(gauges, "_vx"), arguments.velocity, "velocity")
    times, flux = momentum_flux(gauges, level, velocity)
    k = int(np.argmax(flux))
    flux_max, flux_time = float(flux[k]), float(times[k])
    drag = 0.5 * arguments.density * arguments.drag * breadth * flux_max
    surge = arguments.surge_factor * drag
    rows.append(("(h u^2)_max", flux_max, "m^3/s^2", f"gauges {level} x {velocity}^2, at t = {flux_time:.4g} s"))
    rows.append(("FEMA hydrodynamic F_d", drag, unit, f"1/2 rho_s C_d B (h u^2)_max, rho_s = {arguments.density:g}, "
                 f"C_d = {arguments.drag:g}, B = {breadth:g} m (FEMA P-646 2012 eq. 6-5)"))
    rows.append(("FEMA surge F_s", surge, unit, f"{arguments.surge_factor:g} F_d (FEMA P-646 2012 eq. 6-7)"))
    # the simulated force while the momentum flux is near its maximum: the quasi-steady drag it stands for
    near = flux >= 0.9 * flux_max
    window = (loads["time"] >= times[near].min()) & (loads["time"] <= times[near].max())
    mean_force = float(loads.loc[window, column].mean()) if window.any() else float("nan")
    rows.append(("simulated force, mean while h u^2 >= 0.9 max", mean_force, unit,
                 f"loads.csv {column}, {times[near].min():.4g} .. {times[near].max():.4g} s"))
    rows.append(("simulated force, raw peak", force.raw_peak, unit, f"at t = {force.raw_peak_time:.4g} s"))
    rows.append(("simulated force, filtered peak", force.peak, unit,
                 f"low-passed at {force.cutoff:g} Hz, at t = {force.peak_time:.4g} s"))

    if arguments.body:
        bodies, body_comments = read_csv(arguments.folder, "bodies")
        if f"{arguments.body}_vx" not in bodies:
            fail(f"bodies.csv has no body '{arguments.body}'")
        mass = body_mass(body_comments, arguments.body)
        if arguments.stiffness is not None:
            stiffness, how = arguments.stiffness, "given"
        elif None not in (arguments.youngs_modulus, arguments.area, arguments.length):
            stiffness = arguments.youngs_modulus * arguments.area / arguments.length
            how = f"E A / L = {arguments.youngs_modulus:g} x {arguments.area:g} / {arguments.length:g}"
        else:
            fail("--body needs --stiffness, or --youngs-modulus, --area and --length")
        before = bodies["time"] <= force.peak_time
        speed = np.sqrt(sum(bodies[f"{arguments.body}_v{a}"] ** 2 for a in "xyz" if f"{arguments.body}_v{a}" in bodies))
        u = float(speed[before].max()) if before.any() else float(speed.max())
        impact = arguments.impact_coefficient * u * math.sqrt(stiffness * mass)
        rows.append(("debris mass m", mass, "kg/m" if two_d else "kg", "bodies.csv '# mass' line"))
        rows.append(("debris speed u", u, "m/s", f"largest before the filtered peak ({force.peak_time:.4g} s)"))
        rows.append(("impact stiffness k", stiffness, "N/m/m" if two_d else "N/m", how))
        rows.append(("FEMA-style debris impact F_i", impact, unit,
                     f"{arguments.impact_coefficient:g} u sqrt(k m)"))

    width = max(len(r[0]) for r in rows)
    print(f"design check of {arguments.structure} in {arguments.folder}:")
    for quantity, value, unit_text, how in rows:
        print(f"  {quantity:<{width}}  {value:12.6g} {unit_text:<8}  {how}")
    if arguments.out:
        with open(arguments.out, "w", encoding="utf-8") as out:
            out.write("quantity,value,unit,how\n")
            out.write(f"# design_check.py on {arguments.folder}, structure {arguments.structure} (docs/loads.md)\n")
            for quantity, value, unit_text, how in rows:
                out.write(f"\"{quantity}\",{value!r},{unit_text},\"{how}\"\n")
        print(arguments.out)


if __name__ == "__main__":
    main()
