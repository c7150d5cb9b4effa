#!/usr/bin/python3
"""The Slurm scripts (scripts/slurm/*.sbatch) without Slurm: bash -n, shellcheck when installed, and
a job's life played with stand-ins for srun (runs the tasks with the build's mpiexec) and sbatch
(records how it was called):
  * flotsam.sbatch: SIGUSR1 to the batch script (what #SBATCH --signal=B:USR1@600 sends) reaches the
    ranks, which checkpoint; the script submits its follow-up job (afterany dependency, job number 2);
    the follow-up continues from the checkpoint to the end; a third job finds the run finished;
  * study.sbatch: array task 2 runs case 2 of a study; SIGUSR1 to a task stops its case at a checkpoint
    and resubmits that array index; the follow-up finishes the case.

usage: check_slurm.py <flotsam> <mpiexec> <tests/runs/scenes> <scripts folder>"""

import os
import shutil
import signal
import stat
import subprocess
import sys

from flotsam_run import MPI_ENVIRONMENT, Checks, DrainedPopen, main_arguments, read_diagnostics, wait_for_rows

FAKE_SRUN = """#!/bin/bash
# srun stand-in: drop srun's options, start the tasks with the MPI launcher (exec: same pid, so a
# signal to "srun" reaches the launcher, which passes it on as srun does)
tasks="$SLURM_NTASKS"
while [[ $# -gt 0 && "$1" == -* ]]; do
   if [[ "$1" == -n || "$1" == --ntasks ]]; then tasks="$2"; shift; fi
   shift
done
exec "$TEST_MPIEXEC" -n "$tasks" "$@"
"""

FAKE_SBATCH = """#!/bin/bash
# sbatch stand-in: record the call (arguments, one per line, then the job number variable), print a job id
{ printf '%s\\n' "$@"; echo "FLOTSAM_JOB_NUMBER=${FLOTSAM_JOB_NUMBER:-}"; } > "$TEST_SBATCH_LOG"
echo 4242
"""


def executable(path, text):
    with open(path, "w") as f:
        f.write(text)
    os.chmod(path, os.stat(path).st_mode | stat.S_IXUSR | stat.S_IXGRP | stat.S_IXOTH)


