#!/usr/bin/env pvbatch
"""Render one output step of a Flotsam run to PNG: the particles coloured by mean stress (negative
pressure) with a rainbow colour bar, as in the pressure snapshots of Yang et al. (2017), Fig. 5.

usage: pvbatch scripts/render_step.py <output folder> [--step N | --time T] [-o picture.png]
                                      [--array mean_stress] [--range MIN MAX] [--size W H]

--step N    output number N (0 = initial state; default: the last output)
--time T    the output nearest to simulated time T [s]
--array     any particle array of particles.xmf (default mean_stress [Pa])
--range     fixed colour range (default: the range of the step)
--structures  3-D: draw the scene's &structure boxes, cylinders and spheres in grey (from the run's
            resolved scene.nml)
--camera DX DY DZ  3-D: the camera's direction from the scene's centre (default 1.0 -2.5 1.2: from
            the front, a little above)

Needs Debian's python3-paraview (pvbatch). The output folder must hold particles.xmf (&run
particle_output = .true.)."""

import argparse
import math
import os
import re
import sys

from paraview import simple


def parse():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("run", help="output folder of a run")
    choice = parser.add_mutually_exclusive_group()
    choice.add_argument("--step", type=int, help="output number (0 = initial state)")
    choice.add_argument("--time", type=float, help="simulated time [s]: the nearest output")
    parser.add_argument("-o", "--output", help="PNG to write (default: <run>/step_<N>.png)")
    parser.add_argument("--array", default="mean_stress", help="particle array to colour by")
    parser.add_argument("--range", type=float, nargs=2, metavar=("MIN", "MAX"), help="colour range")
    parser.add_argument("--size", type=int, nargs=2, default=[1200, 700], metavar=("W", "H"), help="pixels")
    parser.add_argument("--structures", action="store_true", help="3-D: draw the scene's structures")
    parser.add_argument("--camera", type=float, nargs=3, default=[1.0, -2.5, 1.2], metavar=("DX", "DY", "DZ"),
                        help="3-D: camera direction from the centre")
    return parser.parse_args()


def structures(run):
    """The &structure groups of the run's resolved scene.nml (one variable per line) as dicts."""
    text = open(os.path.join(run, "scene.nml")).read()
    found = []
    for group in re.findall(r"^&structure\n(.*?)^/", text, re.MULTILINE | re.DOTALL):
        values = {}
        for name, value in re.findall(r"^\s*(\w+) = (.*)$", group, re.MULTILINE):
            value = value.strip()
            values[name] = value.strip("'") if value.startswith("'") else [float(v) for v in value.split(",") if v.strip()]
        found.append(values)
    return found


