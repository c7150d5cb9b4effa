#!/usr/bin/python3
"""The HDF5 fields files and XDMF time series of a run, read back with h5py and meshio and checked
against the run's own diagnostics.csv: one fields file per diagnostics row at the same time and step,
particle counts, total mass, kinetic energy, fluid volume and maximum speed recomputed from the
particle fields, unique ids, positions in the world frame, consistent stress fields, a grid whose nodal
mass sums to the total mass, the largest rank's share (max_rank_share) from the particles' ranks, and
the XDMF files listing every output time. The 2-D scene runs on 3 ranks of which one holds no particle
(load balancing off); the 3-D scene on 2 ranks, balanced: no rank holds more than 60 % of the
particles at any output. The run's timing.csv: every phase of the time loop, adding up to the loop's
wall time, with nothing charged to the smoothing phase of a scene without smoothing. A jet whose
particle count grows (moving_box_2d): meshio's TimeSeriesReader and scripts/particle_series.py give
every output its own particles. Also runs scripts/plot_diagnostics.py.

Provenance (docs/output.md): every HDF5 file carries the program version (CMakeLists.txt), a git commit
of this repository, the build type of the build folder, the number of ranks, the date and the resolved
scene (the text of <output>/scene.nml); every dataset its units and description; /particles/material
the material names; pressure = -mean_stress; every CSV file reads with one pandas.read_csv(path,
comment='#') and names program, date and ranks. Output size: the same 2-D run with field_precision =
'single' and three particle_fields writes float32 datasets within float32 rounding of the double run's
(positions double and equal), only the chosen fields, XDMF items of the precision written, the same
diagnostics rows; a restart may not change field_precision, and a restart with a later end_time keeps
the previous scene.nml as scene_1.nml.

usage: check_output.py <flotsam> <mpiexec> <tests/runs/scenes> <scripts folder>"""

import csv
import datetime
import os
import re
import subprocess
import sys
from xml.etree import ElementTree

import h5py
import meshio
import numpy as np
import pandas as pd

from flotsam_run import Checks, Flotsam, csv_data_lines, main_arguments, read_diagnostics

SOURCE = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))


