#!/usr/bin/env python3
"""The FLIP/PIC blend as a rate (issue 53, item 2; docs/theory.md, "The FLIP/PIC blend as a rate"): the
3-D dam break of tests/runs/scenes/blend/dam_break_3d.nml at CFL 0.25, 0.5 and 1.0 on 2 ranks.

  1. the kinetic energy at 0.2 s (diagnostics.csv) and the front's advance (the farthest particle's x
     less the column's 1 m, from the last fields file) of the three runs within 1 % and 3 % of each
     other's median (issue 53 asks 3 % of both; measured 0.35 % and 1.3 % with the PIC share linear in the
     step, 1.5 % and 2.0 % with alpha**a, 41 % and 24 % with the blend per step: the scene says them);
  2. the step count halves with each doubling of the CFL number (the runs are what they say);
  3. a restart at CFL 1.0 (its step of 2 reference steps is in the checkpoint) gives diagnostics.csv byte for
     byte the uninterrupted run's;
  4. NB's stress projection acts at one rate too: the paper's tank at rest (inputs/hydrostatic_tank.nml,
     NB, pure FLIP, CFL 0.05, 0.4 s) keeps its kinetic energy below 1 J (with the whole projection in
     every step it reached 14.8 J; 0.045 J with the share).
"""
import glob
import os

import h5py
import numpy as np
import pandas as pd

from flotsam_run import Checks, Flotsam, main_arguments

COLUMN = 1.0        # the column's length [m]: the front starts there
TOLERANCE = {"energy": 0.01, "advance": 0.03}


def measure(folder):
    diagnostics = pd.read_csv(os.path.join(folder, "diagnostics.csv"), comment="#")
    last = sorted(glob.glob(os.path.join(folder, "fields", "fields_*.h5")))[-1]
    with h5py.File(last) as f:
        front = float(f["particles/position"][:, 0].max())
    return {"time": float(diagnostics["time"].iloc[-1]), "steps": int(diagnostics["step"].iloc[-1]),
            "energy": float(diagnostics["kinetic_energy"].iloc[-1]), "advance": front - COLUMN}


def rows(path):
    with open(path) as f:
        return [line for line in f.read().splitlines() if not line.startswith("#")]


def main():
    flotsam_path, mpiexec, scenes, _ = main_arguments()
    checks = Checks()
    flotsam = Flotsam(flotsam_path, mpiexec, "blend")
    template = os.path.join(scenes, "blend", "dam_break_3d.nml")
    found = {}
    for cfl in ("0.25", "0.5", "1.0"):
        name = f"cfl_{cfl}"
        flotsam.remove(name)
        result = flotsam.run(flotsam.scene(template, name + ".nml", name, cfl=cfl), 2)
        if checks.check(result.returncode == 0, f"CFL {cfl}: run", result.stderr[-1500:]):
            found[cfl] = measure(flotsam.path(name))
            print(f"CFL {cfl}: {found[cfl]}")
    if len(found) == 3:
        checks.check(all(abs(m["time"] - 0.2) < 1e-12 for m in found.values()), "every run reached 0.2 s")
        steps = [found[c]["steps"] for c in ("0.25", "0.5", "1.0")]
        checks.check(all(abs(steps[i] / steps[i + 1] - 2) < 0.05 for i in range(2)),
                     f"the steps halve with each doubling of the CFL number ({', '.join(map(str, steps))})")
        for key, what in (("energy", "kinetic energy at 0.2 s [J]"), ("advance", "front's advance at 0.2 s [m]")):
            values = [found[c][key] for c in ("0.25", "0.5", "1.0")]
            spread = (max(values) - min(values)) / np.median(values)
            checks.check(spread <= TOLERANCE[key], f"{what} at CFL 0.25, 0.5, 1.0: {', '.join(f'{v:.4g}' for v in values)}, "
                         f"within {spread:.1%} of the median (tolerance {TOLERANCE[key]:.0%})")
    # a restart where the step is not one reference step: stopped at step 150, continued from its step-100 checkpoint
    whole = flotsam.path("cfl_1.0", "diagnostics.csv")
    name = "cfl_1.0_split"
    flotsam.remove(name)
    path = flotsam.scene(template, name + ".nml", name, cfl="1.0", checkpoint_interval_steps=100, max_steps=150)
    result = flotsam.run(path, 2)
    if checks.check(result.returncode == 0 and os.path.exists(whole), "restart: stopped at step 150",
                    result.stderr[-1500:]):
        checkpoint = None
        for candidate in glob.glob(flotsam.path(name, "checkpoints", "checkpoint_*.h5")):
            with h5py.File(candidate) as f:
                if int(f.attrs["step"]) == 100:
                    checkpoint = os.path.relpath(candidate, flotsam.workdir)
                    steps = float(f.attrs["reference_steps"])
                    checks.check(steps > 1.9, f"restart: the checkpoint holds the step in reference steps ({steps:.4f})")
        if checks.check(checkpoint is not None, "restart: a checkpoint at step 100"):
            path = flotsam.scene(template, name + "_continue.nml", name, cfl="1.0")
            result = flotsam.run(path, 2, "--restart", checkpoint)
            checks.check(result.returncode == 0, "restart: continued from step 100", result.stderr[-1500:])
            expected, got = rows(whole), rows(flotsam.path(name, "diagnostics.csv"))
            checks.check(got == expected, f"restart: diagnostics.csv byte for byte the uninterrupted run's "
                         f"({len(expected)} rows)", f"{len(got)} rows")
    check_nb_at_small_steps(checks, flotsam, scenes)
    return checks.summary()


def check_nb_at_small_steps(checks, flotsam, scenes):
    tank = os.path.join(os.path.dirname(os.path.dirname(os.path.dirname(scenes))), "inputs", "hydrostatic_tank.nml")
    name = "tank_nb_cfl_0.05"
    flotsam.remove(name)
    path = flotsam.scene(tank, name + ".nml", name, cfl="0.05", flip_fraction="1.0", end_time="0.4",
                         output_interval="0.1", particle_output=".false.", grid_output=".false.")
    result = flotsam.run(path, 2, "--set", "&material name = 'water', stabilization = 'NB' /")
    if checks.check(result.returncode == 0, "NB tank at rest, CFL 0.05: run", result.stderr[-1500:]):
        energy = pd.read_csv(flotsam.path(name, "diagnostics.csv"), comment="#")["kinetic_energy"].max()
        checks.check(energy < 1.0, f"NB tank at rest, pure FLIP, CFL 0.05, 0.4 s: largest kinetic energy {energy:.3g} J "
                     "(below 1 J; the whole projection in every step: 14.8 J)")


if __name__ == "__main__":
    raise SystemExit(main())
