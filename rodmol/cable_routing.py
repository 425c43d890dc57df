"""A cable's routing p(s): where it runs in the section along the rod.

An offset is any of

* ``(p_y, p_z)`` [m]: constant, the paper's cables;
* ``[(s, p_y, p_z), ...]`` knots [m], s increasing, linear between them and
  held constant outside them (converging, diverging, stepped routings);
* a callable ``p(s)`` of the arc length s [m] (called with numpy arrays)
  returning ``(p_y, p_z)``, each a number or an array like s (helical
  routings).

All offsets are in the local (material) frame, p_x = 0: the cable lies in
the section plane. Its path is u + R p(s), so its local tangent follows from
u_c' = R (q + k x p + p').
"""

import numpy as np

from . import _checks
from .errors import ParameterError


def as_offset(value, name):
    """The offset in its stored form, checked: a pair, a tuple of knots or the callable."""
    if callable(value):
        return value
    p = _checks.floats(value)
    if p is not None and p.shape == (2,) and np.all(np.isfinite(p)):
        return (float(p[0]), float(p[1]))
    if p is not None and p.ndim == 2 and p.shape[1] == 3 and len(p) >= 2 and np.all(np.isfinite(p)):
        if np.any(np.diff(p[:, 0]) <= 0):
            raise ParameterError(f"cable {_checks.short(name)}: `offset` knots must have increasing s, "
                                 f"got s = {_checks.short(p[:, 0].tolist())}")
        return tuple(tuple(float(x) for x in row) for row in p)
    raise ParameterError(
        f"cable {_checks.short(name)}: `offset` must be (p_y, p_z) in m, knots [(s, p_y, p_z), ...] "
        f"or a callable p(s), got {_checks.short(value)}")


def offset_at(offset, s, name):
    """(p_y, p_z) [m] of a stored offset at arc lengths ``s`` [m]: array (len(s), 2)."""
    s = np.atleast_1d(np.asarray(s, dtype=float))
    if callable(offset):
        try:
            raw = offset(s)
            p = np.asarray([np.broadcast_to(np.asarray(x, dtype=float), s.shape) for x in raw])
        except Exception as exc:  # noqa: BLE001 (the user's function: chained, never lost)
            raise ParameterError(f"cable {name!r}: the `offset` function failed on arc lengths "
                                 f"(it must return (p_y, p_z) for an array s): {exc}") from exc
        if p.shape != (2,) + s.shape or not np.all(np.isfinite(p)):
            bad = "" if p.shape != (2,) + s.shape else f": p({s[np.argmin(np.all(np.isfinite(p), 0))]:.6g} m) is not finite"
            raise ParameterError(f"cable {name!r}: the `offset` function must return two finite "
                                 f"values (p_y, p_z) for each s{bad}")
        return p.T.copy()
    if isinstance(offset[0], tuple):
        knots = np.asarray(offset)
        return np.stack([np.interp(s, knots[:, 0], knots[:, 1]), np.interp(s, knots[:, 0], knots[:, 2])], axis=1)
    return np.tile(np.asarray(offset, dtype=float), (len(s), 1))


def cell_geometry(offset, s_nodes, s_cells, name):
    """Per cell: p at the cell's sampling point and p' across the cell, as the
    rows [0, p_y, p_z, 0, p_y', p_z'] (local frame), shape (len(s_cells), 6).
    p' is the difference of p over the cell, so the discrete path length is
    exact for knots on the nodes and second order otherwise."""
    p_nodes = offset_at(offset, s_nodes, name)
    geometry = np.zeros((len(s_cells), 6))
    geometry[:, 1:3] = offset_at(offset, s_cells, name)
    geometry[:, 4:6] = np.diff(p_nodes, axis=0) / np.diff(s_nodes)[:, None]
    return geometry
