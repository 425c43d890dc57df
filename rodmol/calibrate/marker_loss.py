"""The loss of measured markers (:class:`MarkerTracking`) for :func:`rodmol.gradient`.

It lives with the calibration, which owns how a measurement names the parts it
sees (:mod:`rodmol.calibrate.targets`); the other losses are in :mod:`rodmol.losses`.
"""

import numpy as np

from .. import _checks
from ..errors import ParameterError
from ..losses import FrameLoss
from .targets import of_result


class MarkerTracking(FrameLoss):
    """sum over the frames of ``tracks`` (a :class:`rodmol.calibrate.MarkerTracks`, or
    ``{part: MarkerTracks}`` of a System, as :func:`rodmol.identify` takes them) and
    over the markers seen (NaN: not seen) of |marker - measured|^2 [m^2]."""

    def __init__(self, tracks):
        self.tracks = tracks
        self._matched = None  # (MarkerTracks, Targets) once the run's result is known

    def _match(self, result):
        if self._matched is None:
            self._matched = of_result(result, self.tracks)
        return self._matched

    def times(self, t0, t_end):
        return np.asarray(_times_of(self.tracks), dtype=float)

    def until(self, t):
        if _times_of(self.tracks)[0] > t:
            return None
        if isinstance(self.tracks, dict):
            return MarkerTracking({part: tracks.until(t) for part, tracks in self.tracks.items()})
        return MarkerTracking(self.tracks.until(t))

    def evaluate(self, kind, system, t, states, span=None):
        self._matched = None  # matched afresh to each run's result (another model may differ)
        return super().evaluate(kind, system, t, states, span)

    def term(self, result, k):
        measured, targets = self._match(result)
        seen = np.isfinite(measured.xyz[k]).all(axis=-1)
        moved = targets.markers(result)[:, seen] - measured.xyz[k][seen]
        return np.sum(moved ** 2, axis=(1, 2))

    def __repr__(self):
        return f"MarkerTracking({len(self.times(0, 0))} frames)"


def _times_of(tracks):
    first = next(iter(tracks.values())) if isinstance(tracks, dict) else tracks
    first = first[0] if isinstance(first, (list, tuple)) else first
    if not hasattr(first, "t"):
        raise ParameterError(f"`tracks` must be MarkerTracks (or {{part: MarkerTracks}}), got {_checks.short(tracks)}")
    return first.t
