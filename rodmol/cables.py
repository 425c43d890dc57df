"""Cables: routing (constant offset in the section, anchor arc length) and tension inputs.

A tension input is any of

* a number [N] (constant tension);
* a sequence of ``(t, T)`` knots [s, N], interpolated linearly and held
  constant outside the knots;
* a path to a CSV file with two columns, time [s] and tension [N]
  (an optional header line; ``#`` starts a comment), as logged by a rig;
* a callable ``T(t)``;
* a callable ``T(t, state)`` (feedback): ``state`` is a :class:`rodmol.StateView`
  (``None`` while the initial equilibrium is solved). Its dependence on the
  state is global, so it is not in the banded Jacobian; CVODE's default
  linear solver for such models is therefore GMRES, whose Jacobian-vector
  products are differences of the full right-hand side and do carry it
  (with ``linsolver="band"`` a strong gain costs many small steps, though
  the result stays correct).
"""

import csv
import inspect
import math
import os
from bisect import bisect_right
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from . import _checks
from .errors import ParameterError


class Tension:
    """Base class of tension inputs; ``feedback`` tells if it reads the state."""

    feedback = False

    def __call__(self, t, state=None):
        raise NotImplementedError


@dataclass(frozen=True)
class ConstantTension(Tension):
    value: float

    def __call__(self, t, state=None):
        return self.value


@dataclass(frozen=True)
class PiecewiseLinearTension(Tension):
    """Linear interpolation between knots, held constant outside them."""

    times: np.ndarray
    values: np.ndarray
    source: str = "knots"

    def __post_init__(self):
        # Plain lists and bisect: called at every right-hand side evaluation with
        # a scalar t, where np.interp's array overhead would dominate.
        object.__setattr__(self, "_t", [float(x) for x in self.times])
        object.__setattr__(self, "_v", [float(x) for x in self.values])

    def __call__(self, t, state=None):
        times, values = self._t, self._v
        j = bisect_right(times, t)
        if j == 0:
            return values[0]
        if j == len(times):
            return values[-1]
        t0, v0 = times[j - 1], values[j - 1]
        return v0 + (values[j] - v0) * (t - t0) / (times[j] - t0)


@dataclass(frozen=True)
class CallableTension(Tension):
    function: Callable
    feedback: bool = False

    def __call__(self, t, state=None):
        return float(self.function(t, state) if self.feedback else self.function(t))


def _knots(name, knots, source="knots"):
    try:
        arr = np.asarray(knots, dtype=float)
    except (TypeError, ValueError):
        raise ParameterError(f"`{name}` knots must be (t, T) pairs, got {knots!r}") from None
    if arr.ndim != 2 or arr.shape[1] != 2 or len(arr) < 1:
        raise ParameterError(f"`{name}` knots must be a list of (t, T) pairs, got {knots!r}")
    if not np.all(np.isfinite(arr)):
        raise ParameterError(f"`{name}` knots must be finite, got {knots!r}")
    if np.any(np.diff(arr[:, 0]) <= 0.0):
        i = int(np.flatnonzero(np.diff(arr[:, 0]) <= 0.0)[0]) + 1
        raise ParameterError(f"`{name}` knot times must increase; knot {i} has t = {float(arr[i, 0])!r}")
    if np.any(arr[:, 1] < 0.0):
        i = int(np.flatnonzero(arr[:, 1] < 0.0)[0])
        raise ParameterError(f"`{name}` must be >= 0 N; knot {i} has T = {float(arr[i, 1])!r}")
    return PiecewiseLinearTension(arr[:, 0].copy(), arr[:, 1].copy(), source)


def _number(cell):
    """The finite float in ``cell``, or None."""
    try:
        x = float(cell)
    except ValueError:
        return None
    return x if math.isfinite(x) else None


