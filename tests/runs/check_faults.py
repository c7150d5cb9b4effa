#!/usr/bin/python3
"""Faults a run must survive (issue 4), each checked on the real program under mpiexec:

  * kill -9 of every rank mid-run, restart from the latest checkpoint: the diagnostics of the finished
    run are bitwise those of an uninterrupted run;
  * SIGTERM to the ranks (what a batch system sends), SIGUSR1 to mpirun (which forwards it): checkpoint
    written, exit status 5, and the restarted run reaches the same end state;
  * restart on another number of ranks: equal to 1e-10 relative;
  * a truncated checkpoint and one of another format version are refused with a clear message;
  * an output folder that holds a previous run or cannot be written is refused before the run starts;
    --overwrite replaces the previous run;
  * a blow-up stops the run within the step, names step, time, rank, particle and quantity, and
    leaves a last output for inspection.

usage: check_faults.py <flotsam> <mpiexec> <tests/runs/scenes>"""

import os
import shutil
import signal

import h5py

from flotsam_run import Checks, Flotsam, csv_data_lines, main_arguments, read_diagnostics, signal_ranks, wait_for_file

RANKS = 2
VALUE_COLUMNS = ["time", "total_mass", "kinetic_energy", "fluid_volume", "h_eq", "max_speed"]


def error_lines(result):
    return [line for line in result.stderr.splitlines() if line.startswith("flotsam: error:")]


def interrupted_run(flotsam, checks, scene, name, wait_for, interrupt):
    """Start a run, interrupt it once checkpoint `wait_for` exists, restart it from the latest
    checkpoint; returns (the interrupted process, its stderr, the restart's CompletedProcess)."""
    process = flotsam.start(scene, RANKS)
    reached = wait_for_file(flotsam.path(name, "checkpoints", wait_for), process)
    checks.check(reached, f"{name}: the run wrote {wait_for}")
    interrupt(process)
    _, stderr = process.communicate(timeout=300)
    rows = read_diagnostics(flotsam.path(name))
    checks.check(float(rows[-1]["time"]) < 0.15 * (1 - 1e-9), f"{name}: interrupted before the end",
                 f"last row at t = {rows[-1]['time']}")
    restart = flotsam.run(scene, RANKS, "--restart", "latest")
    checks.check(restart.returncode == 0, f"{name}: the restart finished", restart.stderr[-2000:])
    return process, stderr, restart


