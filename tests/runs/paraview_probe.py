"""Run by pvbatch (tests/runs/check_paraview.py): open the XDMF files of a run with ParaView's Xdmf3
reader and print what ParaView sees as one JSON line prefixed `PROBE `.

usage: pvbatch paraview_probe.py <output folder>"""

import json
import os
import sys

from paraview import simple


def arrays(data):
    return {data[name].Name: data[name].GetNumberOfComponents() for name in data.keys()}


def main():
    run = os.path.abspath(sys.argv[1])   # Xdmf3 resolves relative file names wrongly unless opened by absolute path
    seen = {}
    for kind in ["particles", "grid"]:
        reader = simple.Xdmf3ReaderS(FileName=[os.path.join(run, kind + ".xmf")])
        times = [float(t) for t in reader.TimestepValues]
        steps = []
        for time in times:
            reader.UpdatePipeline(time)
            info = reader.GetDataInformation()
            steps.append({"time": time, "points": info.GetNumberOfPoints(), "cells": info.GetNumberOfCells(),
                          "bounds": list(info.GetBounds())})
        seen[kind] = {"times": times, "steps": steps, "point_arrays": arrays(reader.PointData),
                      "cell_arrays": arrays(reader.CellData)}
        if kind == "particles":
            seen[kind]["mean_stress_range"] = list(reader.PointData["mean_stress"].GetRange())
    print("PROBE " + json.dumps(seen), flush=True)


main()
