#!/usr/bin/python3
"""Bit-for-bit comparison of two flotsam builds on every scene (a refactoring must not change a result).

usage: scripts/regression_snapshot.py run <flotsam> <folder> [--ranks 1,2] [--steps 400] [--steps-3d 120]
                                          [--scenes GLOB ...]
       scripts/regression_snapshot.py compare <folder A> <folder B>

`run` runs every scene of inputs/ (with inputs/validation/) and tests/runs/scenes/ with the executable
<flotsam> on each rank count, stopped after --steps steps (3-D scenes: --steps-3d; `&run max_steps`), with
the scene's own output times (and the final state a max_steps stop writes). Each run goes to
<folder>/<scene path without .nml>/np<ranks>/, its console to console.txt there, its exit status to
exit_status.txt (a scene that is meant to fail, as tests/runs/scenes/blow_up.nml, fails alike in both).

`compare` holds every run of A against the run of the same name in B and prints one line per difference:
  - the exit status;
  - every CSV (timing.csv, communication.csv and run_summary.csv excepted: wall times and memory), as text without its
    `#` comment lines (they name the commit and the date);
  - every dataset of every HDF5 file of fields/ and of the checkpoints (h5py, exact: the same shape, type and
    bytes; attributes, which carry the provenance, are not compared);
  - scene.nml without comments and its output_dir.
Exit status 0 when everything is identical, 1 otherwise. This is issue 51's acceptance check: the
boundary-constraint refactoring is bit-identical on 1 and 2 ranks.
"""

import argparse
import fnmatch
import glob
import os
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SKIPPED_CSV = {"timing.csv", "communication.csv", "run_summary.csv"}


def scenes(patterns):
    found = sorted(glob.glob(os.path.join(ROOT, "inputs", "*.nml")) +
                   glob.glob(os.path.join(ROOT, "inputs", "validation", "*.nml")) +
                   glob.glob(os.path.join(ROOT, "tests", "runs", "scenes", "**", "*.nml"), recursive=True))
    found = [os.path.relpath(f, ROOT) for f in found]
    if patterns:
        found = [f for f in found if any(fnmatch.fnmatch(f, p) for p in patterns)]
    return found


def is_3d(scene):
    with open(os.path.join(ROOT, scene)) as text:
        for line in text:
            code = line.split("!")[0].replace(" ", "").lower()
            if code.startswith("dim=3") or ",dim=3" in code:
                return True
    return False


def run(args):
    flotsam = os.path.abspath(args.flotsam)
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    for scene in scenes(args.scenes):
        steps = args.steps_3d if is_3d(scene) else args.steps
        for ranks in [int(r) for r in args.ranks.split(",")]:
            out = os.path.abspath(os.path.join(args.folder, scene[:-4], f"np{ranks}"))
            os.makedirs(os.path.dirname(out), exist_ok=True)
            command = ["mpirun", "--oversubscribe", "-np", str(ranks), flotsam, scene, "--overwrite",
                       "--set", f"&run max_steps = {steps}, output_dir = '{out}' /"]
            done = subprocess.run(command, cwd=ROOT, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                                  text=True)
            os.makedirs(out, exist_ok=True)
            with open(os.path.join(out, "console.txt"), "w") as console:
                console.write(done.stdout)
            with open(os.path.join(out, "exit_status.txt"), "w") as status:
                status.write(f"{done.returncode}\n")
            print(f"{scene} np{ranks}: exit {done.returncode}", flush=True)


def csv_body(path):
    with open(path) as text:
        return [line for line in text if not line.startswith("#")]


def scene_body(path):
    with open(path) as text:
        lines = [line.split("!")[0].rstrip() for line in text]
        return [line for line in lines if line.strip() and not line.strip().startswith("output_dir")]


def compare_h5(a, b):
    import h5py
    import numpy as np
    differences = []
    with h5py.File(a, "r") as fa, h5py.File(b, "r") as fb:
        names_a, names_b = [], []
        fa.visit(lambda n: names_a.append(n) if isinstance(fa[n], h5py.Dataset) else None)
        fb.visit(lambda n: names_b.append(n) if isinstance(fb[n], h5py.Dataset) else None)
        for name in sorted(set(names_a) ^ set(names_b)):
            differences.append(f"dataset {name} in one file only")
        for name in sorted(set(names_a) & set(names_b)):
            x, y = fa[name][()], fb[name][()]
            x, y = np.asarray(x), np.asarray(y)
            if x.shape != y.shape or x.dtype != y.dtype or x.tobytes() != y.tobytes():
                differences.append(f"dataset {name} differs")
    return differences


def compare(args):
    differences = 0
    runs = 0
    for status in sorted(glob.glob(os.path.join(args.a, "**", "exit_status.txt"), recursive=True)):
        run_a = os.path.dirname(status)
        name = os.path.relpath(run_a, args.a)
        run_b = os.path.join(args.b, name)
        runs += 1
        if not os.path.isdir(run_b):
            print(f"{name}: not in {args.b}")
            differences += 1
            continue
        found = []
        files_a = {os.path.relpath(f, run_a) for f in glob.glob(os.path.join(run_a, "**", "*"), recursive=True)
                   if os.path.isfile(f)}
        files_b = {os.path.relpath(f, run_b) for f in glob.glob(os.path.join(run_b, "**", "*"), recursive=True)
                   if os.path.isfile(f)}
        for f in sorted(files_a ^ files_b):
            if f.endswith(".tmp") or os.path.basename(f) in SKIPPED_CSV or f.startswith("console"):
                continue
            found.append(f"{f} in one run only")
        for f in sorted(files_a & files_b):
            pa, pb = os.path.join(run_a, f), os.path.join(run_b, f)
            base = os.path.basename(f)
            if base == "exit_status.txt":
                if open(pa).read() != open(pb).read():
                    found.append("exit status differs")
            elif base.endswith(".csv") and base not in SKIPPED_CSV:
                if csv_body(pa) != csv_body(pb):
                    found.append(f"{f} differs")
            elif base == "scene.nml":
                if scene_body(pa) != scene_body(pb):
                    found.append(f"{f} differs")
            elif base.endswith(".h5"):
                found += [f"{f}: {d}" for d in compare_h5(pa, pb)]
        for line in found:
            print(f"{name}: {line}")
        differences += len(found)
    print(f"{runs} runs compared, {differences} differences")
    return 0 if differences == 0 and runs > 0 else 1


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = parser.add_subparsers(dest="command", required=True)
    r = sub.add_parser("run")
    r.add_argument("flotsam")
    r.add_argument("folder")
    r.add_argument("--ranks", default="1,2")
    r.add_argument("--steps", type=int, default=400)
    r.add_argument("--steps-3d", type=int, default=120)
    r.add_argument("--scenes", nargs="*", default=[])
    c = sub.add_parser("compare")
    c.add_argument("a")
    c.add_argument("b")
    args = parser.parse_args()
    if args.command == "run":
        run(args)
        return 0
    return compare(args)


if __name__ == "__main__":
    sys.exit(main())
