"""Helpers of the whole-run tests (tests/runs/): run the flotsam program under mpiexec, find its rank
processes, read its diagnostics, and count checks (each test prints `N passed, N failed` last)."""

import csv
import os
import re
import shutil
import signal
import subprocess
import sys
import time

MPI_ENVIRONMENT = {
    "OMPI_ALLOW_RUN_AS_ROOT": "1",
    "OMPI_ALLOW_RUN_AS_ROOT_CONFIRM": "1",
    "OMPI_MCA_rmaps_base_oversubscribe": "1",
    # Open MPI 4.1's OMPIO can drop ranks' parts of a collective HDF5 write (docs/output.md)
    "OMPI_MCA_io": "romio321",
}



class Checks:
    """Counts checks; `summary()` prints the `N passed, N failed` line and returns the exit status."""

    def __init__(self):
        self.passed = 0
        self.failed = 0

    def check(self, condition, name, detail=""):
        if condition:
            self.passed += 1
            print(f"PASS {name}", flush=True)
        else:
            self.failed += 1
            print(f"FAIL {name}" + (f": {detail}" if detail else ""), flush=True)
        return condition

    def close(self, actual, expected, rel, name):
        """|actual - expected| <= rel * |expected| (exact when expected is 0)."""
        ok = abs(actual - expected) <= rel * abs(expected)
        return self.check(ok, name, f"expected {expected!r}, got {actual!r} (relative tolerance {rel})")

    def summary(self):
        print(f"{self.passed} passed, {self.failed} failed", flush=True)
        return 0 if self.failed == 0 else 1


class Flotsam:
    """Runs `mpiexec -np N flotsam scene [arguments]` in a working directory."""

    def __init__(self, flotsam, mpiexec, workdir):
        self.flotsam = os.path.abspath(flotsam)
        self.mpiexec = mpiexec
        self.workdir = os.path.abspath(workdir)
        os.makedirs(self.workdir, exist_ok=True)
        self.environment = dict(os.environ, **MPI_ENVIRONMENT)

    def scene(self, template, name, output_dir, **run_values):
        """Write scene `name` into the working directory: `template` with output_dir replaced and the
        given &run variables added (values as Fortran text)."""
        with open(template) as f:
            text = f.read()
        text = re.sub(r"output_dir\s*=\s*'[^']*'", f"output_dir = '{output_dir}'", text)
        # at the end of &run, so that they override the template's values
        start = text.index("&run")
        end = text.index("\n/", start)
        extra = "".join(f"\n   {key} = {value}" for key, value in run_values.items())
        text = text[:end] + extra + text[end:]
        path = os.path.join(self.workdir, name)
        with open(path, "w") as f:
            f.write(text)
        return path

    def command(self, scene, ranks, *arguments):
        return [self.mpiexec, "-np", str(ranks), self.flotsam, scene, *arguments]

    def run(self, scene, ranks, *arguments, timeout=600):
        """Run to completion; returns the CompletedProcess (returncode, stdout, stderr)."""
        return subprocess.run(self.command(scene, ranks, *arguments), cwd=self.workdir, env=self.environment,
                              capture_output=True, text=True, timeout=timeout)

    def start(self, scene, ranks, *arguments):
        """Start a run in the background."""
        return subprocess.Popen(self.command(scene, ranks, *arguments), cwd=self.workdir, env=self.environment,
                                stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)

    def path(self, *parts):
        return os.path.join(self.workdir, *parts)

    def remove(self, *parts):
        shutil.rmtree(self.path(*parts), ignore_errors=True)


def child_pids(pid):
    """The processes whose parent is `pid` (the ranks of a local mpirun), from /proc."""
    children = []
    for entry in os.listdir("/proc"):
        if not entry.isdigit():
            continue
        try:
            with open(f"/proc/{entry}/stat") as f:
                fields = f.read().rsplit(")", 1)[1].split()
        except OSError:
            continue
        if int(fields[1]) == pid:
            children.append(int(entry))
    return children


def wait_for_file(path, process, timeout=120):
    """Wait until `path` exists while `process` runs; False if it ended first or time ran out."""
    start = time.time()
    while time.time() - start < timeout:
        if os.path.exists(path):
            return True
        if process.poll() is not None:
            return False
        time.sleep(0.02)
    return False


def rank_pids(pid):
    """The ranks started by the launcher `pid`: its descendants that have no children of their own
    (Open MPI's mpirun starts local ranks itself; MPICH's mpiexec through hydra_pmi_proxy)."""
    ranks, todo = [], [pid]
    while todo:
        children = child_pids(todo.pop())
        for child in children:
            (todo if child_pids(child) else ranks).append(child)
    return ranks


def signal_ranks(process, signum):
    """Send `signum` to every rank of the mpirun `process` (what a batch system does to a job step)."""
    pids = rank_pids(process.pid)
    for pid in pids:
        try:
            os.kill(pid, signum)
        except ProcessLookupError:
            pass
    return pids


def read_diagnostics(output_dir):
    """The rows of diagnostics.csv as dictionaries of strings (exact text, for bitwise comparisons)."""
    with open(os.path.join(output_dir, "diagnostics.csv")) as f:
        return list(csv.DictReader(f))


def main_arguments():
    if len(sys.argv) < 4:
        sys.exit(f"usage: {sys.argv[0]} <flotsam> <mpiexec> <scene folder> [...]")
    return sys.argv[1], sys.argv[2], os.path.abspath(sys.argv[3]), sys.argv[4:]


__all__ = ["Checks", "Flotsam", "child_pids", "rank_pids", "wait_for_file", "signal_ranks", "read_diagnostics", "signal",
           "main_arguments"]