def main():
    flotsam_path, mpiexec, _scenes, rest = main_arguments()
    flotsam_path = os.path.abspath(flotsam_path)
    scripts = os.path.abspath(rest[0])
    slurm = os.path.join(scripts, "slurm")
    inputs = os.path.join(os.path.dirname(scripts), "inputs")
    checks = Checks()
    work = os.path.abspath("slurm")
    shutil.rmtree(work, ignore_errors=True)
    fake = os.path.join(work, "bin")
    os.makedirs(fake)
    executable(os.path.join(fake, "srun"), FAKE_SRUN)
    executable(os.path.join(fake, "sbatch"), FAKE_SBATCH)
    sbatch_log = os.path.join(work, "sbatch.log")

    for name in ("flotsam.sbatch", "study.sbatch"):
        path = os.path.join(slurm, name)
        syntax = subprocess.run(["bash", "-n", path], capture_output=True, text=True)
        checks.check(syntax.returncode == 0, f"bash -n {name}", syntax.stderr)
        if shutil.which("shellcheck"):
            lint = subprocess.run(["shellcheck", path], capture_output=True, text=True)
            checks.check(lint.returncode == 0, f"shellcheck {name}", lint.stdout[-2000:])

    def job(script, arguments, job_id, **variables):
        environment = dict(os.environ, **MPI_ENVIRONMENT)
        environment.update(PATH=fake + os.pathsep + os.environ["PATH"], TEST_MPIEXEC=mpiexec,
                           TEST_SBATCH_LOG=sbatch_log, SLURM_JOB_ID=str(job_id), SLURM_JOB_NAME="tank",
                           SLURM_NTASKS="2", SLURM_SUBMIT_DIR=work, FLOTSAM=flotsam_path, **variables)
        if os.path.exists(sbatch_log):
            os.remove(sbatch_log)
        return DrainedPopen(["bash", os.path.join(slurm, script)] + arguments, env=environment, cwd=work,
                            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)

    def submitted():
        if not os.path.exists(sbatch_log):
            return []
        with open(sbatch_log) as f:
            return f.read().splitlines()

    # --- one run through the time limit --------------------------------------------------------------
    steps = 2000
    scene = os.path.join(inputs, "hydrostatic_tank.nml")
    output = os.path.join(work, "tank")
    arguments = [scene, "--set", f"&run max_steps = {steps} /"]
    process = job("flotsam.sbatch", arguments, 100, FLOTSAM_OUTPUT=output)
    started = wait_for_rows(os.path.join(output, "diagnostics.csv"), process)
    process.send_signal(signal.SIGUSR1)          # Slurm's B:USR1, to the batch script only
    log, _ = process.communicate(timeout=300)
    checks.check(started and process.returncode == 5 and "outcome 'stopped_by_signal'" in log,
                 "flotsam.sbatch: SIGUSR1 to the script stops flotsam at a checkpoint (exit 5)", log)
    call = submitted()
    checks.check("--dependency=afterany:100" in call and scene in call and f"&run max_steps = {steps} /" in call
                 and "FLOTSAM_JOB_NUMBER=2" in call and "submitted follow-up job 4242" in log,
                 "flotsam.sbatch: follow-up job submitted, after this one, with the same scene and arguments",
                 str(call))
    process = job("flotsam.sbatch", arguments, 101, FLOTSAM_OUTPUT=output, FLOTSAM_JOB_NUMBER="2")
    log, _ = process.communicate(timeout=600)
    checks.check(process.returncode == 0 and "continuing from" in log and "run finished" in log and not submitted(),
                 "flotsam.sbatch: the follow-up job continues from the checkpoint to the end", log)
    last = read_diagnostics(output)[-1]["step"] if os.path.exists(os.path.join(output, "diagnostics.csv")) else "none"
    checks.check(last == str(steps), f"the run reached step {steps}", last)
    process = job("flotsam.sbatch", arguments, 102, FLOTSAM_OUTPUT=output, FLOTSAM_JOB_NUMBER="3")
    log, _ = process.communicate(timeout=120)
    checks.check(process.returncode == 0 and "holds a finished run: nothing to do" in log,
                 "flotsam.sbatch: a job after the end does nothing", log)
    checks.check(not [f for f in os.listdir(output) if f.startswith(".job_")], "no marker files left")

    # --- a study as an array job ------------------------------------------------------------------
    study = os.path.join(work, "tank.study")
    with open(study, "w") as f:
        f.write(f"[study]\nscene = {scene}\nranks = 2\noutput = study_out\n[parameters]\n"
                f"material:water stabilization = [\"C0\", \"NB\"]\nrun max_steps = [{steps}]\n")
    case2 = os.path.join(work, "study_out", "cases", f"stabilization-NB_max_steps-{steps}")
    study_script = os.path.join(scripts, "study")
    process = job("study.sbatch", [study], 200, SLURM_ARRAY_TASK_ID="2", SLURM_ARRAY_JOB_ID="199",
                  FLOTSAM_STUDY=study_script)
    started = wait_for_rows(os.path.join(case2, "diagnostics.csv"), process)
    process.send_signal(signal.SIGUSR1)
    log, _ = process.communicate(timeout=300)
    call = submitted()
    checks.check(started and process.returncode == 5 and "stopped_by_signal" in log and "--array=2" in call and
                 "--dependency=afterany:199_2" in call and study in call,
                 "study.sbatch: SIGUSR1 stops case 2 at a checkpoint and resubmits array index 2", log + str(call))
    process = job("study.sbatch", [study], 201, SLURM_ARRAY_TASK_ID="2", SLURM_ARRAY_JOB_ID="199",
                  FLOTSAM_STUDY=study_script, FLOTSAM_JOB_NUMBER="2")
    log, _ = process.communicate(timeout=600)
    checks.check(process.returncode == 0 and "continuing from checkpoints/" in log and (": finished, " in log or ": max_steps, " in log) and
                 "[2/2]" in log and not os.path.exists(os.path.join(work, "study_out", "cases",
                                                                     f"stabilization-C0_max_steps-{steps}")),
                 "study.sbatch: the follow-up finishes case 2, and only case 2", log)
    missing = subprocess.run([sys.executable, study_script, study, "--report", "--flotsam", flotsam_path],
                             cwd=work, capture_output=True, text=True)
    checks.check(missing.returncode == 0 and "(1 of 2 cases)" in missing.stdout and
                 f"stabilization-C0_max_steps-{steps}: not run" in missing.stdout,
                 "--report after the array: the done case tabulated, the missing one named",
                 missing.stdout + missing.stderr)
    raise SystemExit(checks.summary())


if __name__ == "__main__":
    main()
