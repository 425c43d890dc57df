"""A synthetic experiment, made by the project (no recordings of the paper's
prototype are published): two cameras with known DLT parameters looking at
the paper's workspace, eight control points on a calibration frame, the
markers of a run seen by both cameras with pixel noise and occlusions, and
the tension log with sensor noise.

Everything is generated from a model run with known parameters, so the
reconstruction and the identification can be checked against the truth.
"""

from dataclasses import dataclass

import numpy as np

from ..model import Model
from .dlt import Camera
from .measured import MarkerTracks, PixelTracks, TensionLog
from .runs import MarkersAt
from .targets import of_part
from .variants import apply, as_spec

#: The image size of the paper's cameras [px] (1240 x 1000, 100 frames/s).
IMAGE = (1240, 1000)
FRAME_RATE = 100.0  # frames/s
#: The calibration frame's corners [m], global: 0.45 x 0.6 x 0.5 m (the
#: paper's frame holds about 125 dm^3 and the whole motion).
FRAME = ((0.0, 0.45), (-0.3, 0.3), (-0.25, 0.25))


def cameras():
    """The two synthetic cameras: one in front of the arm (on +z), one above it (on +y)."""
    centre = (0.22, 0.0, 0.0)
    front = Camera.looking_at((0.22, 0.0, 1.2), centre, focal=1300.0, centre=(620, 500), name="front")
    top = Camera.looking_at((0.22, 1.2, 0.0), centre, focal=1300.0, centre=(620, 500), up=(0, 0, -1),
                            name="top")
    return front, top


def control_points():
    """The eight corners of the calibration frame, (8, 3) [m], global."""
    return np.array([(x, y, z) for x in FRAME[0] for y in FRAME[1] for z in FRAME[2]])


def pulse_tensions(amplitude=2.0, ramp=0.05, on=0.7, off=0.7, pulses=4, delay=0.7):
    """An identification experiment: cable 11 pulsed ``pulses`` times to
    ``amplitude`` [N] (``ramp`` s up and down, held ``on`` s, slack ``off`` s)
    and cable 2 to twice that, ``delay`` s later. Sharp pulses excite the
    fast motions that the internal viscosity damps, which the paper's slow
    ramps hardly do. Returns ({cable number: knots}, end time [s])."""
    knots, t = [(0.0, 0.0)], 0.0
    for _ in range(pulses):
        knots += [(t + ramp, amplitude), (t + ramp + on, amplitude), (t + 2 * ramp + on, 0.0)]
        t += 2 * ramp + on + off
        knots.append((t, 0.0))
    second = [(0.0, 0.0)] + [(a + delay, 2.0 * v) for a, v in knots[1:]]
    return {11: knots, 2: second}, t + delay + off


@dataclass(frozen=True)
class Experiment:
    """A synthetic recording: the ``truth`` (overrides of the generating run),
    its exact markers ``true_markers``, the true ``cameras``, the measured
    control points (``control_xyz`` and ``control_uv``, one (8, 2) array per
    camera), the cameras' ``pixels`` (PixelTracks) and the ``tensions`` log
    (a system's: {rod: TensionLog})."""

    truth: dict
    true_markers: MarkerTracks
    cameras: tuple
    control_xyz: np.ndarray
    control_uv: tuple
    pixels: tuple
    tensions: TensionLog


def synthesize(spec, truth=None, *, noise_px=1.0, control_noise_px=None, tension_noise=0.0, occlusion=0.0,
               rate=FRAME_RATE, seed=0, part=None):
    """Record ``spec`` run with the overrides ``truth`` through :func:`cameras`.

    ``part`` is what a system's recording sees (:mod:`rodmol.calibrate.targets`:
    a rod's markers ``"arm1"``, its tip ``"arm1.tip"``, a body ``"head"``);
    its markers' tracks carry it. A system's ``tensions`` are one log per
    rod, {rod: TensionLog} (``log.overrides(rod)`` drives the rod's cables).

    ``noise_px`` is the standard deviation [px] of the markers' image
    coordinates, ``control_noise_px`` that of the control points (default
    ``noise_px / 10``: the control points are fixed markers whose centroids
    are averaged over the recording's frames, 100 frames giving a tenth); ``tension_noise`` [N] that of the logged
    tensions (clipped at 0, as a sensor reading of a slack cable would be);
    ``occlusion`` the fraction of marker samples each camera misses.
    """
    spec = apply(as_spec(spec), dict(truth or {}))
    rng = np.random.default_rng(seed)
    times = np.arange(int(np.floor(spec.t_end * rate + 1e-9)) + 1) / rate
    targets = of_part(spec, part)
    result = spec.simulate()
    if not result.success:
        raise RuntimeError(f"the generating run failed: {result.message}")
    xyz = MarkersAt(times, targets)(result, spec)
    names = _names(spec.model, targets.parts[0])
    cams = cameras()
    ctrl = control_points()
    control_noise = noise_px / 10.0 if control_noise_px is None else control_noise_px
    control_uv = tuple(c.project(ctrl) + control_noise * rng.standard_normal((len(ctrl), 2)) for c in cams)
    pixels = []
    for cam in cams:
        uv = cam.project(xyz) + noise_px * rng.standard_normal(xyz.shape[:2] + (2,))
        uv[rng.random(xyz.shape[:2]) < occlusion] = np.nan
        pixels.append(PixelTracks(times, uv, names))
    if isinstance(spec.model, Model):
        log = _log(spec.model.cables, times, tension_noise, rng)
    else:
        log = {rod: _log(m.cables, times, tension_noise, rng) for rod, m in spec.model.given_rods.items()}
    return Experiment(dict(truth or {}), MarkerTracks(times, xyz, names, part), cams, ctrl, control_uv,
                      tuple(pixels), log)


def _log(cables, times, noise, rng):
    """The TensionLog of the ``cables`` that pull, read at ``times`` [s] with sensor ``noise`` [N]."""
    tension = np.stack([[c.tension_at(t) for c in cables] for t in times]).reshape(len(times), len(cables))
    used = np.flatnonzero(np.any(tension > 0.0, axis=0))
    logged = np.maximum(tension[:, used] + noise * rng.standard_normal((len(times), len(used))), 0.0)
    return TensionLog(times, logged, tuple(cables[i].name for i in used))


def _names(model, target):
    """The names of the markers of ``target`` ((name, kind, count))."""
    name, kind, _ = target
    if kind == "markers":
        return tuple(m.name for m in (model if name is None else model.given_rods[name]).markers)
    return (name or kind,) if kind == "body" or name is None else (f"{name}.{kind}",)