def check_run(checks, flotsam, scenes, name, ranks, fluid_materials, empty_rank=None):
    flotsam.remove(name)
    scene = flotsam.scene(os.path.join(scenes, name + ".nml"), name + ".nml", name)
    result = flotsam.run(scene, ranks)
    if not checks.check(result.returncode == 0, f"{name}: run on {ranks} ranks", result.stderr[-2000:]):
        return
    rows = read_diagnostics(flotsam.path(name))
    directory = flotsam.path(name)
    with open(scene) as f:
        text = f.read()
    dim = 3 if "dim = 3" in text else 2
    check_timing(checks, name, directory, smoothed="stabilization" in text and "FOAL1" in text)
    started = datetime.datetime.now(datetime.timezone.utc) - datetime.timedelta(seconds=600)
    check_csv_files(checks, name, directory, ranks)
    scene_text = check_scene_file(checks, name, directory, scene)
    materials = re.findall(r"&material\s+name\s*=\s*'([^']*)'", text)

    for index, row in enumerate(rows):
        label = f"{name} output {index}"
        path = os.path.join(directory, "fields", f"fields_{index:06d}.h5")
        if not checks.check(os.path.exists(path), f"{label}: fields file exists"):
            continue
        with h5py.File(path) as f:
            check_provenance(checks, label, f, ranks, scene_text, started)
            check_descriptions(checks, label, f, dim, materials)
            checks.check(np.array_equal(f["particles/pressure"][:], -f["particles/mean_stress"][:]),
                         f"{label}: pressure = -mean_stress (bit for bit)")
            checks.close(f.attrs["time"], float(row["time"]), 1e-15, f"{label}: time")
            checks.check(int(f.attrs["step"]) == int(row["step"]), f"{label}: step")
            p = f["particles"]
            n = int(row["particles"])
            checks.check(p["position"].shape == (n, 3) and p["stress"].shape == (n, 9),
                         f"{label}: {n} particles with 3 coordinates and 9 stress components",
                         f"{p['position'].shape}, {p['stress'].shape}")
            mass, velocity, volume, density = p["mass"][:], p["velocity"][:], p["volume"][:], p["density"][:]
            material, ids, rank = p["material"][:], p["id"][:], p["rank"][:]
            checks.close(mass.sum(), float(row["total_mass"]), 1e-12, f"{label}: total mass")
            checks.close(0.5 * (mass * (velocity ** 2).sum(axis=1)).sum(), float(row["kinetic_energy"]), 1e-10,
                         f"{label}: kinetic energy")
            fluid = np.isin(material, fluid_materials)
            checks.close(volume[fluid].sum(), float(row["fluid_volume"]), 1e-10, f"{label}: fluid volume")
            checks.close(np.sqrt((velocity ** 2).sum(axis=1).max()), float(row["max_speed"]), 1e-12,
                         f"{label}: max speed")
            checks.check(np.allclose(volume, mass / density, rtol=1e-14), f"{label}: volume = mass / density")
            checks.check(np.array_equal(np.sort(ids), np.arange(n)), f"{label}: ids unique, 0 .. N-1")
            checks.check(np.array_equal(p["connectivity"][:], np.arange(n)), f"{label}: connectivity 0 .. N-1")
            if n > 0:
                checks.close(np.bincount(rank).max() / n, float(row["max_rank_share"]), 1e-15,
                             f"{label}: max_rank_share = largest count in /particles/rank / N")
            if ranks == 2 and empty_rank is None:     # load balancing on (the default)
                checks.check(float(row["max_rank_share"]) <= 0.6, f"{label}: no rank holds more than 60 %",
                             row["max_rank_share"])
            if empty_rank is not None:
                checks.check(empty_rank not in rank and set(rank) <= set(range(ranks)),
                             f"{label}: rank {empty_rank} held no particle and still wrote", f"{set(rank)}")
            stress = p["stress"][:].reshape(n, 3, 3)
            checks.check(np.allclose(stress, stress.transpose(0, 2, 1), rtol=0, atol=0), f"{label}: stress symmetric")
            checks.check(np.allclose(p["mean_stress"][:], np.trace(stress, axis1=1, axis2=2) / 3, rtol=1e-13,
                                     atol=1e-9), f"{label}: mean stress = trace / 3")
            position = p["position"][:]
            if dim == 2:
                checks.check(not position[:, 2].any() and not velocity[:, 2].any() and
                             not stress[:, 2, 0:2].any(), f"{label}: z = 0 in 2-D")
            g = f["grid"]
            checks.close(g["node/mass"][:].sum(), float(row["total_mass"]), 1e-10, f"{label}: grid mass")
            node_dims = g["node/mass"].shape
            checks.check(g["node/velocity"].shape == node_dims + (3,), f"{label}: nodal velocity shape")
            densities = [k for k in g["cell"] if k.startswith("density_")]
            for key in densities:
                cells = g["cell"][key][:]
                checks.check(cells.shape == tuple(max(d - 1, 1) for d in node_dims),
                             f"{label}: {key} on the cells", f"{cells.shape} for nodes {node_dims}")
                filled = cells[np.isfinite(cells)]
                checks.check(filled.size > 0 and np.all(filled > 0), f"{label}: {key} positive where present")

    # checkpoints carry the same provenance
    checkpoints = sorted(p for p in os.listdir(os.path.join(directory, "checkpoints")) if p.endswith(".h5"))
    if checks.check(len(checkpoints) > 0, f"{name}: a checkpoint"):
        with h5py.File(os.path.join(directory, "checkpoints", checkpoints[-1])) as f:
            check_provenance(checks, f"{name} {checkpoints[-1]}", f, ranks, scene_text, started)

    # the particle time series, as meshio reads it
    with meshio.xdmf.TimeSeriesReader(os.path.join(directory, "particles.xmf")) as reader:
        points, cells = reader.read_points_cells()
        times = [reader.read_data(k)[0] for k in range(reader.num_steps)]
        checks.check(reader.num_steps == len(rows), f"{name} particles.xmf: one step per diagnostics row",
                     f"{reader.num_steps} steps, {len(rows)} rows")
        checks.check(np.allclose(times, [float(r["time"]) for r in rows], rtol=1e-15, atol=0),
                     f"{name} particles.xmf: the diagnostics times")
        checks.check(points.shape == (int(rows[0]["particles"]), 3) and cells[0].type == "vertex",
                     f"{name} particles.xmf: point cloud of vertices", f"{points.shape}, {cells[0].type}")
        _, point_data, _ = reader.read_data(reader.num_steps - 1)
        checks.check({"velocity", "stress", "mean_stress", "pressure", "density", "id", "rank"} <= set(point_data),
                     f"{name} particles.xmf: arrays", f"{sorted(point_data)}")
    check_xdmf_precision(checks, name, directory, 8)

    # the grid time series (a structured mesh, which meshio does not read): times and data items. Each
    # member of the temporal collection is a spatial collection of one uniform grid (docs/output.md).
    root = ElementTree.parse(os.path.join(directory, "grid.xmf")).getroot()
    members = list(root.find(".//Grid[@CollectionType='Temporal']"))
    times = [float(m.find("Time").get("Value")) for m in members]
    checks.check(np.allclose(times, [float(r["time"]) for r in rows], rtol=1e-15, atol=0),
                 f"{name} grid.xmf: one grid per diagnostics time", f"{times}")
    checks.check(all(m.get("CollectionType") == "Spatial" and len(m.findall("Grid[@GridType='Uniform']")) == 1
                     for m in members), f"{name} grid.xmf: each time one uniform grid in a spatial collection")
    grids = [m if m.get("GridType") == "Uniform" else m.find("Grid") for m in members]
    shapes_agree = True
    for g in grids:
        for item in g.iter("DataItem"):
            if item.get("Format") != "HDF":
                continue
            file, dataset = item.text.split(":")
            with h5py.File(os.path.join(directory, file)) as f:
                shapes_agree &= f[dataset].shape == tuple(int(d) for d in item.get("Dimensions").split())
    checks.check(shapes_agree, f"{name} grid.xmf: every data item has the shape of its dataset")


