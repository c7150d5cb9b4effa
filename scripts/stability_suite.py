#!/usr/bin/python3
"""Numerical stability at the extremes: every scheme through the parameter ranges of the batch-study
issue, one parameter at a time around the paper's hydrostatic tank (8 cells per 3.2 m, 3x3 particles
per cell, grid turned by 45 degrees, 1 s), plus a block of another density in the floating-block scene.

    scripts/stability_suite.py [--quick] [--contact-only] [--parameter LABEL] [--flotsam PATH] [--ranks N] [--out DIR]

Every case must end in one of two acceptable ways:
  bounded    it reached its end time with the kinetic energy below the tank's potential energy
             (rho g H^2 W / 2: nothing in a tank at rest can gain more), no particle behind a wall,
             no particle lost and the mass kept;
  detected   it stopped with exit status 4 and the blow-up report (the check runs after every step,
             so the report comes in the step the state first goes bad);
anything else (another exit status, a hang past the time limit, a finished run with unbounded energy or
particles outside the walls) is a failure.
Contact at the extremes (once, not per scheme: no fluid): two elastic disks with &contact, one moving
into the other off-centre in a box of slip walls, with the Young's modulus, the speed and the friction
coefficient taken one at a time to their extremes. Bounded there means: the kinetic energy never above
its initial value (walls and contact cannot add energy), no particle lost or behind a wall, the mass
kept, and the disks' particles never closer than a quarter of the particle spacing (no interpenetration). Prints one line per case, writes <out>/stability.csv and
<out>/stability.md (the table of docs/stability.md) and exits 1 if a case failed.
--quick runs the subset of the default test suite (a few seconds per case); --parameter runs only the tank
and block rows whose parameter label starts with LABEL (e.g. 'CFL'), no contact cases, to re-measure one
row of the table after a change.
"""

import argparse
import csv
import glob
import os
import subprocess
import sys
import time

import h5py
import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
TANK = os.path.join(ROOT, "inputs", "hydrostatic_tank.nml")
BLOCK = os.path.join(ROOT, "inputs", "floating_block.nml")
# a scheme, or scheme+volume_correction (docs/volume-conservation.md)
SCHEMES = ["none", "C0", "FOAL1", "NB", "FOAL1+shifting", "FOAL1+shifting+eos_relaxation"]
RHO, G, H, W = 1000.0, 10.0, 3.2, 3.2
TIME_LIMIT = 1800      # seconds of wall time per case: beyond it the case counts as a hang


def tank_cases(quick):
    """(label, parameter, value, overrides) around the 45 degree tank."""
    end = "0.2" if quick else "1.0"
    base = [f"&run end_time = {end}, output_interval = {end} /", "&grid rotation = 45.0 /"]
    ranges = {
        "bulk modulus [Pa]": ("material:water bulk_modulus", [2.0e7, 2.2e9, 2.2e10] if not quick else [2.0e7, 2.2e10]),
        "grid rotation [deg]": ("grid rotation", [0.0, 22.5, 45.0] if not quick else [22.5]),
        "CFL": ("run cfl", [0.05, 0.25, 0.5, 0.95] if not quick else [0.95]),
        "particles per cell": ("body particles_per_cell", [1, 2, 4, 6] if not quick else [1]),
        "cell size [m]": ("grid cell_size", [0.8, 0.2, 0.1, 0.05] if not quick else [0.8]),
        "FLIP fraction": ("run flip_fraction", [1.0] if not quick else []),
        "viscosity [Pa s]": ("material:water viscosity", [0.0, 1.0, 1.0e3] if not quick else [1.0e3]),
    }
    cases = []
    for label, (key, values) in ranges.items():
        for value in values:
            group_key, variable = key.split()
            group, _, selected = group_key.partition(":")
            head = f"&{group}" + (f" name = '{selected}'," if selected else "")
            overrides = base + [f"{head} {variable} = {value!r} /"]
            if variable == "cell_size" and value <= 0.1:
                overrides[0] = "&run end_time = 0.1, output_interval = 0.1 /"     # 32 and 64 cpl: 0.1 s
            if variable == "flip_fraction":
                overrides[0] = "&run end_time = 3.0, output_interval = 3.0 /"     # the paper's 3 s
            cases.append((label, value, TANK, overrides))
    if not quick:      # a long run: 1e5 steps and more (10 s of the 45 degree tank)
        cases.append(("long run [s]", 10.0, TANK, ["&run end_time = 10.0, output_interval = 1.0 /",
                                                     "&grid rotation = 45.0 /"]))
    return cases


