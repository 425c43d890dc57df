"""Cables: routing (constant offset in the section, anchor arc length) and tension inputs.

A tension input is any of

* a number [N] (constant tension);
* a sequence of ``(t, T)`` knots [s, N], interpolated linearly and held
  constant outside the knots;
* a path to a CSV file with two columns, time [s] and tension [N]
  (an optional header line; ``#`` starts a comment), as logged by a rig;
* a callable ``T(t)``;
* a callable ``T(t, state)`` with two required arguments (feedback): ``state`` is a :class:`rodmol.StateView`
  (while the initial equilibrium is solved, a view of the current iterate, at rest). Its dependence on the
  state is global, so it is not in the banded Jacobian; CVODE's default
  linear solver for such models is therefore GMRES, whose Jacobian-vector
  products are differences of the full right-hand side and do carry it
  (with ``linsolver="band"`` a strong gain costs many small steps, though
  the result stays correct).
"""

import inspect
import os
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from . import _checks
from .errors import ParameterError, RodmolError
from .inputs import Knots, TimeInput, as_time_input, read_table


class Tension:
    """A cable's tension input: ``tension(t, state=None)`` [N].

    ``feedback`` tells if it reads the state; ``constant`` holds the value of
    a constant tension (None otherwise), so the right-hand side reads it once.
    """

    feedback = False

    def __init__(self, signal: TimeInput):
        self.signal = signal
        self.constant = signal.value(0.0) if signal.constant else None

    def __call__(self, t, state=None):
        return self.signal.value(t)

    def __repr__(self):
        return f"Tension({self.signal!r})"


@dataclass(frozen=True)
class FeedbackTension(Tension):
    """A feedback law ``T(t, state)``; ``state`` is a :class:`rodmol.StateView`."""

    function: Callable
    feedback = True
    constant = None

    def __call__(self, t, state=None):
        return float(self.function(t, state))


def read_tension_csv(path):
    """Read a two-column CSV (time [s], tension [N]) into a tension input.

    Errors name the file and the line.
    """
    times, values = read_table(path, 1, "tension", "N", minimum=0.0)
    return Tension(Knots(times, values, source=os.fspath(path)))


def as_tension(value, name="tension"):
    """Turn any accepted tension input into a :class:`Tension`."""
    if isinstance(value, Tension):
        return value
    if isinstance(value, (str, os.PathLike)):
        return read_tension_csv(value)
    if callable(value) and _required_arguments(value) >= 2:
        return FeedbackTension(value)
    return Tension(as_time_input(name, value, 1, "N", minimum=0.0))


def _required_arguments(function):
    """Positional parameters without defaults (``lambda t, gain=1.0: ...`` has one)."""
    try:
        parameters = inspect.signature(function).parameters.values()
    except (TypeError, ValueError, OverflowError):
        return 1
    kinds = (inspect.Parameter.POSITIONAL_ONLY, inspect.Parameter.POSITIONAL_OR_KEYWORD)
    return sum(1 for p in parameters if p.kind in kinds and p.default is inspect.Parameter.empty)


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
        p = _checks.floats(self.offset)
        if p is None or p.shape != (2,) or not np.all(np.isfinite(p)):
            raise ParameterError(
                f"cable {_checks.short(self.name)}: `offset` must be (p_y, p_z) in m, got "
                f"{_checks.short(self.offset)}"
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
        try:
            value = self.tension(t, state)
        except RodmolError:
            raise
        except Exception as exc:  # noqa: BLE001 (the user's function: chained, never lost)
            raise _checks.user_error(f"cable {self.name!r}: the tension function", exc, t) from exc
        if not value >= 0.0:  # also catches NaN
            raise ParameterError(f"cable {self.name!r}: tension must be >= 0 N, got {float(value)!r} at t = {float(t)!r} s")
        return value