def check_particle_series(checks, flotsam, scenes, scripts):
    """moving_box_2d: the particle count grows with the inflow. meshio's TimeSeriesReader must give every
    output's own particles (the array `position`, as many rows as every other array), and so must
    scripts/particle_series.py (a meshio.Mesh per output), equal to the fields files."""
    name = "moving_box_2d"
    flotsam.remove(name)
    scene = flotsam.scene(os.path.join(scenes, name + ".nml"), name + ".nml", name)
    result = flotsam.run(scene, 2)
    if not checks.check(result.returncode == 0, f"{name}: run on 2 ranks", result.stderr[-2000:]):
        return
    directory = flotsam.path(name)
    rows = read_diagnostics(directory)
    counts = [int(r["particles"]) for r in rows]
    checks.check(len(set(counts)) == len(counts), f"{name}: the particle count changes at every output",
                 f"{counts}")
    stored = []
    for index in range(len(rows)):
        with h5py.File(os.path.join(directory, "fields", f"fields_{index:06d}.h5")) as f:
            stored.append((f["particles/position"][:], f["particles/mean_stress"][:]))

    with meshio.xdmf.TimeSeriesReader(os.path.join(directory, "particles.xmf")) as reader:
        reader.read_points_cells()
        for k in range(reader.num_steps):
            time, point_data, _ = reader.read_data(k)
            position, mean_stress = stored[k]
            checks.check("position" in point_data and np.array_equal(point_data["position"], position),
                         f"{name} meshio step {k} (t = {time}): the output's {counts[k]} particle positions",
                         f"arrays {sorted(point_data)}, {len(point_data.get('position', []))} positions")
            checks.check(all(len(v) == counts[k] for v in point_data.values()) and
                         np.array_equal(point_data["mean_stress"], mean_stress),
                         f"{name} meshio step {k}: every array has {counts[k]} rows",
                         f"{ {key: len(v) for key, v in point_data.items()} }")

    sys.path.insert(0, scripts)
    try:
        from particle_series import particle_steps
        steps = list(particle_steps(directory))
    except Exception as error:          # reported as a failed check, not a crash of the test
        steps = []
        checks.check(False, f"{name}: scripts/particle_series.py reads the series", repr(error))
    for k, (time, mesh) in enumerate(steps):
        position, mean_stress = stored[k]
        checks.check(time == float(rows[k]["time"]) and np.array_equal(mesh.points, position) and
                     np.array_equal(mesh.cells[0].data.ravel(), np.arange(counts[k])) and
                     np.array_equal(mesh.point_data["mean_stress"], mean_stress),
                     f"{name} particle_series.py step {k}: time, {counts[k]} points, vertex cells, arrays",
                     f"t = {time}, points {mesh.points.shape}")
    checks.check(len(steps) == len(rows), f"{name} particle_series.py: one mesh per output",
                 f"{len(steps)} meshes, {len(rows)} outputs")