def main():
    flotsam_path, mpiexec, scenes, _ = main_arguments()
    flotsam = Flotsam(flotsam_path, mpiexec, "faults")
    checks = Checks()
    template = os.path.join(scenes, "column.nml")

    # --- the uninterrupted reference ------------------------------------------------------------
    flotsam.remove("reference")
    reference_scene = flotsam.scene(template, "reference.nml", "reference")
    result = flotsam.run(reference_scene, RANKS)
    checks.check(result.returncode == 0, "reference run", result.stderr[-2000:])
    reference = read_diagnostics(flotsam.path("reference"))
    with open(flotsam.path("reference", "diagnostics.csv")) as f:
        reference_text = f.read()
    reference_rows = csv_data_lines(flotsam.path("reference", "diagnostics.csv"))

    def same_end_state(name):
        # the rows, not the '#' lines: those name each invocation's date (and a continuation)
        rows = csv_data_lines(flotsam.path(name, "diagnostics.csv"))
        checks.check(rows == reference_rows, f"{name}: diagnostics rows bitwise equal to the uninterrupted run",
                     f"{len(rows)} rows against {len(reference_rows)}")

    # --- kill -9 of every rank mid-run ------------------------------------------------------------
    flotsam.remove("killed")
    scene = flotsam.scene(template, "killed.nml", "killed")
    process, _, _ = interrupted_run(flotsam, checks, scene, "killed", "checkpoint_000012.h5",
                                    lambda p: signal_ranks(p, signal.SIGKILL))
    checks.check(process.returncode != 0, "killed: mpirun reports the killed ranks")
    same_end_state("killed")

    # --- SIGTERM to the ranks ---------------------------------------------------------------------
    flotsam.remove("terminated")
    scene = flotsam.scene(template, "terminated.nml", "terminated")
    process, stderr, restart = interrupted_run(flotsam, checks, scene, "terminated", "checkpoint_000010.h5",
                                               lambda p: signal_ranks(p, signal.SIGTERM))
    checks.check(process.returncode == 5, "terminated: exit status 5", f"got {process.returncode}")
    checks.check("flotsam: stopped by SIGTERM at step" in stderr and "checkpoint written" in stderr,
                 "terminated: says where it stopped and which checkpoint it wrote", stderr[-1000:])
    checks.check("continuing" in restart.stderr, "terminated: the restart says where it continues")
    same_end_state("terminated")

    # --- SIGUSR1 to mpirun, which forwards it to the ranks at once -------------------------------
    flotsam.remove("mpirun_signalled")
    scene = flotsam.scene(template, "mpirun_signalled.nml", "mpirun_signalled")
    process, stderr, _ = interrupted_run(flotsam, checks, scene, "mpirun_signalled", "checkpoint_000010.h5",
                                         lambda p: p.send_signal(signal.SIGUSR1))
    checks.check(process.returncode == 5 and "flotsam: stopped by SIGUSR1" in stderr,
                 "mpirun_signalled: checkpoint written, exit status 5", f"{process.returncode}: {stderr[-1000:]}")
    same_end_state("mpirun_signalled")

    # --- restart on another number of ranks --------------------------------------------------------
    # Over a short continuation: this flow amplifies round-off within a few hundred steps (an
    # uninterrupted run on 3 ranks differs from one on 2 ranks by 1e-6 after 200 steps).
    flotsam.remove("three_ranks")
    shutil.copytree(flotsam.path("reference"), flotsam.path("three_ranks"))
    scene = flotsam.scene(template, "three_ranks.nml", "three_ranks", end_time="0.02")
    result = flotsam.run(scene, 3, "--restart", "three_ranks/checkpoints/checkpoint_000002.h5")
    checks.check(result.returncode == 0, "three ranks: restart of a 2-rank checkpoint", result.stderr[-2000:])
    rows = read_diagnostics(flotsam.path("three_ranks"))
    end = len(rows) - 1
    checks.check(end == 2 and rows[end]["time"] == reference[end]["time"], "three ranks: rows up to t = 0.02",
                 f"{len(rows)} rows")
    checks.check(rows[end]["step"] == reference[end]["step"] and rows[end]["particles"] == reference[end]["particles"],
                 "three ranks: same step and particle count")
    for column in VALUE_COLUMNS:
        checks.close(float(rows[end][column]), float(reference[end][column]), 1e-10, f"three ranks: {column}")

    # --- checkpoints that must be refused -----------------------------------------------------------
    source = flotsam.path("reference", "checkpoints", "checkpoint_000015.h5")
    truncated = flotsam.path("truncated.h5")
    with open(source, "rb") as f:
        data = f.read()
    with open(truncated, "wb") as f:
        f.write(data[: len(data) // 2])
    result = flotsam.run(reference_scene, RANKS, "--restart", truncated)
    errors = error_lines(result)
    checks.check(result.returncode == 2 and len(errors) == 1 and "truncated" in errors[0],
                 "truncated checkpoint refused once, clearly, with status 2", f"{result.returncode}: {errors}")

    other_version = flotsam.path("other_version.h5")
    shutil.copyfile(source, other_version)
    with h5py.File(other_version, "r+") as f:
        other = int(f.attrs["format_version"]) + 1
        f.attrs.modify("format_version", other)
    result = flotsam.run(reference_scene, RANKS, "--restart", other_version)
    errors = error_lines(result)
    checks.check(result.returncode == 2 and len(errors) == 1 and f"has format version {other}" in errors[0],
                 "checkpoint of another format version refused", f"{result.returncode}: {errors}")
    with open(flotsam.path("reference", "diagnostics.csv")) as f:
        checks.check(f.read() == reference_text, "a refused restart leaves the run's files alone")

    # --- output folders that must be refused ---------------------------------------------------------
    result = flotsam.run(reference_scene, RANKS)
    errors = error_lines(result)
    checks.check(result.returncode == 3 and len(errors) == 1 and "already holds a previous run" in errors[0],
                 "folder with a previous run refused with status 3", f"{result.returncode}: {errors}")
    scene = flotsam.scene(template, "unwritable.nml", "/proc/flotsam_cannot_write_here")
    result = flotsam.run(scene, RANKS)
    errors = error_lines(result)
    checks.check(result.returncode == 3 and len(errors) == 1 and "cannot create or write to output folder" in errors[0],
                 "unwritable folder refused with status 3", f"{result.returncode}: {errors}")

    # --overwrite: a shorter run replaces the previous one entirely; it checkpoints by wall-clock time
    scene = flotsam.scene(template, "short.nml", "killed", end_time="0.02", checkpoint_interval_steps="0",
                          checkpoint_interval_wall="0.02")
    result = flotsam.run(scene, RANKS, "--overwrite")
    checks.check(result.returncode == 0, "--overwrite replaces a previous run", result.stderr[-2000:])
    left = sorted(os.listdir(flotsam.path("killed", "checkpoints")))
    with open(flotsam.path("killed", "checkpoints", "latest")) as f:
        latest = f.read().strip()
    checks.check(left[-2] == latest and len(read_diagnostics(flotsam.path("killed"))) == 3,
                 "--overwrite leaves no file of the previous run", f"latest {latest}, files {left}")
    checks.check(len(left) >= 3, "checkpoints every checkpoint_interval_wall seconds", f"{left}")

    # --- blow-up -------------------------------------------------------------------------------------
    flotsam.remove("blow_up")
    scene = flotsam.scene(os.path.join(scenes, "blow_up.nml"), "blow_up.nml", "blow_up")
    result = flotsam.run(scene, RANKS)
    errors = error_lines(result)
    message = errors[0] if errors else ""
    checks.check(result.returncode == 4 and len(errors) == 1, "blow-up stops the run with status 4",
                 f"{result.returncode}: {result.stderr[-1500:]}")
    for part in ["blew up at step 5 (t = 0.018", "s) on rank 0: particle ", "(material 'water') at x = (",
                 "density = -", "written to blow_up/fields/fields_000002.h5 for inspection"]:
        checks.check(part in message, f"blow-up message names: {part}", message)
    inspection = flotsam.path("blow_up", "fields", "fields_000002.h5")
    checks.check(os.path.exists(inspection), "blow-up: the state is written")
    if os.path.exists(inspection):
        with h5py.File(inspection) as f:
            checks.check(f.attrs["step"] == 5 and min(f["particles/density"][:]) < 0,
                         "blow-up: the inspection file holds the failing step")
    with open(flotsam.path("blow_up", "particles.xmf")) as f:
        checks.check("fields_000002.h5" in f.read(), "blow-up: the inspection output is in particles.xmf")

    return checks.summary()


if __name__ == "__main__":
    raise SystemExit(main())
