#!/usr/bin/python3
"""Command-line overrides of a scene (`flotsam scene.nml [override.nml ...] [--set '<namelist>' ...]`):
singleton groups change the variables they assign, repeated groups the entries they select, later
overrides win, and a bad override fails like a bad scene file: one message naming the override, the
group and the variable, exit status 2 on every rank, no output folder.

usage: check_overrides.py <flotsam> <mpiexec> <tests/runs/scenes> <scripts folder>"""

import os

from flotsam_run import Checks, Flotsam, main_arguments, read_diagnostics

RANKS = 2


def error_lines(result):
    return [line for line in result.stderr.splitlines() if line.startswith("flotsam: error")]


def main():
    flotsam_path, mpiexec, _scenes, rest = main_arguments()
    inputs = os.path.join(os.path.dirname(os.path.abspath(rest[0])), "inputs")
    tank = os.path.join(inputs, "hydrostatic_tank.nml")
    checks = Checks()
    flotsam = Flotsam(flotsam_path, mpiexec, "output")

    # the paper's 45 degree variant with C0 and 2 x 2 particles per cell, without a copy of the file
    flotsam.remove("variant")
    with open(flotsam.path("later.nml"), "w") as f:
        f.write("&material name = 'water', stabilization = 'NB' /\n&run max_steps = 3 /\n")
    result = flotsam.run(tank, RANKS, flotsam.path("later.nml"),
                         "--set", "&run end_time = 0.05, output_dir = 'variant', max_steps = 2 /",
                         "--set", "&grid rotation = 45.0 /",
                         "--set", "&material name = 'water', stabilization = 'C0' /",
                         "--set", "&body particles_per_cell = 2 /")
    if checks.check(result.returncode == 0, "variant runs", result.stderr[-1500:]):
        rows = read_diagnostics(flotsam.path("variant"))
        checks.check(int(rows[0]["particles"]) == 8 * 8 * 4, "&body override: 2 x 2 particles per cell (256)",
                     rows[0]["particles"])
        checks.check(int(rows[-1]["step"]) == 2, "--set after the override file wins (max_steps = 2)", rows[-1]["step"])
        with open(os.path.join(flotsam.path("variant"), "particles.xmf")) as f:
            checks.check("Time" in f.read(), "output written")
    # the rotation took effect: the positions are written in the world frame, so compare the grid
    # file's node positions (only a rotated grid has them)
    import h5py
    path = os.path.join(flotsam.path("variant"), "fields", "fields_000000.h5")
    if os.path.exists(path):
        with h5py.File(path) as f:
            checks.check("position" in f["grid/node"], "&grid override: the grid is rotated")

    bad = [
        (["--set", "&grid rotation = 400 /"],
         "hydrostatic_tank.nml with --set 1, --set 2: group &grid: variable rotation must be in [-360, 360], got 400"),
        (["--set", "&material name = 'oil', stabilization = 'C0' /"],
         "--set 1: group &material (1st): the scene has no &material with name = 'oil'"),
        (["--set", "&grid rotaton = 4 /"], "--set 1: line 1: group &grid: unknown variable rotaton"),
        (["--set", "&run end_time = 1.0 /", "--set", "&material name = 'water', density = -1.0 /"],
         "with --set 1, --set 2, --set 3: group &material (1st, name 'water'): variable density must be > 0, got -1"),
        (["missing_override.nml"], "missing_override.nml: override file not found"),
        (["--set"], "--set needs namelist text"),
        (["--set", "&wall point = 0.0, 0.0 /"], "--set 1: group &wall (1st): the scene has no &wall to change"),
    ]
    for arguments, expected in bad:
        flotsam.remove("refused")
        redirect = ["--set", "&run output_dir = 'refused' /"]     # applied last: the override numbers hold
        command = redirect + arguments if arguments == ["--set"] else arguments + redirect
        result = flotsam.run(tank, RANKS, *command)
        errors = error_lines(result)
        label = " ".join(arguments)
        checks.check(result.returncode == 2, f"{label}: exit status 2", str(result.returncode))
        checks.check(len(errors) == 1 and expected in errors[0], f"{label}: one clear message",
                     f"{errors} (expected ...{expected}...)")
        checks.check(not os.path.exists(flotsam.path("refused")), f"{label}: no output folder")
    raise SystemExit(checks.summary())


if __name__ == "__main__":
    main()