def rotation_onto(vector, target):
    """(angle in degrees, axis) of the rotation taking vector onto target (both 3-vectors)."""
    a = [c / math.sqrt(sum(x * x for x in vector)) for c in vector]
    b = [c / math.sqrt(sum(x * x for x in target)) for c in target]
    axis = [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
    sine = math.sqrt(sum(c * c for c in axis))
    cosine = sum(x * y for x, y in zip(a, b))
    if sine < 1e-12:
        return (0.0 if cosine > 0 else 180.0), ([1.0, 0.0, 0.0] if abs(a[0]) < 0.9 else [0.0, 1.0, 0.0])
    return math.degrees(math.atan2(sine, cosine)), axis


def show_structures(run, view):
    """Grey, opaque sources for the 3-D structures (box, cylinder, sphere) of the run's scene."""
    for structure in structures(run):
        shape = structure.get("shape", "box")
        centre = structure["centre"]
        if shape == "box":
            source = simple.Box(Center=[0.0, 0.0, 0.0], XLength=structure["size"][0],
                                YLength=structure["size"][1], ZLength=structure["size"][2])
            angle, axis = structure["rotation"][0], structure["rotation_axis"]
        elif shape == "cylinder":              # VTK's cylinder lies along y
            source = simple.Cylinder(Center=[0.0, 0.0, 0.0], Radius=structure["radius"][0],
                                     Height=structure["length"][0], Resolution=48)
            angle, axis = rotation_onto([0.0, 1.0, 0.0], structure["axis"])
        elif shape == "sphere":
            source = simple.Sphere(Center=[0.0, 0.0, 0.0], Radius=structure["radius"][0],
                                   ThetaResolution=48, PhiResolution=24)
            angle, axis = 0.0, [0.0, 0.0, 1.0]
        else:
            print(f"render_step: structure '{structure.get('name')}' ({shape}) not drawn", file=sys.stderr)
            continue
        turned = simple.Transform(Input=source)
        turned.Transform = "Transform"
        turned.Transform.Translate = centre
        if angle:
            # VTK turns about x, y, z in turn; one turn about an arbitrary axis as a rotation vector is
            # not offered, so put the axis turn into a vtkTransform
            from vtkmodules.vtkCommonTransforms import vtkTransform
            matrix = vtkTransform()
            matrix.RotateWXYZ(angle, *axis)
            turned.Transform.Rotate = list(matrix.GetOrientation())
        display = simple.Show(turned, view)
        display.AmbientColor = display.DiffuseColor = [0.55, 0.55, 0.55]


def main():
    arguments = parse()
    run = os.path.abspath(arguments.run)   # Xdmf3 resolves relative data paths from the file's folder
    xdmf = os.path.join(run, "particles.xmf")
    if not os.path.exists(xdmf):
        sys.exit(f"render_step: no {xdmf} (was the run written with particle_output = .true.?)")

    reader = simple.Xdmf3ReaderS(FileName=[xdmf])
    times = reader.TimestepValues
    times = [float(t) for t in times] if hasattr(times, "__len__") else [float(times)]
    if arguments.step is not None:
        if not 0 <= arguments.step < len(times):
            sys.exit(f"render_step: --step {arguments.step}: the run has outputs 0 .. {len(times) - 1}")
        step = arguments.step
    elif arguments.time is not None:
        step = min(range(len(times)), key=lambda k: abs(times[k] - arguments.time))
    else:
        step = len(times) - 1
    time = times[step]
    output = arguments.output or os.path.join(run, f"step_{step:06d}.png")

    view = simple.CreateView("RenderView")
    view.ViewSize = arguments.size
    view.OrientationAxesVisibility = 0
    if hasattr(view, "UseColorPaletteForBackground"):
        view.UseColorPaletteForBackground = 0
    view.Background = [1.0, 1.0, 1.0]
    view.ViewTime = time
    reader.UpdatePipeline(time)

    bounds = reader.GetDataInformation().GetBounds()
    flat = bounds[4] == bounds[5]
    # discs of the particle spacing: the particles read as a continuum, as in the paper's figures
    volume = reader.PointData["volume"].GetRange()[1]
    spacing = volume ** (0.5 if flat else 1.0 / 3.0)
    display = simple.Show(reader, view)
    display.SetRepresentationType("Point Gaussian")
    display.ShaderPreset = "Plain circle"
    display.GaussianRadius = 0.5 * spacing
    simple.ColorBy(display, ("POINTS", arguments.array))
    colours = simple.GetColorTransferFunction(arguments.array)
    colours.ApplyPreset("Jet", True)
    if arguments.range:
        colours.RescaleTransferFunction(*arguments.range)
    else:
        display.RescaleTransferFunctionToDataRange(False, True)
    bar = simple.GetScalarBar(colours, view)
    bar.Title = "mean stress [Pa]" if arguments.array == "mean_stress" else arguments.array
    bar.ComponentTitle = ""
    bar.TitleColor = bar.LabelColor = [0.0, 0.0, 0.0]
    display.SetScalarBarVisibility(view, True)

    label = simple.Text(Text=f"t = {time:.4g} s   (output {step})")
    label_display = simple.Show(label, view)
    label_display.Color = [0.0, 0.0, 0.0]
    label_display.WindowLocation = "Upper Left Corner"

    centre = [(bounds[0] + bounds[1]) / 2, (bounds[2] + bounds[3]) / 2, (bounds[4] + bounds[5]) / 2]
    if flat:                         # 2-D: look at the x-y plane
        view.InteractionMode = "2D"
        view.CameraPosition = [centre[0], centre[1], centre[2] + 10.0]
        view.CameraFocalPoint = centre
        view.CameraViewUp = [0.0, 1.0, 0.0]
    else:                            # 3-D: from the front, a little above, z up
        if arguments.structures:
            show_structures(run, view)
        d = arguments.camera
        view.CameraPosition = [centre[0] + d[0], centre[1] + d[1], centre[2] + d[2]]
        view.CameraFocalPoint = centre
        view.CameraViewUp = [0.0, 0.0, 1.0]
    view.ResetCamera()
    simple.SaveScreenshot(output, view, ImageResolution=arguments.size)
    print(output)


if __name__ == "__main__":
    main()
