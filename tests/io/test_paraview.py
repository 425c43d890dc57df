"""ParaView itself opens the series and draws the tapered body (pvpython under xvfb-run).

Skipped when ``pvpython`` or ``xvfb-run`` is missing (Debian: ``apt-get install
paraview xvfb xauth``). ParaView 5.11 needs an X display to render; its
``--force-offscreen-rendering`` alone crashes on the Debian build.
"""

import json
import shutil
import subprocess
import textwrap

import numpy as np
import pytest

import rodmol
from rodmol.io.writers import write_series

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
    write_series(result, tmp_path)
    script, png = tmp_path / "render.py", tmp_path / "frame.png"
    script.write_text(SCRIPT)
    run = subprocess.run([XVFB, "-a", "-s", "-screen 0 1280x1024x24", PVPYTHON, str(script),
                          str(tmp_path), str(png)], capture_output=True, text=True, timeout=120)
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