# --- provenance -------------------------------------------------------------------------------------------

def expected_build():
    """The version of CMakeLists.txt and the build type of the build folder of the flotsam under test."""
    with open(os.path.join(SOURCE, "CMakeLists.txt")) as f:
        version = re.search(r"project\(flotsam\s+VERSION\s+([0-9.]+)", f.read()).group(1)
    build_type = None
    cache = os.path.join(os.path.dirname(os.path.abspath(sys.argv[1])), "CMakeCache.txt")
    if os.path.exists(cache):
        with open(cache) as f:
            found = re.search(r"^CMAKE_BUILD_TYPE:STRING=(.*)$", f.read(), re.M)
            build_type = found.group(1) if found else None
    return version, build_type


def known_commit(text):
    """'unknown' outside a checkout; else 12 hex digits (+ '-modified') naming a commit of this repository."""
    if text == "unknown":
        return True
    found = re.fullmatch(r"([0-9a-f]{12})(-modified)?", text)
    if not found:
        return False
    result = subprocess.run(["git", "-C", SOURCE, "cat-file", "-e", found.group(1) + "^{commit}"],
                            capture_output=True)
    return result.returncode == 0


def parse_date(text):
    try:
        return datetime.datetime.fromisoformat(text)
    except ValueError:
        return None


def check_provenance(checks, label, f, ranks, scene_text, started):
    """The root attributes of an HDF5 file (fields file or checkpoint) that say where it came from."""
    version, build_type = expected_build()
    attrs = {k: (v.decode() if isinstance(v, bytes) else v) for k, v in f.attrs.items()}
    missing = {"flotsam_version", "flotsam_git_commit", "flotsam_build_type", "ranks", "date", "scene",
               "scene_file"} - set(attrs)
    if not checks.check(not missing, f"{label}: provenance attributes", f"missing {missing}"):
        return
    checks.check(attrs["flotsam_version"] == version, f"{label}: flotsam_version {version} (CMakeLists.txt)",
                 attrs["flotsam_version"])
    checks.check(known_commit(attrs["flotsam_git_commit"]), f"{label}: flotsam_git_commit names a commit of the "
                 "repository", attrs["flotsam_git_commit"])
    checks.check(build_type is None or attrs["flotsam_build_type"] == build_type,
                 f"{label}: flotsam_build_type {build_type} (CMakeCache.txt)", attrs["flotsam_build_type"])
    checks.check(int(attrs["ranks"]) == ranks, f"{label}: ranks = {ranks}", str(attrs["ranks"]))
    date = parse_date(attrs["date"])
    now = datetime.datetime.now(datetime.timezone.utc)
    checks.check(date is not None and date.tzinfo is not None and started <= date <= now,
                 f"{label}: date, ISO 8601 with offset, during the run", attrs["date"])
    checks.check(attrs["scene"] == scene_text, f"{label}: scene = the resolved text of scene.nml",
                 attrs["scene"][:200])


def check_descriptions(checks, label, f, dim, materials):
    """units and description of every dataset; the material names of /particles/material."""
    datasets = []
    f.visititems(lambda key, item: datasets.append(key) if isinstance(item, h5py.Dataset) else None)
    undescribed = [k for k in datasets if not (f[k].attrs.get("units") and f[k].attrs.get("description"))]
    checks.check(datasets and not undescribed, f"{label}: units and description on all {len(datasets)} datasets",
                 f"{undescribed}")
    units = {"particles/position": "m", "particles/velocity": "m/s", "particles/stress": "Pa",
             "particles/mean_stress": "Pa", "particles/pressure": "Pa", "particles/density": "kg/m^3",
             "particles/mass": "kg/m" if dim == 2 else "kg", "particles/volume": "m^2" if dim == 2 else "m^3",
             "grid/node/velocity": "m/s", "grid/node/mass": "kg/m" if dim == 2 else "kg"}
    wrong = {k: f[k].attrs["units"] for k in units if k in f and f[k].attrs.get("units", b"").decode() != units[k]}
    checks.check(not wrong, f"{label}: units (SI, 2-D per metre of thickness)", f"{wrong}")
    if "particles/material" in f:
        names = [n.decode().rstrip() for n in f["particles/material"].attrs.get("material_names", [])]
        checks.check(names == materials, f"{label}: material_names {materials}", f"{names}")


