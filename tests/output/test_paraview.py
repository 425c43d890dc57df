"""ParaView itself opens the outputs and draws the tapered body (pvpython under xvfb-run):
the streamed XDMF views (moving geometry across chunk files, all arrays) and the
.pvd/.vtp series.

Skipped when ``pvpython`` or ``xvfb-run`` is missing (Debian: ``apt-get install
paraview xvfb xauth``). ParaView 5.11 needs an X display to render; its
``--force-offscreen-rendering`` alone crashes on the Debian build.
"""

import json
import shutil
import textwrap

import numpy as np
import pytest
import xserver

import rodmol
from rodmol.output.formats import write_series

PVPYTHON, XVFB = shutil.which("pvpython"), shutil.which("xvfb-run")
pytestmark = [pytest.mark.subprocess, pytest.mark.skipif(
    not (PVPYTHON and XVFB), reason="needs pvpython and xvfb-run (apt-get install paraview xvfb xauth)")]

SCRIPT = textwrap.dedent("""
    import json, sys
    from paraview.simple import (ColorBy, CreateView, GetAnimationScene, PVDReader, Render,
                                 SaveScreenshot, Show, Tube)
    directory, png = sys.argv[1], sys.argv[2]
    rod = PVDReader(FileName=directory + "/rod.pvd")
    times = list(rod.TimestepValues)
    scene = GetAnimationScene()
    scene.UpdateAnimationUsingDataTimeSteps()
    scene.AnimationTime = times[-1]
    tube = Tube(Input=rod)
    tube.Scalars = ["POINTS", "radius [m]"]
    tube.VaryRadius = "By Absolute Scalar"
    tube.NumberofSides = 24
    view = CreateView("RenderView")
    view.ViewSize = [640, 400]
    view.OrientationAxesVisibility = 0
    display = Show(tube, view)
    ColorBy(display, ("POINTS", "curvature [1/m]", "Magnitude"))
    view.CameraPosition, view.CameraFocalPoint, view.CameraViewUp = [0.2, 0, 1], [0.2, 0, 0], [0, 1, 0]
    view.ResetCamera()
    Render(view)
    SaveScreenshot(png, view, ImageResolution=[640, 400])
    info = tube.GetDataInformation()
    print(json.dumps(dict(times=times, bounds=list(info.GetBounds()), points=info.GetNumberOfPoints(),
                          arrays=list(rod.PointData.keys()))))
""")


def test_paraview_loads_the_series_and_renders_the_tube(tmp_path):
    model = rodmol.scenarios.get("bending").model(12)
    result = rodmol.simulate(model, 0.1, output_dt=0.05)
    write_series(result, tmp_path, format="vtp")
    script, png = tmp_path / "render.py", tmp_path / "frame.png"
    script.write_text(SCRIPT)
    run = xserver.run([XVFB, *xserver.XVFB_ARGS, PVPYTHON, str(script), str(tmp_path), str(png)], timeout=120)
    assert run.returncode == 0, run.stderr[-2000:]
    report = json.loads(run.stdout.strip().splitlines()[-1])
    np.testing.assert_allclose(report["times"], result.t)
    assert "radius [m]" in report["arrays"] and "curvature [1/m]" in report["arrays"]
    # The tube is as thick as the base section: its extent in z is the base diameter.
    zmin, zmax = report["bounds"][4:]
    assert zmax - zmin == pytest.approx(2 * result.radius[0], rel=0.05)
    assert report["points"] >= 13 * 24  # 24 sides around each of the 13 nodes

    from PIL import Image

    pixels = np.asarray(Image.open(png).convert("RGB"), dtype=float)
    background = pixels[0, 0]
    drawn = np.any(np.abs(pixels - background) > 30, axis=-1).mean()
    assert 0.01 < drawn < 0.9, f"fraction of pixels drawn: {drawn}"


XDMF_SCRIPT = textwrap.dedent("""
    import json, sys
    import numpy as np
    from paraview import servermanager
    from paraview.simple import (CreateView, ExtractSurface, Render, SaveScreenshot, Show, Tube,
                                 Xdmf3ReaderS)
    from vtkmodules.util.numpy_support import vtk_to_numpy
    directory, png = sys.argv[1], sys.argv[2]
    report = {}
    for name in ("rod", "cables", "markers"):
        reader = Xdmf3ReaderS(FileName=[directory + "/" + name + ".xdmf"])
        times = list(reader.TimestepValues)
        frames = []
        for t in (times[0], times[-1]):
            reader.UpdatePipeline(t)
            data = servermanager.Fetch(reader)
            frames.append(vtk_to_numpy(data.GetPoints().GetData()).tolist())
        tension = data.GetCellData().GetArray("tension [N]")
        report[name] = dict(times=times, first=frames[0], last=frames[-1], cells=data.GetNumberOfCells(),
                            arrays=list(reader.PointData.keys()), cell_arrays=list(reader.CellData.keys()),
                            tension=vtk_to_numpy(tension).tolist() if tension else None)
        if name == "rod":
            rod = reader
    tube = Tube(Input=ExtractSurface(Input=rod))
    tube.Scalars = ["POINTS", "radius [m]"]
    tube.VaryRadius = "By Absolute Scalar"
    tube.NumberofSides = 24
    view = CreateView("RenderView")
    view.ViewSize = [640, 400]
    view.ViewTime = report["rod"]["times"][-1]
    display = Show(tube, view)
    display.ColorArrayName = ["POINTS", ""]
    view.ResetCamera()
    Render(view)
    SaveScreenshot(png, view, ImageResolution=[640, 400])
    report["tube_points"] = tube.GetDataInformation().GetNumberOfPoints()
    print(json.dumps(report))
""")