def block_cases(quick):
    """The floating-block scene, 2 s, with the block lighter and heavier than the water."""
    ratios = [0.1, 0.3, 1.0, 3.0, 10.0] if not quick else [10.0]
    end = "0.5" if quick else "2.0"
    return [("block / fluid density", ratio, BLOCK,
             [f"&run end_time = {end}, output_interval = {end} /",
              f"&material name = 'block', density = {1000.0 * ratio!r} /"]) for ratio in ratios]


# Two disks (R = 0.2 m, h = 0.04 m, 2 x 2 particles per cell, rho = 1000, nu = 0.3) 0.1 m apart, the
# right one 0.1 m higher so that the impact is oblique and friction acts; the left one moves at v. Two
# materials alike, so that an override can select the left body (&body material = 'rubber_a').
DISKS = """&run end_time = 0.4, output_interval = 0.02, load_interval = 0.0, output_dir = 'disks' /
&grid dim = 2, cell_size = 0.04, extent = 2.0, 1.0 /
&box_walls x_min = 'slip', x_max = 'slip', y_min = 'slip', y_max = 'slip' /
&material name = 'rubber_a', model = 'linear_elastic', density = 1000.0, youngs_modulus = 1.0e6, poisson_ratio = 0.3 /
&material name = 'rubber_b', model = 'linear_elastic', density = 1000.0, youngs_modulus = 1.0e6, poisson_ratio = 0.3 /
&body name = 'left', material = 'rubber_a', shape = 'circle', centre = 0.75, 0.45, radius = 0.2, velocity = 1.0, 0.0 /
&body name = 'right', material = 'rubber_b', shape = 'circle', centre = 1.25, 0.55, radius = 0.2 /
&contact between = 'rubber_a', 'rubber_b', friction = 0.3 /
"""
DISK_SPACING = 0.02    # cell size / particles per cell


def contact_cases(quick):
    """(label, value, overrides) around the disks: E 1e6 Pa, v 1 m/s, mu 0.3."""
    ranges = {
        # E = 1e8 Pa and v = 0.1 m/s once gained kinetic energy through the contact (docs/contact.md): in
        # the quick subset as well; v = 50 m/s interpenetrates (docs/stability.md): the whole suite only
        "Young's modulus [Pa]": ("material youngs_modulus", [1.0e4, 1.0e8, 1.0e9] if not quick else [1.0e8]),
        "speed [m/s]": ("body:rubber_a velocity", [0.1, 10.0, 50.0] if not quick else [0.1, 10.0]),
        "friction": ("contact friction", [0.0, 1.0, 10.0] if not quick else [0.0, 10.0]),
    }
    cases = []
    for label, (key, values) in ranges.items():
        for value in values:
            group_key, variable = key.split()
            group, _, selected = group_key.partition(":")
            selector = "material" if group == "body" else "name"
            head = f"&{group}" + (f" {selector} = '{selected}'," if selected else "")
            text = f"{value!r}, 0.0" if variable == "velocity" else repr(value)
            overrides = [f"{head} {variable} = {text} /"]
            # past the impact (0.1 m / v) and the disks' parting; a stiff disk's step is short
            end = 0.1 / (value if variable == "velocity" else 1.0) + (0.15 if value == 1.0e9 else 0.3)
            overrides.append(f"&run end_time = {end!r}, output_interval = {end / 20!r} /")
            cases.append((label, value, overrides))
    return cases


