"""Helpers of the whole-run tests (tests/runs/): run the flotsam program under mpiexec, find its rank
processes, read its diagnostics, and count checks (each test prints `N passed, N failed` last)."""

import csv
import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import threading
import time

MPI_ENVIRONMENT = {
    "OMPI_ALLOW_RUN_AS_ROOT": "1",
    "OMPI_ALLOW_RUN_AS_ROOT_CONFIRM": "1",
    "OMPI_MCA_rmaps_base_oversubscribe": "1",
    # Open MPI 4.1's OMPIO can drop ranks' parts of a collective HDF5 write (docs/output.md)
    "OMPI_MCA_io": "romio321",
}


# A Debug build's report of an array copy (cmake/FlotsamTesting.cmake): a run's report is passed on to the
# test's own output, where CTest fails the test on it.
ARRAY_COPY_MESSAGE = "An array temporary was created"


def pass_on_array_copies(stderr):
    """Write the lines of a run's stderr (text) that report an array copy, and the line before each (where),
    to this test's stderr."""
    lines = (stderr or "").splitlines()
    for i, line in enumerate(lines):
        if ARRAY_COPY_MESSAGE in line:
            sys.stderr.write("flotsam run: " + (lines[i - 1] + " " if i > 0 else "") + line + "\n")


class DrainedPopen(subprocess.Popen):
    """subprocess.Popen whose stdout and stderr pipes are read by threads from the start. A test that waits
    for a file or for diagnostics rows while the run goes on reads none of its output meanwhile; with a
    plain pipe, a run that prints more than the pipe holds (64 kB on Linux: progress lines of a slow debug
    build on a loaded machine) blocks in its write, and the test waits for rows that never come.
    communicate() returns what was read, as Popen's does."""

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        self._read = {}
        self._readers = []
        for name in ("stdout", "stderr"):
            stream = getattr(self, name)
            if stream is None:
                continue
            chunks = self._read[name] = []
            # read() returns at the end of the stream: when the run and its children have closed it
            reader = threading.Thread(target=lambda stream=stream, chunks=chunks: chunks.append(stream.read()),
                                      daemon=True)
            reader.start()
            self._readers.append(reader)

    def communicate(self, input=None, timeout=None):
        if input is not None:
            raise ValueError("DrainedPopen takes no input")
        self.wait(timeout=timeout)
        for reader in self._readers:
            reader.join()
        for name in self._read:
            getattr(self, name).close()
        empty = "" if self.text_mode else b""
        output = tuple(empty.join(self._read[name]) if name in self._read else None for name in ("stdout", "stderr"))
        if self.text_mode:
            pass_on_array_copies(output[1])
        return output


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
        result = subprocess.run(self.command(scene, ranks, *arguments), cwd=self.workdir, env=self.environment,
                                capture_output=True, text=True, timeout=timeout)
        pass_on_array_copies(result.stderr)
        return result

    def start(self, scene, ranks, *arguments):
        """Start a run in the background."""
        return DrainedPopen(self.command(scene, ranks, *arguments), cwd=self.workdir, env=self.environment,
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


def wait_for_rows(path, process, rows=1, timeout=300):
    """Wait until diagnostics.csv `path` has `rows` rows after the initial one: the time loop runs, and
    flotsam's signal handlers are installed (after the initial output). False if the run ended first."""
    start = time.time()
    while time.time() - start < timeout and process.poll() is None:
        if os.path.exists(path):
            with open(path) as f:
                if sum(1 for line in f if line.strip() and not line.startswith("#")) >= rows + 2:
                    return True
        time.sleep(0.05)
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


def checkpoint_at_step(flotsam, output_dir, step):
    """The checkpoint of `output_dir` (in flotsam's working directory) written at `step`: its path
    relative to the working directory (for `--restart`) and its time; (None, None) if there is none."""
    import glob
    import h5py
    for path in glob.glob(flotsam.path(output_dir, "checkpoints", "checkpoint_*.h5")):
        with h5py.File(path) as f:
            if int(f.attrs["step"]) == step:
                return os.path.relpath(path, flotsam.workdir), float(f.attrs["time"])
    return None, None


def read_diagnostics(output_dir):
    """The rows of diagnostics.csv as dictionaries of strings (exact text, for bitwise comparisons)."""
    with open(os.path.join(output_dir, "diagnostics.csv")) as f:
        return list(csv.DictReader(line for line in f if not line.startswith("#")))


def csv_data_lines(path):
    """The header and the rows of a CSV file a run wrote, without its '#' comment lines (which carry
    the date and the invocation, so they differ between two runs with the same results)."""
    with open(path) as f:
        return [line for line in f.read().splitlines() if not line.startswith("#")]


class PrivateDisplay:
    """A virtual X server of its own for pvbatch (Debian's ParaView renders through X only; it has no
    EGL or OSMesa build, so `pvbatch --force-offscreen-rendering` still needs a display). Xvfb picks a
    free display number itself and reports it (-displayfd): no race with other X servers starting at
    the same moment, which `xvfb-run -a` has (it picks the number from /tmp/.X*-lock files, then
    starts the server). Use as `with PrivateDisplay() as environment:` and pass `env=environment` to the
    programs that render; the server is stopped when the block ends (after those programs: pvbatch
    aborts when its X server goes away under it)."""

    def __init__(self, xvfb="Xvfb", timeout=30):
        self.xvfb = xvfb
        self.timeout = timeout
        self.process = None
        self.display = None

    def __enter__(self):
        read_end, write_end = os.pipe()
        # -noreset: by default the server resets when its last client leaves, and pvbatch, which opens a
        # test connection, closes it and connects again at once, then finds no server ("bad X server
        # connection"). Its messages go to a file: a pipe nobody reads would fill up.
        self.log = tempfile.TemporaryFile()
        self.process = subprocess.Popen([self.xvfb, "-displayfd", str(write_end), "-nolisten", "tcp", "-noreset",
                                         "-screen", "0", "1280x1024x24"], pass_fds=[write_end],
                                        stdout=subprocess.DEVNULL, stderr=self.log)
        os.close(write_end)
        number = b""
        start = time.time()
        with os.fdopen(read_end, "rb", buffering=0) as pipe:
            while not number.endswith(b"\n") and time.time() - start < self.timeout:
                chunk = pipe.read(16)     # Xvfb writes the number once it accepts connections
                if not chunk:             # it ended without starting
                    break
                number += chunk
        if not number.strip().isdigit():
            self.__exit__()
            self.log.seek(0)
            raise RuntimeError(f"{self.xvfb} did not start: {self.log.read().decode(errors='replace')[-500:]}")
        self.display = ":" + number.decode().strip()
        return dict(os.environ, DISPLAY=self.display)

    def __exit__(self, *_):
        if self.process is not None and self.process.poll() is None:
            self.process.terminate()
        if self.process is not None:
            self.process.wait(timeout=30)
            self.log.close()


def main_arguments():
    if len(sys.argv) < 4:
        sys.exit(f"usage: {sys.argv[0]} <flotsam> <mpiexec> <scene folder> [...]")
    return sys.argv[1], sys.argv[2], os.path.abspath(sys.argv[3]), sys.argv[4:]


__all__ = ["Checks", "DrainedPopen", "Flotsam", "PrivateDisplay", "checkpoint_at_step", "child_pids", "rank_pids", "wait_for_file", "wait_for_rows",
           "signal_ranks", "read_diagnostics", "csv_data_lines", "signal", "main_arguments", "pass_on_array_copies"]
