#!/usr/bin/python3
"""Faults a run must survive (issue 4), each checked on the real program under mpiexec:

  * kill -9 of every rank mid-run, restart from the latest checkpoint: the diagnostics of the finished
    run are bitwise those of an uninterrupted run;
  * SIGTERM to the ranks (what a batch system sends), SIGUSR1 to mpirun (which forwards it): checkpoint
    written, exit status 5, and the restarted run reaches the same end state;
  * restart on another number of ranks: equal to 1e-10 relative;
  * a truncated checkpoint and one of another format version are refused with a clear message;
  * a restart with a changed scene: a changed bulk modulus is refused with status 2 and a message naming
    material(1)%bulk_modulus, continues with --allow-scene-change (a warning names it); a changed end_time,
    or only comments, layout, order and number spelling changed, continue silently (the latter bit for
    bit); a checkpoint of format 4 (no stored scene) is refused, and continued with the flag;
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


def warning_lines(result):
    return [line for line in result.stderr.splitlines() if line.startswith("flotsam: warning:")]


def continued_copy(flotsam, name, text, *arguments):
    """Copy the reference run to folder `name`, write `text` (output_dir 'reference') as scene name.nml
    with output_dir `name`, and continue it there from its third-last checkpoint."""
    flotsam.remove(name)
    shutil.copytree(flotsam.path("reference"), flotsam.path(name))
    scene = flotsam.path(name + ".nml")
    with open(scene, "w") as f:
        f.write(text.replace("output_dir = 'reference'", f"output_dir = '{name}'"))
    checkpoint = sorted(os.listdir(flotsam.path(name, "checkpoints")))[-4]      # [-1] is `latest`
    return flotsam.run(scene, RANKS, "--restart", os.path.join(name, "checkpoints", checkpoint), *arguments)


def check_scene_changes(flotsam, checks, template, reference_text):
    """A restart compares its scene with the one the checkpoint stores (docs/output.md)."""
    with open(flotsam.scene(template, "reference.nml", "reference")) as f:
        scene = f.read()

    def diagnostics(name):
        with open(flotsam.path(name, "diagnostics.csv")) as f:
            return f.read()

    stiffer = scene.replace("bulk_modulus = 2.0e6", "bulk_modulus = 1.0e6")
    checks.check(stiffer != scene, "scene changes: the template sets bulk_modulus = 2.0e6")
    result = continued_copy(flotsam, "bulk_modulus", stiffer)
    errors = error_lines(result)
    checks.check(result.returncode == 2 and len(errors) == 1 and "was written for another scene: "
                 "material(1)%bulk_modulus: 2000000.0 -> 1000000.0 (" in errors[0] and "--allow-scene-change" in errors[0],
                 "changed bulk_modulus refused with status 2, the message names it", f"{result.returncode}: {errors}")
    checks.check(diagnostics("bulk_modulus") == reference_text, "a refused scene leaves the run's files alone")

    result = continued_copy(flotsam, "bulk_modulus", stiffer, "--allow-scene-change")
    warnings = warning_lines(result)
    checks.check(result.returncode == 0 and len(warnings) == 1 and "continuing with a changed scene "
                 "(--allow-scene-change): material(1)%bulk_modulus: 2000000.0 -> 1000000.0" in warnings[0],
                 "--allow-scene-change continues, with a warning naming the change",
                 f"{result.returncode}: {warnings} {result.stderr[-1500:]}")

    longer = scene.replace("end_time = 0.15", "end_time = 0.16")
    result = continued_copy(flotsam, "end_time", longer)
    rows = read_diagnostics(flotsam.path("end_time"))
    checks.check(result.returncode == 0 and not warning_lines(result) and abs(float(rows[-1]["time"]) - 0.16) < 1e-12,
                 "a changed end_time continues silently to the new end",
                 f"{result.returncode}, last row at t = {rows[-1]['time']}: {result.stderr[-1500:]}")

    # comments, blanks, line breaks, the order of variables and groups, the spelling of numbers and logicals
    reworded = ("! the same scene, written otherwise\n"
                + scene.replace("density = 1000.0, bulk_modulus = 2.0e6, viscosity = 1.0e-3",
                                "viscosity = 0.001,   ! Pa s\n   Density = 1e3,\n   bulk_modulus = 2000000")
                       .replace("end_time = 0.15", "end_time = 1.5e-1 ! s")
                       .replace("&gravity acceleration = 0.0, -9.81 /", "")
                + "\n&gravity\n   acceleration = 0, -9.810  ! m/s^2\n/\n")
    checks.check("1e3" in reworded and "&gravity\n" in reworded, "scene changes: the reworded scene is reworded")
    result = continued_copy(flotsam, "reworded", reworded)
    checks.check(result.returncode == 0 and not warning_lines(result), "the scene written otherwise continues silently",
                 f"{result.returncode}: {result.stderr[-1500:]}")
    reference_rows = csv_data_lines(flotsam.path("reference", "diagnostics.csv"))
    checks.check(csv_data_lines(flotsam.path("reworded", "diagnostics.csv")) == reference_rows,
                 "reworded: diagnostics rows bitwise equal to the uninterrupted run")

    # a checkpoint of the previous format, without the scene
    flotsam.remove("format_4")
    shutil.copytree(flotsam.path("reference"), flotsam.path("format_4"))
    checkpoint = sorted(os.listdir(flotsam.path("format_4", "checkpoints")))[-4]
    with h5py.File(flotsam.path("format_4", "checkpoints", checkpoint), "r+") as f:
        del f.attrs["scene"]
        f.attrs.modify("format_version", 4)
    old = flotsam.scene(template, "format_4.nml", "format_4")
    result = flotsam.run(old, RANKS, "--restart", os.path.join("format_4", "checkpoints", checkpoint))
    errors = error_lines(result)
    checks.check(result.returncode == 2 and len(errors) == 1 and "stores no scene (format version 4" in errors[0]
                 and "--allow-scene-change" in errors[0], "a checkpoint without a scene is refused", f"{errors}")
    result = flotsam.run(old, RANKS, "--restart", os.path.join("format_4", "checkpoints", checkpoint),
                         "--allow-scene-change")
    warnings = warning_lines(result)
    checks.check(result.returncode == 0 and len(warnings) == 1 and "stores no scene" in warnings[0]
                 and csv_data_lines(flotsam.path("format_4", "diagnostics.csv")) == reference_rows,
                 "... and continued with --allow-scene-change, with a warning", f"{result.returncode}: {warnings}")


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
        # the XDMF series continue across the restart: the same outputs, times and boxes as uninterrupted
        for xdmf in ["particles.xmf", "grid.xmf"]:
            with open(flotsam.path(name, xdmf)) as f, open(flotsam.path("reference", xdmf)) as g:
                checks.check(f.read() == g.read(), f"{name}: {xdmf} equal to the uninterrupted run's")

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

    check_scene_changes(flotsam, checks, template, reference_text)

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
