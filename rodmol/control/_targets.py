"""What the inverse statics aims at: the tip, its tangent and markers, as
weighted functions of a rest state, with their derivatives in the state."""

import numpy as np

from .. import _checks
from .._differences import central_columns
from ..discretise import centreline, rotations
from ..errors import ParameterError

#: Relative step of the central differences of the outputs in the state
#: entries they read (positions and quaternions of a few nodes: a cheap
#: geometric function, no equilibrium solve; the truncation error is about 1e-14).
_STEP = 1e-7


class Targets:
    """The outputs aimed at, stacked as [tip, w_d d, w_m markers] (each part if asked for).

    Parameters
    ----------
    model : Model
    layout : StateLayout
    tip : bool
    direction : bool
    marker_names : sequence of str
        Names of the model's markers aimed at.
    direction_weight : float
        w_d [m]: the tangent's error counts as this length times |d - d_target|.
    marker_weight : float
        w_m [-]: the markers' errors count this much against the tip's.
    """

    def __init__(self, model, layout, tip, direction, marker_names, direction_weight, marker_weight):
        self.tip, self.direction, self.layout = tip, direction, layout
        self.direction_weight, self.marker_weight = direction_weight, marker_weight
        names = [m.name for m in model.markers]
        self.marker_names = list(marker_names)
        self._marker_index = [names.index(n) for n in self.marker_names]
        self._s = [model.markers[i].s for i in self._marker_index]
        self._offsets = model.marker_offsets[self._marker_index, 1:]
        self._s_nodes = model.s_nodes
        index = np.arange(layout.size)
        nodes = {layout.n_elements} if tip or direction else set()
        for s in self._s:
            j, _ = centreline.bracket(model.s_nodes, s)
            nodes.update((j, j + 1))
        nodes = sorted(n for n in nodes if n <= layout.n_elements)
        self.entries = np.concatenate([np.concatenate([layout.integrated_positions(index)[n],
                                                       layout.quaternions(index)[n]]) for n in nodes])

    @property
    def size(self):
        return 3 * (self.tip + self.direction + len(self.marker_names))

    def values(self, y):
        """The weighted outputs of state ``y``: positions [m] global, the tangent times w_d."""
        positions = self.layout.integrated_positions(y)
        frames = rotations.matrices(self.layout.quaternions(y))
        parts = []
        if self.tip:
            parts.append(positions[-1])
        if self.direction:
            parts.append(self.direction_weight * frames[-1][:, 0])
        if self.marker_names:
            points = centreline.track(self._s, self._offsets, self._s_nodes, positions[None], frames[None])[0]
            parts.append(self.marker_weight * points.ravel())
        return np.concatenate(parts)

    def aim(self, tip, direction, marker_positions):
        """The weighted target vector of checked inputs (tip (3,), a unit tangent, (n, 3) markers)."""
        parts = []
        if self.tip:
            parts.append(tip)
        if self.direction:
            parts.append(self.direction_weight * direction)
        if self.marker_names:
            parts.append(self.marker_weight * np.asarray(marker_positions).ravel())
        return np.concatenate(parts)

    def rows(self, y):
        """d values / d y[entries], (size, len(entries))."""
        h = _STEP * np.maximum(np.abs(y[self.entries]), 0.1)
        return central_columns(self.values, y, self.entries, h)

    def errors(self, y, aim):
        """(tip error [m] or None, tangent angle [rad] or None, {marker: error [m]})."""
        got, start = self.values(y), 0
        tip_error = angle = None
        if self.tip:
            tip_error = float(np.linalg.norm(got[:3] - aim[:3]))
            start = 3
        if self.direction:
            tangent, goal = got[start:start + 3], aim[start:start + 3]
            angle = float(np.arctan2(np.linalg.norm(np.cross(tangent, goal)), tangent @ goal))
            start += 3
        gaps = (got[start:] - aim[start:]).reshape(-1, 3) / self.marker_weight
        return tip_error, angle, dict(zip(self.marker_names, np.linalg.norm(gaps, axis=1).tolist()))


def check_aims(model, tip, direction, marker_targets):
    """The checked (tip or None, unit direction or None, marker names, (n, 3) positions)."""
    if tip is not None:
        tip = _checks.vector3("tip", tip)
    if direction is not None:
        direction = _checks.vector3("direction", direction)
        size = np.linalg.norm(direction)
        if size == 0.0:
            raise ParameterError("`direction` must be a nonzero vector, got (0, 0, 0)")
        direction = direction / size
    names, positions = [], np.zeros((0, 3))
    if marker_targets is not None:
        if not isinstance(marker_targets, dict) or not marker_targets:
            raise ParameterError(f"`markers` must map marker names to positions [m], got "
                                 f"{_checks.short(marker_targets)}")
        known = [m.name for m in model.markers]
        for name in marker_targets:
            if name not in known:
                raise ParameterError(f"`markers`: no marker named {name!r} in the model (it has {known})"
                                     + _checks.did_you_mean(name, known))
            names.append(name)
        positions = np.array([_checks.vector3(f"markers[{n!r}]", marker_targets[n]) for n in names])
    if tip is None and direction is None and not names:
        raise ParameterError("give a target: `tip`, `direction` or `markers`")
    return tip, direction, names, positions


def path_rows(name, value):
    """The checked (n, 3) array of a path's targets ``value`` (n >= 1, finite), named ``name``."""
    arr = _checks.floats(value)
    if arr is None or arr.ndim != 2 or arr.shape[1] != 3 or len(arr) == 0:
        raise ParameterError(f"`{name}` must be an (n, 3) array of positions [m], got {_checks.short(value)}")
    if not np.all(np.isfinite(arr)):
        raise ParameterError(f"`{name}` must be finite, got {_checks.short(value)}")
    return arr
