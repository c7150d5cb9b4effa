"""Run by pvbatch (tests/runs/check_paraview.py): open the XDMF files of a run with ParaView's Xdmf3
reader, show each in a render view as a surface and step the view through the outputs, and print what
the representation holds at each time (what is drawn: points, cells, bounds, array ranges) as one JSON
line prefixed `PROBE `. Reading through the reader alone (`UpdatePipeline`) is not enough: the
render view asks for the extent the reader announced before reading, which is where a series of
structured grids whose box moves went wrong (docs/output.md). Needs an X display.

usage: pvbatch paraview_probe.py <output folder>"""

import json
import math
import os
import sys

from paraview import simple


def arrays(data):
    return {data[name].Name: data[name].GetNumberOfComponents() for name in data.keys()}


def ranges(attributes):
    """Range of each array's first component, None where it holds no finite value (JSON has no NaN)."""
    found = {}
    for k in range(attributes.GetNumberOfArrays()):
        array = attributes.GetArrayInformation(k)
        if array.GetName().startswith("vtk"):          # vtkCompositeIndex etc., added by ParaView
            continue
        low, high = array.GetComponentRange(0)
        found[array.GetName()] = [low, high] if math.isfinite(low) and math.isfinite(high) else None
    return found


def main():
    run = os.path.abspath(sys.argv[1])   # Xdmf3 resolves relative file names wrongly unless opened by absolute path
    seen = {}
    view = simple.CreateView("RenderView")
    view.ViewSize = [400, 300]
    for kind in ["particles", "grid"]:
        reader = simple.Xdmf3ReaderS(FileName=[os.path.join(run, kind + ".xmf")])
        times = [float(t) for t in reader.TimestepValues]
        display = simple.Show(reader, view)
        display.SetRepresentationType("Surface")
        steps = []
        for time in times:
            view.ViewTime = time
            simple.Render(view)
            info = display.GetRepresentedDataInformation()
            steps.append({"time": time, "points": info.GetNumberOfPoints(), "cells": info.GetNumberOfCells(),
                          "bounds": list(info.GetBounds()), "point_ranges": ranges(info.GetPointDataInformation()),
                          "cell_ranges": ranges(info.GetCellDataInformation())})
        simple.Hide(reader, view)
        seen[kind] = {"times": times, "steps": steps, "point_arrays": arrays(reader.PointData),
                      "cell_arrays": arrays(reader.CellData)}
        if kind == "particles":
            reader.UpdatePipeline(times[-1])
            seen[kind]["mean_stress_range"] = list(reader.PointData["mean_stress"].GetRange())
    print("PROBE " + json.dumps(seen), flush=True)


main()