def judge_disks(folder, code, stderr):
    """(outcome, verdict ok?, detail) of a two-disk case."""
    if code is None or code != 0:
        return judge(folder, code, stderr, None)
    with open(os.path.join(folder, "diagnostics.csv")) as f:
        rows = list(csv.DictReader(line for line in f if not line.startswith("#")))
    energy = [float(r["kinetic_energy"]) for r in rows]
    problems = []
    if max(energy) > energy[0] * (1 + 1e-9):
        problems.append(f"kinetic energy {max(energy):.4g} J above the initial {energy[0]:.4g} J")
    if int(rows[-1]["lost_particles"]) > 0:
        problems.append(f"{rows[-1]['lost_particles']} particles lost")
    if abs(float(rows[-1]["total_mass"]) / float(rows[0]["total_mass"]) - 1) > 1e-12:
        problems.append("mass not kept")
    closest, deepest, left_ids = np.inf, np.inf, None
    for path in sorted(glob.glob(os.path.join(folder, "fields", "fields_*.h5"))):
        with h5py.File(path) as f:
            x, ids = f["particles/position"][:, :2], f["particles/id"][:]
        if left_ids is None:
            left_ids = set(ids[x[:, 0] < 1.0].tolist())
        left = np.isin(ids, list(left_ids))
        gaps = np.linalg.norm(x[left][:, None, :] - x[~left][None, :, :], axis=2)
        closest = min(closest, gaps.min())
        deepest = min(deepest, x[:, 0].min(), x[:, 1].min(), (2.0 - x[:, 0]).min(), (1.0 - x[:, 1]).min())
    if closest < DISK_SPACING / 4:
        problems.append(f"disks' particles {closest * 1000:.1f} mm apart (interpenetration)")
    if deepest < -1e-9:
        problems.append(f"a particle {-deepest:.3g} m behind a wall")
    detail = (f"KE end/start {energy[-1] / energy[0]:.3f}, closest particles {closest * 1000:.1f} mm, "
              f"{rows[-1]['step']} steps")
    if problems:
        return "unbounded", False, "; ".join(problems)
    return "bounded", True, detail


def run(flotsam, ranks, scene, overrides, folder):
    command = [os.environ.get("FLOTSAM_MPIEXEC") or "mpirun", "-np", str(ranks), flotsam, scene]
    for text in overrides + [f"&run output_dir = '{folder}', overwrite = .true., progress_interval = 0.0, "
                             "checkpoint_interval_wall = 0.0 /"]:
        command += ["--set", text]
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
               OMPI_MCA_rmaps_base_oversubscribe="1")
    start = time.time()
    try:
        result = subprocess.run(command, env=env, capture_output=True, text=True, timeout=TIME_LIMIT)
        return result.returncode, result.stderr, time.time() - start
    except subprocess.TimeoutExpired:
        return None, "", time.time() - start