def test_paraview_opens_the_streamed_views_with_moving_geometry(tmp_path):
    from rodmol.output.stream import RunWriter

    model = rodmol.scenarios.get("fetching").model(12)
    out = tmp_path / "run"  # chunks of 4 frames: the views include several fragment files
    result = rodmol.simulate(model, 0.5, output_dt=0.05, out=RunWriter(out, chunk_frames=4))
    script, png = tmp_path / "open.py", tmp_path / "frame.png"
    script.write_text(XDMF_SCRIPT)
    run = xserver.run([XVFB, *xserver.XVFB_ARGS, PVPYTHON, str(script), str(out.resolve()), str(png)],
                      timeout=180)
    assert run.returncode == 0, run.stderr[-2000:]
    report = json.loads(run.stdout.strip().splitlines()[-1])
    rod, cables, markers = report["rod"], report["cables"], report["markers"]
    for view in (rod, cables, markers):
        np.testing.assert_allclose(view["times"], result.t)
    # The geometry moves, and is the result's at the first and the last time.
    np.testing.assert_allclose(rod["first"], result.positions[0], atol=1e-12)
    np.testing.assert_allclose(rod["last"], result.positions[-1], atol=1e-12)
    assert np.abs(result.positions[-1] - result.positions[0]).max() > 0.01
    np.testing.assert_allclose(markers["last"], result.markers[-1], atol=1e-12)
    assert rod["cells"] == 1 and set(rod["arrays"]) >= {
        "radius [m]", "s [m]", "curvature [1/m]", "internal force [N]", "external force [N/m]",
        "velocity (global) [m/s]", "frame x [-]"}
    assert {"tension [N]", "s [m]", "cable index [-]"} <= set(cables["arrays"])
    # Each cable's segments carry its tension at the last time.
    n_cables = result.tensions.shape[1]
    assert set(np.round(cables["tension"], 12)) == set(np.round(result.tensions[-1], 12)) and n_cables > 1
    assert report["tube_points"] >= 13 * 24

    from PIL import Image

    pixels = np.asarray(Image.open(png).convert("RGB"), dtype=float)
    drawn = np.any(np.abs(pixels - pixels[0, 0]) > 30, axis=-1).mean()
    assert 0.01 < drawn < 0.9, f"fraction of pixels drawn: {drawn}"


BODIES_SCRIPT = textwrap.dedent("""
    import json, sys
    from paraview import servermanager
    from paraview.simple import Xdmf3ReaderS
    from vtkmodules.util.numpy_support import vtk_to_numpy
    reader = Xdmf3ReaderS(FileName=[sys.argv[1] + "/bodies.xdmf"])
    times = list(reader.TimestepValues)
    reader.UpdatePipeline(times[-1])
    data = servermanager.Fetch(reader)
    block = data.GetBlock(0) if data.IsA("vtkMultiBlockDataSet") else data
    print(json.dumps(dict(times=times, last=vtk_to_numpy(block.GetPoints().GetData()).tolist(),
                          cells=block.GetNumberOfCells())))
""")


def test_paraview_opens_a_systems_bodies_view_at_the_bodies_poses(tmp_path):
    from rodmol.output.system_files import body_surface
    from rodmol.output.system_stream import SystemRunWriter

    arm = rodmol.Model(rodmol.Rod(0.2, 0.008, rodmol.Material(E=1e5, nu=0.5, mu=300.0, rho=1100.0)), 6)
    head = rodmol.RigidBody(0.3, (2e-4, 3e-4, 4e-4), volume=2e-4)
    system = rodmol.System({"arm": arm}, {"head": head}, [rodmol.Joint(("head", (0.04, 0.0, 0.0)), ("arm", "base"))],
                           medium="water", gravity=(0.0, 0.0, -9.81))
    out = tmp_path / "run"
    result = rodmol.simulate(system, 0.2, output_dt=0.05, out=SystemRunWriter(out, chunk_frames=2))  # 3 chunks
    script = tmp_path / "open.py"
    script.write_text(BODIES_SCRIPT)
    run = xserver.run([XVFB, *xserver.XVFB_ARGS, PVPYTHON, str(script), str(out.resolve())], timeout=180)
    assert run.returncode == 0, run.stderr[-2000:]
    report = json.loads(run.stdout.strip().splitlines()[-1])
    np.testing.assert_allclose(report["times"], result.t)
    points, triangles = body_surface(head)
    body = result["head"]
    assert report["cells"] == len(triangles) and abs(body.position[-1, 2]) > 1e-3  # it sank
    np.testing.assert_allclose(report["last"], body.position[-1] + points @ body.rotation[-1].T, atol=1e-6)
