#!/usr/bin/python3
"""`cmake --install <build> --prefix P` into a temporary prefix: the programs, the user scripts
(flotsam-study, flotsam-plot-*, ...), the Slurm scripts, the example inputs and the docs are installed;
the installed flotsam runs from another folder on an installed example scene; flotsam-plot-diagnostics
plots it; flotsam-study, with no --flotsam or --mpiexec, runs a case with the installed flotsam and
the launcher of the build's MPI (share/flotsam/mpiexec.txt), not with a checkout's.

usage: check_install.py <cmake> <build folder> <mpiexec>"""

import csv
import json
import os
import shutil
import subprocess
import sys

from flotsam_run import MPI_ENVIRONMENT, Checks, pass_on_array_copies


def main():
    cmake, build, mpiexec = sys.argv[1], os.path.abspath(sys.argv[2]), sys.argv[3]
    checks = Checks()
    work = os.path.abspath("install")
    shutil.rmtree(work, ignore_errors=True)
    prefix = os.path.join(work, "prefix")
    elsewhere = os.path.join(work, "elsewhere")
    os.makedirs(elsewhere)
    done = subprocess.run([cmake, "--install", build, "--prefix", prefix], capture_output=True, text=True)
    checks.check(done.returncode == 0, "cmake --install into a temporary prefix", done.stdout[-1000:] + done.stderr)
    expected = ["bin/flotsam", "bin/flotsam_bench", "bin/flotsam-study", "bin/flotsam-plot-loads",
                "bin/flotsam-load-report", "bin/flotsam-design-check", "share/flotsam/python/load_signals.py", "share/flotsam/python/ensemble.py",
                "bin/flotsam-plot-diagnostics", "bin/flotsam-render-step", "bin/flotsam-crowding-map",
                "share/flotsam/slurm/flotsam.sbatch", "share/flotsam/slurm/study.sbatch",
                "share/flotsam/inputs/hydrostatic_tank.nml", "share/flotsam/inputs/studies/tank_ppc.study",
                "share/doc/flotsam/README.md", "share/doc/flotsam/cluster.md", "share/doc/flotsam/output.md"]
    missing = [p for p in expected if not os.path.isfile(os.path.join(prefix, p))]
    checks.check(not missing, "programs, scripts, Slurm scripts, inputs and docs installed", str(missing))
    not_executable = [p for p in expected if p.startswith("bin/") and not os.access(os.path.join(prefix, p), os.X_OK)]
    checks.check(not not_executable, "installed programs and scripts are executable", str(not_executable))
    with open(os.path.join(prefix, "share", "flotsam", "mpiexec.txt")) as f:
        recorded = f.read().strip()
    checks.check(recorded == mpiexec, "share/flotsam/mpiexec.txt names the build's launcher", recorded)
    flotsam = os.path.join(prefix, "bin", "flotsam")
    libraries = subprocess.run(["ldd", flotsam], capture_output=True, text=True)
    checks.check(libraries.returncode == 0 and "not found" not in libraries.stdout,
                 "the installed flotsam finds its libraries", libraries.stdout)

    # from another folder, with nothing of the build or source tree named
    environment = dict(os.environ, **MPI_ENVIRONMENT)
    environment.pop("FLOTSAM_MPIEXEC", None)
    scene = os.path.join(prefix, "share", "flotsam", "inputs", "hydrostatic_tank.nml")
    run = subprocess.run([mpiexec, "-n", "2", flotsam, scene, "--set", "&run max_steps = 10, output_dir = 'run' /"],
                         cwd=elsewhere, env=environment, capture_output=True, text=True)
    pass_on_array_copies(run.stderr)
    summary = os.path.join(elsewhere, "run", "run_summary.csv")
    ok = run.returncode == 0 and os.path.exists(summary)
    if ok:
        with open(summary) as f:
            rows = list(csv.DictReader(line for line in f if not line.startswith("#")))
            ok = rows[0]["outcome"] in ("finished", "max_steps")
    checks.check(ok, "the installed flotsam runs an installed scene from another folder", run.stderr[-1500:])
    plot = subprocess.run([os.path.join(prefix, "bin", "flotsam-plot-diagnostics"), "run", "-o", "d.png"],
                          cwd=elsewhere, env=environment, capture_output=True, text=True)
    checks.check(plot.returncode == 0 and os.path.exists(os.path.join(elsewhere, "d.png")),
                 "flotsam-plot-diagnostics plots it", plot.stderr[-1000:])
    report = subprocess.run([os.path.join(prefix, "bin", "flotsam-load-report"), "run", "--no-plot"],
                            cwd=elsewhere, env=environment, capture_output=True, text=True)
    checks.check(report.returncode == 0 and os.path.exists(os.path.join(elsewhere, "run", "load_report.csv")),
                 "flotsam-load-report (with the installed load_signals.py) reports on its loads",
                 report.stdout[-500:] + report.stderr[-1000:])

    with open(os.path.join(elsewhere, "tiny.study"), "w") as f:
        f.write(f"[study]\nscene = {scene}\nranks = 2\noutput = tiny\n[parameters]\nrun max_steps = [10]\n")
    study = subprocess.run([os.path.join(prefix, "bin", "flotsam-study"), "tiny.study"], cwd=elsewhere,
                           env=environment, capture_output=True, text=True)
    record_path = os.path.join(elsewhere, "tiny", "cases", "max_steps-10", "study_case.json")
    command = []
    if os.path.exists(record_path):
        with open(record_path) as f:
            command = json.load(f)["attempts"][-1]["command"]
    checks.check(study.returncode == 0 and (": finished, " in study.stdout or ": max_steps, " in study.stdout) and command[:1] == [mpiexec]
                 and command[3:4] == [flotsam], "flotsam-study runs the installed flotsam with the build's launcher",
                 f"{study.stdout}{study.stderr[-1000:]} {command[:4]}")
    raise SystemExit(checks.summary())


if __name__ == "__main__":
    main()