def check_csv_files(checks, name, directory, ranks):
    """Every CSV file of the run: one pandas.read_csv(path, comment='#') call gives the header's columns and
    every row; the first '#' line names program, date and ranks."""
    version, _ = expected_build()
    paths = sorted(p for p in os.listdir(directory) if p.endswith(".csv"))
    checks.check({"diagnostics.csv", "run_summary.csv", "timing.csv"} <= set(paths),
                 f"{name}: the CSV files", f"{paths}")
    for file in paths:
        path = os.path.join(directory, file)
        lines = csv_data_lines(path)
        with open(path) as f:
            comments = [line for line in f.read().splitlines() if line.startswith("#")]
        try:
            frame = pd.read_csv(path, comment="#")
        except Exception as error:       # what a user would see
            checks.check(False, f"{name}: {file} reads with pandas.read_csv(path, comment='#')", repr(error))
            continue
        checks.check(list(frame.columns) == lines[0].split(",") and len(frame) == len(lines) - 1 and len(frame) > 0,
                     f"{name}: {file}: pandas reads the header's {len(frame.columns)} columns and all "
                     f"{len(lines) - 1} rows", f"{list(frame.columns)[:4]}, {len(frame)} rows")
        found = re.match(r"# written by flotsam (\S+) \(commit (\S+), (\S*) build\) on (\S+) by (\d+) ranks?",
                         comments[0] if comments else "")
        checks.check(found is not None and found.group(1) == version and known_commit(found.group(2)) and
                     parse_date(found.group(4)) is not None and int(found.group(5)) == ranks,
                     f"{name}: {file}: the first comment names flotsam {version}, its commit, the date and "
                     f"{ranks} ranks", comments[0] if comments else "no comment line")
        checks.check(any(line.startswith("# units:") for line in comments), f"{name}: {file}: a units line")


def check_scene_file(checks, name, directory, scene):
    """<output>/scene.nml: comment lines, then the resolved scene (returned, as the HDF5 files hold it)."""
    path = os.path.join(directory, "scene.nml")
    if not checks.check(os.path.exists(path), f"{name}: scene.nml written"):
        return None
    with open(path) as f:
        lines = f.read().split("\n")
    body = "\n".join(lines[next(k for k, line in enumerate(lines) if line.startswith("&")):])
    checks.check(all(line.startswith("!") or not line.strip() for line in lines[:lines.index(body.split("\n")[0])])
                 and f"from scene {scene}" in "\n".join(lines[:5]),
                 f"{name}: scene.nml starts with comments naming the scene file {os.path.basename(scene)}")
    return body


def check_xdmf_precision(checks, name, directory, precision, integers=None):
    """Every HDF data item of the XDMF files declares the precision of its dataset (floats: `precision`
    bytes, except the positions, always 8); also the dtype of the dataset it points to."""
    wrong = []
    for xmf in ["particles.xmf", "grid.xmf"]:
        root = ElementTree.parse(os.path.join(directory, xmf)).getroot()
        for item in root.iter("DataItem"):
            if item.get("Format") != "HDF":
                continue
            file, dataset = item.text.split(":")
            with h5py.File(os.path.join(directory, file)) as f:
                dtype = f[dataset].dtype
            declared = (item.get("NumberType"), int(item.get("Precision")))
            actual = ("Int" if dtype.kind == "i" else "Float", dtype.itemsize)
            expected = precision if actual[0] == "Float" and not dataset.endswith("position") else actual[1]
            if declared != actual or actual[1] != expected:
                wrong.append((dataset, declared, str(dtype)))
    checks.check(not wrong, f"{name}: XDMF items declare the type and precision of their datasets "
                 f"(floats {precision} bytes, positions 8)", f"{wrong[:4]}")