def read_tension_csv(path):
    """Read a two-column CSV (time [s], tension [N]) into a tension input.

    Errors name the file and the line.
    """
    path = os.fspath(path)
    rows, header_seen = [], False
    try:
        handle = open(path, newline="")  # noqa: SIM115 (closed by the with below)
    except OSError as exc:
        raise ParameterError(f"cannot read tension table {path!r}: {exc.strerror}") from None
    with handle:
        for lineno, row in enumerate(csv.reader(handle), start=1):
            cells = [c.strip() for c in row]
            if not any(cells) or cells[0].startswith("#"):
                continue
            values = [_number(c) for c in cells[:2]]
            if not rows and not header_seen and any(v is None for v in values):
                header_seen = True  # the first row that is not all numbers is a header
                continue
            if len(cells) < 1 or not cells[0]:
                raise ParameterError(f"{path}:{lineno}: missing time in {row!r}")
            if len(cells) < 2 or not cells[1]:
                raise ParameterError(f"{path}:{lineno}: missing tension in {row!r}")
            if any(v is None for v in values):
                raise ParameterError(f"{path}:{lineno}: not a number in {row!r}")
            t, tension = values
            if rows and t <= rows[-1][1]:
                raise ParameterError(
                    f"{path}:{lineno}: time {t!r} s does not increase (previous {rows[-1][1]!r} s)"
                )
            if tension < 0.0:
                raise ParameterError(f"{path}:{lineno}: negative tension {tension!r} N")
            rows.append((lineno, t, tension))
    if not rows:
        raise ParameterError(f"{path}: no (time, tension) rows found")
    arr = np.array([r[1:] for r in rows])
    return PiecewiseLinearTension(arr[:, 0], arr[:, 1], source=path)


def as_tension(value, name="tension"):
    """Turn any accepted tension input into a :class:`Tension`."""
    if isinstance(value, Tension):
        return value
    if isinstance(value, (str, os.PathLike)):
        return read_tension_csv(value)
    if callable(value):
        try:
            n_args = len(inspect.signature(value).parameters)
        except (TypeError, ValueError):
            n_args = 1
        return CallableTension(value, feedback=n_args >= 2)
    if np.ndim(value) == 0:
        return ConstantTension(_checks.non_negative(name, value, " N"))
    return _knots(name, value)


@dataclass(frozen=True)
class Cable:
    """A cable at a constant offset in the section, pulled from the base.

    Parameters
    ----------
    offset : (float, float)
        (p_y, p_z) [m]: the cable's position in the section, local frame.
    anchor : float
        Arc length s_bar [m] of the anchor, in (0, L].
    tension : tension input
        See the module docstring; negative tensions are errors.
    name : str, optional
        Used in messages and outputs.
    """

    offset: Any
    anchor: float
    tension: Any = 0.0
    name: str = field(default="cable")

    def __post_init__(self):
        p = np.asarray(self.offset, dtype=float) if np.ndim(self.offset) == 1 else None
        if p is None or p.shape != (2,) or not np.all(np.isfinite(p)):
            raise ParameterError(
                f"cable {self.name!r}: `offset` must be (p_y, p_z) in m, got {self.offset!r}"
            )
        object.__setattr__(self, "offset", (float(p[0]), float(p[1])))
        object.__setattr__(self, "anchor", _checks.positive(f"cable {self.name!r} anchor",
                                                             self.anchor, " m"))
        object.__setattr__(self, "tension", as_tension(self.tension, f"cable {self.name!r} tension"))

    @property
    def offset3(self):
        """Offset p = (0, p_y, p_z) [m], local frame."""
        return np.array([0.0, *self.offset])

    def tension_at(self, t, state=None):
        """Tension [N] at time t; a negative value is an error naming the cable."""
        value = self.tension(t, state)
        if not value >= 0.0:  # also catches NaN
            raise ParameterError(f"cable {self.name!r}: tension must be >= 0 N, got {float(value)!r} at t = {float(t)!r} s")
        return value
