#!/usr/bin/python3
"""Read the particle time series of a Flotsam run (particles.xmf) step by step, each step with its own
particles: the count changes with inflow, while meshio's TimeSeriesReader gives the points of the
first step only (read_points_cells) next to each step's arrays (read_data).

    import sys; sys.path.insert(0, "scripts")          # this folder
    from particle_series import particle_steps
    for time, mesh in particle_steps("output/floating_block"):
        x = mesh.points                  # (N, 3) positions of this output [m]
        p = -mesh.point_data["mean_stress"]
        ...

Each step is a meshio.Mesh: points, one vertex cell per particle, and every array of particles.xmf as
point data (`position` too). Built on meshio's own reader, so it reads what ParaView reads.

usage (a summary per output): /usr/bin/python3 scripts/particle_series.py <output folder or particles.xmf>"""

import os
import sys

import meshio
import numpy as np


def particle_steps(run):
    """Yield (time [s], meshio.Mesh) for every output of `run` (an output folder or its particles.xmf)."""
    path = os.path.join(run, "particles.xmf") if os.path.isdir(run) else run
    with meshio.xdmf.TimeSeriesReader(path) as reader:
        reader.read_points_cells()        # meshio needs it before read_data; the points are the first step's
        for k in range(reader.num_steps):
            time, point_data, _ = reader.read_data(k)
            if "position" not in point_data:
                raise ValueError(f"{path}: no array 'position' (written by Flotsam since issue 14); "
                                 "read the fields files with h5py instead")
            points = point_data["position"]
            cells = [meshio.CellBlock("vertex", np.arange(len(points)).reshape(-1, 1))]
            yield time, meshio.Mesh(points, cells, point_data=point_data)


def main():
    if len(sys.argv) != 2 or sys.argv[1] in ("-h", "--help"):
        sys.exit(__doc__)
    print("output,time,particles,x_min,x_max,y_min,y_max,z_min,z_max")
    for k, (time, mesh) in enumerate(particle_steps(sys.argv[1])):
        if len(mesh.points):
            low, high = mesh.points.min(axis=0), mesh.points.max(axis=0)
            bounds = ",".join(f"{float(a)!r},{float(b)!r}" for a, b in zip(low, high))
        else:
            bounds = ",,,,,"
        print(f"{k},{time!r},{len(mesh.points)},{bounds}")


if __name__ == "__main__":
    main()