def check_single_precision(checks, flotsam, scenes):
    """The 2-D run again with field_precision = 'single' and three particle fields, against the double run."""
    name, reference = "two_materials_single", flotsam.path("two_materials_2d")
    flotsam.remove(name)
    scene = flotsam.scene(os.path.join(scenes, "two_materials_2d.nml"), name + ".nml", name,
                          field_precision="'single'", particle_fields="'Velocity, pressure,material'")
    result = flotsam.run(scene, 3)
    if not checks.check(result.returncode == 0, f"{name}: run on 3 ranks", result.stderr[-2000:]):
        return
    directory = flotsam.path(name)
    checks.check(csv_data_lines(os.path.join(directory, "diagnostics.csv")) ==
                 csv_data_lines(os.path.join(reference, "diagnostics.csv")),
                 f"{name}: diagnostics rows bit for bit those of the double run (output precision only)")
    rows = read_diagnostics(directory)
    half_ulp = 2.0 ** -24
    sizes = [0, 0]
    for index in range(len(rows)):
        label = f"{name} output {index}"
        single_path = os.path.join(directory, "fields", f"fields_{index:06d}.h5")
        double_path = os.path.join(reference, "fields", f"fields_{index:06d}.h5")
        sizes[0] += os.path.getsize(single_path)
        sizes[1] += os.path.getsize(double_path)
        with h5py.File(single_path) as s, h5py.File(double_path) as d:
            checks.check(set(s["particles"]) == {"position", "connectivity", "velocity", "pressure", "material"},
                         f"{label}: only position, connectivity and the chosen velocity, pressure, material",
                         f"{sorted(s['particles'])}")
            checks.check(s["particles/position"].dtype == np.float64 and
                         np.array_equal(s["particles/position"][:], d["particles/position"][:]),
                         f"{label}: positions double, equal to the double run's")
            reals = [k for k in ["particles/velocity", "particles/pressure"]] + \
                    [f"grid/node/{k}" for k in s["grid/node"]] + [f"grid/cell/{k}" for k in s["grid/cell"]]
            for key in reals:
                single, double = s[key][:], d[key][:]
                finite = np.isfinite(double)
                ok = single.dtype == np.float32 and single.shape == double.shape and \
                    np.array_equal(np.isfinite(single), finite) and \
                    np.all(np.abs(single[finite].astype(np.float64) - double[finite]) <= half_ulp * np.abs(double[finite]))
                checks.check(ok, f"{label}: {key} float32, within float32 rounding (2^-24 relative) of the double run",
                             f"{single.dtype}, largest relative difference "
                             f"{np.max(np.abs(single[finite] - double[finite]) / np.maximum(np.abs(double[finite]), 1e-300)):.3g}")
            checks.check(s["particles/material"].dtype == np.int32 and
                         np.array_equal(s["particles/material"][:], d["particles/material"][:]),
                         f"{label}: material numbers as in the double run")
    checks.check(sizes[0] < 0.7 * sizes[1], f"{name}: fields files {sizes[0]} bytes against {sizes[1]} in double "
                 f"({sizes[0] / sizes[1]:.2f})")
    check_xdmf_precision(checks, name, directory, 4)
    with meshio.xdmf.TimeSeriesReader(os.path.join(directory, "particles.xmf")) as reader:
        reader.read_points_cells()
        _, point_data, _ = reader.read_data(reader.num_steps - 1)
        checks.check(set(point_data) == {"position", "velocity", "pressure", "material"} and
                     point_data["pressure"].dtype == np.float32,
                     f"{name} particles.xmf: meshio reads the three arrays and the positions, pressure as float32",
                     f"{ {k: str(v.dtype) for k, v in point_data.items()} }")

    # a continuation may not change the fields; one with a later end_time keeps the previous scene.nml
    with open(os.path.join(directory, "scene.nml")) as f:
        before = f.read()
    result = flotsam.run(scene, 3, "--set", "&run field_precision = 'double' /", "--restart", "latest")
    errors = [line for line in result.stderr.splitlines() if "flotsam: error:" in line]
    with open(os.path.join(directory, "scene.nml")) as f:
        checks.check(result.returncode == 2 and len(errors) == 1 and "field_precision" in errors[0] and
                     f.read() == before, f"{name}: a restart that changes field_precision is refused (status 2), "
                     "scene.nml unchanged", f"{result.returncode}: {errors}")
    result = flotsam.run(scene, 3, "--set", "&run end_time = 0.12 /", "--restart", "latest")
    if checks.check(result.returncode == 0, f"{name}: continued to a later end_time", result.stderr[-2000:]):
        kept = os.path.join(directory, "scene_1.nml")
        with open(os.path.join(directory, "scene.nml")) as f:
            now = f.read()
        checks.check(os.path.exists(kept) and open(kept).read() == before,
                     f"{name}: the previous scene.nml kept as scene_1.nml")
        checks.check("end_time = 0.12\n" in now and "continued from" in now and "scene_1.nml" in now and
                     now.split("&run", 1)[1].replace("0.12", "0.1", 1) == before.split("&run", 1)[1],
                     f"{name}: scene.nml: the new end_time, where it continues, nothing else changed")
        with open(os.path.join(directory, "diagnostics.csv")) as f:
            continued = [line for line in f if line.startswith("# continued from the checkpoint at step")]
        after = read_diagnostics(directory)
        checks.check(len(continued) == 1 and len(after) == len(rows) + 1 and float(after[-1]["time"]) == 0.12 and
                     int(after[-1]["step"]) > int(after[-2]["step"]),
                     f"{name}: diagnostics.csv continues with one '#' line and one row, at t = 0.12",
                     f"{continued}, rows {[(r['time'], r['step']) for r in after[len(rows) - 1:]]}")


