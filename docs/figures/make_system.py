"""A ParaView picture of any system run directory (``simulate(system, t_end, out=DIR)``):

    xvfb-run -a -s "-screen 0 1280x1024x24" pvpython docs/figures/make_system.py DIR PNG \\
        [--time T] [--floor Z] [--floor-axis {x,y,z}] [--floor-size HALF] [--camera X Y Z] \\
        [--focus X Y Z] [--up X Y Z] [--dolly D] [--curvature-max K] [--size W H]

Every rod folder's rod.xdmf (each subfolder of DIR holding one) as a tube of
its true radius coloured by its curvature [1/m], the bodies of bodies.xdmf,
and, with --floor, the plane z = Z (global; or x, y = Z by --floor-axis) as
a floor. The camera looks from
--camera at --focus (global, m), --up upwards; ParaView then fits everything in
view and --dolly moves it closer. The frame shown is the one at or before T [s]
(default: the last). docs/systems.md, "Pictures of the examples", gives the
command lines of its pictures (the octopus, the parallel robot, ...).
"""

import argparse
import glob
import os

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

parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
parser.add_argument("directory")
parser.add_argument("png")
parser.add_argument("--time", type=float, help="the time shown [s]; default: the run's last frame")
parser.add_argument("--floor", type=float, help="draw the floor z = FLOOR [m], global (or the axis given)")
parser.add_argument("--floor-axis", choices="xyz", default="z", help="the floor's normal: a global axis")
parser.add_argument("--floor-size", type=float, default=0.3, help="its half width about the focus [m]")
parser.add_argument("--camera", type=float, nargs=3, default=(1.0, -1.5, 0.8), help="the camera's position [m]")
parser.add_argument("--focus", type=float, nargs=3, default=(0.0, 0.0, 0.0), help="focal point [m]")
parser.add_argument("--up", type=float, nargs=3, default=(0.0, 0.0, 1.0), help="the picture's up direction")
parser.add_argument("--dolly", type=float, default=1.0, help="move the camera closer by this factor")
parser.add_argument("--curvature-max", type=float, help="the colour scale's top [1/m]; default: the largest")
parser.add_argument("--size", type=int, nargs=2, default=(1000, 600), help="width and height [px]")
args = parser.parse_args()

directory = os.path.abspath(args.directory)  # ParaView 5.11 needs absolute XDMF paths
rods = sorted(glob.glob(os.path.join(directory, "*", "rod.xdmf")))
if not rods:
    raise SystemExit(f"no rod folder (*/rod.xdmf) in {directory}: is it a system run directory?")

view = CreateView("RenderView")
view.ViewSize = list(args.size)
view.OrientationAxesVisibility = 0
LoadPalette("WhiteBackground")

readers, tubes = [], []  # each rod's reader and tube filter
for path in rods:
    rod = Xdmf3ReaderS(registrationName=os.path.basename(os.path.dirname(path)), FileName=[path])
    readers.append(rod)
    tube = Tube(Input=ExtractSurface(Input=rod))
    tube.Scalars = ["POINTS", "radius [m]"]
    tube.VaryRadius = "By Absolute Scalar"
    tube.NumberofSides = 24
    tubes.append(tube)
    ColorBy(Show(tube, view), ("POINTS", "curvature [1/m]", "Magnitude"))
times = list(readers[0].TimestepValues) or [0.0]
t = times[-1] if args.time is None else max([s for s in times if s <= args.time + 1e-9] or times[:1])
view.ViewTime = t

bodies = os.path.join(directory, "bodies.xdmf")
if os.path.exists(bodies):
    Show(Xdmf3ReaderS(registrationName="bodies", FileName=[bodies]), view).DiffuseColor = [0.85, 0.5, 0.35]
if args.floor is not None:
    normal, half = "xyz".index(args.floor_axis), args.floor_size
    a, b = [k for k in range(3) if k != normal]
    corners = []
    for da, db in ((-1, -1), (1, -1), (-1, 1)):
        corner = list(args.focus)
        corner[normal], corner[a], corner[b] = args.floor, corner[a] + da * half, corner[b] + db * half
        corners.append(corner)
    plane = Plane(registrationName="floor", Origin=corners[0], Point1=corners[1], Point2=corners[2])
    ground = Show(plane, view)
    ground.DiffuseColor, ground.Opacity = [0.76, 0.70, 0.55], 0.8
Show(Text(registrationName="time", Text=f"t = {t:.2f} s"), view).FontSize = 14

view.CameraPosition, view.CameraFocalPoint = list(args.camera), list(args.focus)
view.CameraViewUp = list(args.up)
Render(view)
view.ResetCamera()
view.GetActiveCamera().Dolly(args.dolly)  # closer than ParaView's fit of everything
curvature = GetColorTransferFunction("curvature [1/m]")
top = args.curvature_max
if top is None:  # the largest at the time shown, not at the first frame (often straight)
    for tube in tubes:
        tube.UpdatePipeline(t)
    top = max(tube.PointData["curvature [1/m]"].GetRange(-1)[1] for tube in tubes) or 1.0
curvature.RescaleTransferFunction(0.0, top)
Render(view)
SaveScreenshot(args.png, view, ImageResolution=list(args.size))
