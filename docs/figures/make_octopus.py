"""The octopus picture of docs/systems.md, drawn by ParaView from the run's views:

    python examples/octopus.py out/octopus
    xvfb-run -a -s "-screen 0 1280x1024x24" pvpython docs/figures/make_octopus.py out/octopus \\
        docs/figures/octopus.png 8.0

Each arm's rod.xdmf as a tube of its true radius coloured by its curvature,
the head from bodies.xdmf, the sea floor as a plane.
"""

import os
import sys

from paraview.simple import (
    ColorBy,
    CreateView,
    ExtractSurface,
    GetColorTransferFunction,
    LoadPalette,
    Plane,
    Render,
    SaveScreenshot,
    Show,
    Text,
    Tube,
    Xdmf3ReaderS,
)

directory, png = os.path.abspath(sys.argv[1]), sys.argv[2]
t = float(sys.argv[3]) if len(sys.argv) > 3 else 8.0
FLOOR = float(sys.argv[4]) if len(sys.argv) > 4 else -0.0922  # examples/octopus.py's FLOOR [m]
view = CreateView("RenderView")
view.ViewSize = [1200, 700]
view.OrientationAxesVisibility = 0
view.ViewTime = t
LoadPalette("WhiteBackground")

for i in range(1, 9):
    arm = Xdmf3ReaderS(registrationName=f"arm{i}", FileName=[f"{directory}/arm{i}/rod.xdmf"])
    tube = Tube(Input=ExtractSurface(Input=arm))
    tube.Scalars = ["POINTS", "radius [m]"]
    tube.VaryRadius = "By Absolute Scalar"
    tube.NumberofSides = 24
    shown = Show(tube, view)
    ColorBy(shown, ("POINTS", "curvature [1/m]", "Magnitude"))
curvature = GetColorTransferFunction("curvature [1/m]")
curvature.RescaleTransferFunction(0.0, 15.0)

head = Show(Xdmf3ReaderS(registrationName="head", FileName=[directory + "/bodies.xdmf"]), view)
head.DiffuseColor = [0.85, 0.5, 0.35]
floor = Plane(registrationName="floor", Origin=[-0.55, -0.55, FLOOR], Point1=[0.6, -0.55, FLOOR],
              Point2=[-0.55, 0.55, FLOOR])
ground = Show(floor, view)
ground.DiffuseColor, ground.Opacity = [0.76, 0.70, 0.55], 0.8
Show(Text(registrationName="time", Text=f"t = {t:.2f} s"), view).FontSize = 14

view.CameraPosition = [0.55, -0.75, 0.42]
view.CameraFocalPoint = [0.02, 0.0, -0.06]
view.CameraViewUp = [0.0, 0.0, 1.0]
Render(view)
view.ResetCamera()
view.GetActiveCamera().Dolly(1.7)  # closer than ParaView's fit of everything
Render(view)
SaveScreenshot(png, view, ImageResolution=[1200, 700])