PHASES = ["particles_to_grid", "grid_update", "walls", "stabilization", "grid_to_particles", "constitutive",
          "inflow", "node_halo", "migration", "sort", "time_step", "health_check", "diagnostics", "output",
          "checkpoint", "rebalance", "volume_correction", "loads", "other"]


def check_timing(checks, name, directory, smoothed):
    """timing.csv against run_summary.csv (docs/output.md)."""
    with open(os.path.join(directory, "timing.csv"), newline="") as f:
        rows = {row["phase"]: row for row in csv.DictReader(line for line in f if not line.startswith("#"))}
    with open(os.path.join(directory, "run_summary.csv"), newline="") as f:
        summary = next(csv.DictReader(line for line in f if not line.startswith("#")))
    if not checks.check(list(rows) == PHASES + ["total"], f"{name} timing.csv: one row per phase and the total",
                        f"{list(rows)}"):
        return
    mean = {phase: float(row["seconds_mean"]) for phase, row in rows.items()}
    largest = {phase: float(row["seconds_max"]) for phase, row in rows.items()}
    checks.check(all(0 <= mean[p] <= largest[p] for p in PHASES), f"{name} timing.csv: 0 <= mean <= max")
    checks.close(sum(mean[p] for p in PHASES), mean["total"], 1e-9, f"{name} timing.csv: phases add up to the total")
    wall = float(summary["wall_seconds"])
    checks.check(0.5 * wall <= largest["total"] <= wall + 0.05, f"{name} timing.csv: total within the run's wall time",
                 f"{largest['total']} s of {wall} s")
    checks.check(mean["particles_to_grid"] > 0 and mean["grid_to_particles"] > 0, f"{name} timing.csv: the transfers")
    if not smoothed:
        # two clock reads per step; the margin is for the rank being descheduled between them on a busy machine
        checks.check(largest["stabilization"] < 0.01 * largest["total"] + 0.005,
                     f"{name} timing.csv: no smoothing, no time for it",
                     f"{largest['stabilization']} s of {largest['total']} s")


def main():
    flotsam_path, mpiexec, scenes, rest = main_arguments()
    checks = Checks()
    flotsam = Flotsam(flotsam_path, mpiexec, "output")
    check_run(checks, flotsam, scenes, "two_materials_2d", 3, fluid_materials=[1], empty_rank=2)
    check_run(checks, flotsam, scenes, "column_3d", 2, fluid_materials=[1])
    check_single_precision(checks, flotsam, scenes)
    if rest:
        check_particle_series(checks, flotsam, scenes, os.path.abspath(rest[0]))

    # the matplotlib script plots the diagnostics of a run
    if rest:
        picture = flotsam.path("diagnostics.png")
        if os.path.exists(picture):
            os.remove(picture)
        result = subprocess.run([sys.executable, os.path.join(rest[0], "plot_diagnostics.py"),
                                 flotsam.path("two_materials_2d"), "-o", picture], capture_output=True, text=True)
        checks.check(result.returncode == 0 and os.path.getsize(picture) > 10000,
                     "plot_diagnostics.py draws the diagnostics", result.stderr[-1000:])
    return checks.summary()


if __name__ == "__main__":
    raise SystemExit(main())
