#!/usr/bin/python3
"""Crowding of a 2-D fluid measured without the grid: each particle's Voronoi area against its volume.

    scripts/crowding_map.py OUTPUT_DIR [--walls x_min,x_max,y_min] [--bands 0.4] [--columns 4] [--at -1]

For every fluid particle of one output (the last by default) the area of its Voronoi cell A_p is
compared with its volume V_p = m_p / rho_p: A_p / V_p - 1 < 0 where particles crowd (they occupy less
area than their volumes say), > 0 where they spread. Walls are closed by mirroring the particles
across them (`--walls`, in the tank frame of the output, e.g. 0,3.2,0 for the hydrostatic tank; an
empty entry leaves that side open). Surface particles have open or huge cells and are left out of the
map (an unbounded cell, or A_p > 4 V_p: a cell reaching into the air); the particles just below them are
in it. A region's figure is sum A_p / sum V_p - 1 over its particles (a disordered fluid has small and
large cells side by side; the ratio of the sums is the region's occupied area against its volume).

This is the independent check of the nodal occupancy that `volume_correction = 'shifting'` uses
(docs/volume-conservation.md): the occupancy sums N_i V_p over a node's support, so it cannot see
crowding finer than a cell, nor under a free surface; the Voronoi area sees both.
Needs Debian's python3-numpy, python3-h5py and python3-scipy.
"""
import argparse
import glob
import os
import sys

import h5py
import numpy as np

try:
    from scipy.spatial import Voronoi
except ImportError:
    sys.exit("crowding_map.py: needs scipy (Debian: apt-get install python3-scipy; run with /usr/bin/python3)")


def polygon_area(points):
    x, y = points[:, 0], points[:, 1]
    return 0.5 * abs(np.dot(x, np.roll(y, 1)) - np.dot(y, np.roll(x, 1)))


def voronoi_ratio(x, volume, walls):
    """A_p / V_p per particle (nan for unbounded cells), walls closed by mirror images."""
    images = [x]
    x_min, x_max, y_min = walls
    if x_min is not None:
        images.append(np.column_stack([2 * x_min - x[:, 0], x[:, 1]]))
    if x_max is not None:
        images.append(np.column_stack([2 * x_max - x[:, 0], x[:, 1]]))
    if y_min is not None:
        images.append(np.column_stack([x[:, 0], 2 * y_min - x[:, 1]]))
    diagram = Voronoi(np.vstack(images))
    ratio = np.full(len(x), np.nan)
    for p in range(len(x)):
        region = diagram.regions[diagram.point_region[p]]
        if region and -1 not in region:
            ratio[p] = polygon_area(diagram.vertices[region]) / volume[p]
    return ratio


def crowding(folder, walls, at=-1, fluid_material=1):
    """(time, positions, A_p/V_p with surface particles as nan) of one output of `folder`."""
    files = sorted(glob.glob(os.path.join(folder, "fields", "fields_*.h5")))
    if not files:
        sys.exit("crowding_map.py: no fields/fields_*.h5 in %s" % folder)
    with h5py.File(files[at], "r") as f:
        time = float(f.attrs["time"])
        fluid = f["particles/material"][:] == fluid_material
        x = f["particles/position"][:][fluid][:, :2]
        volume = f["particles/volume"][:][fluid]
    ratio = voronoi_ratio(x, volume, walls)
    ratio[ratio > 4.0] = np.nan          # free-surface particles: their cells reach into the air
    return time, x, volume, ratio


def table(x, volume, ratio, band, columns):
    """Rows of (band low, band high, [sum A / sum V - 1 per column]) from the bottom up."""
    lo, hi = x[:, 0].min(), x[:, 0].max() + 1e-12
    edges = np.linspace(lo, hi, columns + 1)
    rows = []
    for y0 in np.arange(0.0, x[:, 1].max() + band, band):
        in_band = (x[:, 1] >= y0) & (x[:, 1] < y0 + band) & np.isfinite(ratio)
        cells = []
        for c in range(columns):
            sel = in_band & (x[:, 0] >= edges[c]) & (x[:, 0] < edges[c + 1])
            cells.append((ratio[sel] * volume[sel]).sum() / volume[sel].sum() - 1.0 if sel.any() else np.nan)
        if in_band.any():
            rows.append((y0, y0 + band, cells))
    return rows


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("folder")
    parser.add_argument("--walls", default="0,3.2,0", help="x_min,x_max,y_min of the mirroring walls ('' = open)")
    parser.add_argument("--bands", type=float, default=0.4, help="height of a band [m]")
    parser.add_argument("--columns", type=int, default=4)
    parser.add_argument("--at", type=int, default=-1, help="output index (default: the last)")
    args = parser.parse_args()
    walls = [float(w) if w.strip() else None for w in args.walls.split(",")]
    if len(walls) != 3:
        sys.exit("crowding_map.py: --walls takes x_min,x_max,y_min")
    time, x, volume, ratio = crowding(args.folder, walls, args.at)
    finite = np.isfinite(ratio)
    print("%s  t = %.3f s  %d particles mapped, %d at the surface left out" %
          (args.folder, time, finite.sum(), (~finite).sum()))
    print("sum A / sum V - 1 of the mapped particles: %+.2f %%" %
          (100 * ((ratio[finite] * volume[finite]).sum() / volume[finite].sum() - 1)))
    for y0, y1, cells in reversed(table(x, volume, ratio, args.bands, args.columns)):
        print("  y %5.2f-%5.2f  " % (y0, y1) + "  ".join("%+6.1f %%" % (100 * c) for c in cells))


if __name__ == "__main__":
    main()