def judge(folder, code, stderr, scene):
    """(outcome, verdict ok?, detail)."""
    if code is None:
        return "hang", False, f"no end within {TIME_LIMIT} s"
    if code == 4 and "blew up" in stderr:
        line = [l for l in stderr.splitlines() if "blew up" in l][0]
        return "detected", True, line.split("error: ")[-1][:160]
    if code != 0:
        return f"exit {code}", False, stderr.strip().splitlines()[-1][:200] if stderr.strip() else ""
    with open(os.path.join(folder, "diagnostics.csv")) as f:
        rows = list(csv.DictReader(line for line in f if not line.startswith("#")))
    energy = max(float(r["kinetic_energy"]) for r in rows)
    bound = RHO * G * H * H * W / 2
    problems = []
    if energy > bound:
        problems.append(f"kinetic energy {energy:.3g} J above {bound:.3g} J")
    if int(rows[-1]["lost_particles"]) > 0:
        problems.append(f"{rows[-1]['lost_particles']} particles lost")
    if scene == TANK and abs(float(rows[-1]["total_mass"]) / float(rows[0]["total_mass"]) - 1) > 1e-12:
        problems.append("mass not kept")
    last = sorted(glob.glob(os.path.join(folder, "fields", "fields_*.h5")))[-1]
    with h5py.File(last) as f:
        x = f["particles/position"][:]
    right = W if scene == TANK else 3.0
    deepest = min(x[:, 1].min(), x[:, 0].min(), (right - x[:, 0]).min())
    if deepest < -1e-9:
        problems.append(f"a particle {-deepest:.3g} m behind a wall")
    detail = f"max KE {energy:.3g} J, {rows[-1]['step']} steps, {rows[-1]['wall_corrections']} wall corrections"
    if problems:
        return "unbounded", False, "; ".join(problems)
    return "bounded", True, detail


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--quick", action="store_true")
    parser.add_argument("--flotsam", default=os.path.join(ROOT, "build", "release", "flotsam"))
    parser.add_argument("--ranks", type=int, default=2)
    parser.add_argument("--out", default=os.path.join("output", "stability"))
    parser.add_argument("--schemes", default=",".join(SCHEMES),
                        help="comma-separated subset of " + ", ".join(SCHEMES))
    parser.add_argument("--contact-only", action="store_true", help="only the two-disk contact cases")
    parser.add_argument("--parameter", help="only the rows whose parameter label starts with this (no contact)")
    args = parser.parse_args()
    schemes = [] if args.contact_only else args.schemes.split(",")
    unknown = [s for s in schemes if s not in SCHEMES]
    if unknown:
        parser.error("unknown scheme(s): " + ", ".join(unknown))
    if not args.quick and args.flotsam == os.path.join(ROOT, "build", "release", "flotsam"):
        subprocess.run([os.path.join(ROOT, "scripts", "flotsam"), "build", "release"], check=True,
                       stdout=subprocess.DEVNULL)
    out = os.path.abspath(args.out)
    os.makedirs(out, exist_ok=True)
    rows, failures = [], 0
    cases = [] if args.contact_only else tank_cases(args.quick) + block_cases(args.quick)
    if args.parameter:
        cases = [case for case in cases if case[0].startswith(args.parameter)]
        if not cases:
            parser.error(f"no parameter label starts with {args.parameter!r}")
    for scheme in schemes:
        stabilization, _, correction = scheme.partition("+")
        material = f"&material name = 'water', stabilization = '{stabilization}'" + \
            (f", volume_correction = '{correction}'" if correction else "") + " /"
        for label, value, scene, overrides in cases:
            folder = os.path.join(out, "cases", f"{scheme}_{label.split()[0]}_{value}".replace(" ", "_")
                                  .replace("/", "").replace("+", "_"))
            code, stderr, seconds = run(args.flotsam, args.ranks, scene, overrides + [material], folder)
            outcome, ok, detail = judge(folder, code, stderr, scene)
            failures += not ok
            rows.append({"scheme": scheme, "parameter": label, "value": value, "outcome": outcome,
                         "acceptable": ok, "wall_seconds": round(seconds, 1), "detail": detail})
            print(f"{'ok  ' if ok else 'FAIL'} {scheme:6s} {label:24s} {value!s:>10s}: {outcome:9s} "
                  f"({seconds:.0f} s) {detail}", flush=True)
    contact_rows = []
    disks = os.path.join(out, "two_disks.nml")
    with open(disks, "w") as f:
        f.write(DISKS)
    for label, value, overrides in ([] if args.parameter else contact_cases(args.quick)):
        folder = os.path.join(out, "cases", f"contact_{label.split()[0]}_{value}".replace("'", ""))
        code, stderr, seconds = run(args.flotsam, args.ranks, disks, overrides, folder)
        outcome, ok, detail = judge_disks(folder, code, stderr)
        failures += not ok
        contact_rows.append({"scheme": "contact", "parameter": label, "value": value, "outcome": outcome,
                             "acceptable": ok, "wall_seconds": round(seconds, 1), "detail": detail})
        print(f"{'ok  ' if ok else 'FAIL'} contact {label:24s} {value!s:>10s}: {outcome:9s} "
              f"({seconds:.0f} s) {detail}", flush=True)
    rows += contact_rows
    with open(os.path.join(out, "stability.csv"), "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)
    with open(os.path.join(out, "stability.md"), "w") as f:
        f.write("| parameter | value | " + " | ".join(schemes) + " |\n|---|---|" + "---|" * len(schemes) + "\n")
        for label, value, _scene, _overrides in cases:
            cells = [next(r for r in rows if r["scheme"] == s and r["parameter"] == label and r["value"] == value)
                     for s in schemes]
            f.write(f"| {label} | {value} | " + " | ".join(c["outcome"] + ("" if c["acceptable"] else " **FAIL**")
                                                         for c in cells) + " |\n")
        f.write("\n| contact (two disks) | value | outcome | detail | wall s |\n|---|---|---|---|---|\n")
        for r in contact_rows:
            f.write(f"| {r['parameter']} | {r['value']} | {r['outcome']}{'' if r['acceptable'] else ' **FAIL**'} | "
                    f"{r['detail']} | {r['wall_seconds']} |\n")
    print(f"{len(rows) - failures} acceptable, {failures} failed")
    sys.exit(1 if failures else 0)


if __name__ == "__main__":
    main()
