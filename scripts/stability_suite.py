#!/usr/bin/python3
"""Numerical stability at the extremes: every scheme through the parameter ranges of the batch-study
issue, one parameter at a time around the paper's hydrostatic tank (8 cells per 3.2 m, 3x3 particles
per cell, grid turned by 45 degrees, 1 s), plus a block of another density in the floating-block scene.

    scripts/stability_suite.py [--quick] [--flotsam PATH] [--ranks N] [--out DIR]

Every case must end in one of two acceptable ways:
  bounded    it reached its end time with the kinetic energy below the tank's potential energy
             (rho g H^2 W / 2: nothing in a tank at rest can gain more), no particle behind a wall,
             no particle lost and the mass kept;
  detected   it stopped with exit status 4 and the blow-up report (the check runs after every step,
             so the report comes in the step the state first goes bad);
anything else (another exit status, a hang past the time limit, a finished run with unbounded energy or
particles outside the walls) is a failure. Prints one line per case, writes <out>/stability.csv and
<out>/stability.md (the table of docs/stability.md) and exits 1 if a case failed.
--quick runs the subset of the default test suite (a few seconds per case).
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
    args = parser.parse_args()
    schemes = args.schemes.split(",")
    unknown = [s for s in schemes if s not in SCHEMES]
    if unknown:
        parser.error("unknown scheme(s): " + ", ".join(unknown))
    if not args.quick and args.flotsam == os.path.join(ROOT, "build", "release", "flotsam"):
        subprocess.run([os.path.join(ROOT, "scripts", "flotsam"), "build", "release"], check=True,
                       stdout=subprocess.DEVNULL)
    out = os.path.abspath(args.out)
    os.makedirs(out, exist_ok=True)
    rows, failures = [], 0
    cases = tank_cases(args.quick) + block_cases(args.quick)
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
    print(f"{len(rows) - failures} acceptable, {failures} failed")
    sys.exit(1 if failures else 0)


if __name__ == "__main__":
    main()
