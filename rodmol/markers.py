"""Markers: material points on the arm's surface, tracked like the paper's camera markers."""

from dataclasses import dataclass

import numpy as np

from . import _checks
from .errors import ParameterError


@dataclass(frozen=True)
class Marker:
    """A material point at arc length ``s`` [m], offset ``(p_y, p_z)`` [m] from the
    midline in the section (local frame). ``offset=None`` puts it on the surface
    on the local +y side, at the section radius."""

    s: float
    offset: tuple = None
    name: str = "marker"

    def __post_init__(self):
        object.__setattr__(self, "s", _checks.non_negative(f"marker {self.name!r} s", self.s, " m"))
        if self.offset is not None:
            p = _checks.floats(self.offset)
            if p is None or p.shape != (2,) or not np.all(np.isfinite(p)):
                raise ParameterError(f"marker {self.name!r}: `offset` must be (p_y, p_z) in m, "
                                     f"got {self.offset!r}")
            object.__setattr__(self, "offset", (float(p[0]), float(p[1])))


def marker_offsets(markers, rod):
    """(n_markers, 3) local offsets, resolving ``offset=None`` to the surface."""
    out = np.zeros((len(markers), 3))
    for i, m in enumerate(markers):
        if m.s > rod.length * (1 + 1e-12):
            raise ParameterError(f"marker {m.name!r}: `s` must lie in [0, L = {rod.length} m], got {m.s!r}")
        radius = float(rod.radius_at(min(m.s, rod.length)))
        out[i, 1:] = (radius, 0.0) if m.offset is None else m.offset
        reach = float(np.hypot(*out[i, 1:]))
        if reach > radius * (1 + 1e-9):
            raise ParameterError(f"marker {m.name!r}: offset {m.offset} m (|p| = {reach:.6g} m) lies "
                                 f"outside the body, whose radius at s = {m.s!r} m is {radius:.6g} m "
                                 "(a marker is a point of the body or of its surface)")
    return out
