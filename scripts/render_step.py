#!/usr/bin/env pvbatch
"""Render one output step of a Flotsam run to PNG: the particles coloured by mean stress (negative
pressure) with a rainbow colour bar, as in the pressure snapshots of Yang et al. (2017), Fig. 5.

usage: pvbatch scripts/render_step.py <output folder> [--step N | --time T] [-o picture.png]
                                      [--array mean_stress] [--range MIN MAX] [--size W H]

--step N    output number N (0 = initial state; default: the last output)
--time T    the output nearest to simulated time T [s]
--array     any particle array of particles.xmf (default mean_stress [Pa])
--range     fixed colour range (default: the range of the step)

Needs Debian's python3-paraview (pvbatch). The output folder must hold particles.xmf (&run
particle_output = .true.)."""

import argparse
import os
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
    return parser.parse_args()


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
        view.CameraPosition = [centre[0] + 1.0, centre[1] - 2.5, centre[2] + 1.2]
        view.CameraFocalPoint = centre
        view.CameraViewUp = [0.0, 0.0, 1.0]
    view.ResetCamera()
    simple.SaveScreenshot(output, view, ImageResolution=arguments.size)
    print(output)


if __name__ == "__main__":
    main()
