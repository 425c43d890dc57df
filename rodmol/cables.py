"""Cables: routing (offset in the section, anchor arc length), tension inputs,
displacement control (:class:`ActuatorTension`) and friction.

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

import copy
import inspect
import math
import os
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from . import _checks, cable_routing
from .errors import ParameterError, RodmolError
from .inputs import Knots, TimeInput, as_time_input, read_table


class Tension:
    """A cable's tension input: ``tension(t, state=None)`` [N].

    ``feedback`` tells if it reads the state; ``constant`` holds the value of
    a constant tension (None otherwise), so the right-hand side reads it once.
    """

    feedback = False
    #: What the input is called in messages.
    label = "tension input"

    def __init__(self, signal: TimeInput):
        self.signal = signal
        self.constant = signal.value(0.0) if signal.constant else None
        self.held = signal.held

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
    held = False
    label = "feedback law T(t, state)"

    def __call__(self, t, state=None):
        return self.function(t, state)  # checked by Cable.tension_at, which names the cable


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


class ActuatorTension(Tension):
    """The tension of a displacement-controlled cable (Till, Aloi and Rucker's
    tendon model): the tendon runs from an actuator at ``base_to_actuator`` [m]
    behind the base along the cable path to the anchor; its unstretched length
    there is l = rest_length + z(t) (z [m] the actuator position, negative
    when it reels in), and it stretches by compliance [1/N] x l x T, so

        T = max(0, (path length + base_to_actuator - l) / (l x compliance)),

    slack (T = 0) when the path is shorter than the free tendon. It reads the
    path length of the state (``StateView.cable_length``), so it is a
    feedback law; without a state it assumes the unloaded rod in its rest
    shape (path length ``unloaded_length`` [m]). ``default_rest`` is True
    if the rest length was not given (then it follows the rod's rest shape,
    :meth:`Cable.on_rod`).
    """

    feedback = True
    constant = None
    held = False
    label = "displacement-controlled tension"

    def __init__(self, name, position, compliance, base_to_actuator, rest_length, unloaded_length,
                 default_rest=False):
        self.name, self.position = name, position
        self.compliance, self.base_to_actuator = compliance, base_to_actuator
        self.rest_length, self.unloaded_length = rest_length, unloaded_length
        self.default_rest = default_rest

    def free_length(self, t):
        """Unstretched tendon length [m] between the actuator and the anchor at t."""
        return self.rest_length + self.position.value(t)

    def from_length(self, t, length):
        """Tension [N] for a cable path length ``length`` [m] at t."""
        free = self.free_length(t)
        return max(0.0, (length + self.base_to_actuator - free) / (free * self.compliance))

    def position_for(self, length, tension):
        """Actuator position z [m] that holds ``tension`` [N] > 0 over a path of
        ``length`` [m] (the inverse of :meth:`from_length`); at 0 N, the position
        that leaves the tendon just taut."""
        return (length + self.base_to_actuator) / (1.0 + self.compliance * tension) - self.rest_length

    def slopes(self, t, length):
        """(dT / d path length, dT / dz) [N/m] at path ``length`` [m] and time t:
        the tendon's stiffness and the actuator's gain (both 0 when slack)."""
        free = self.free_length(t)
        if self.from_length(t, length) == 0.0:
            return 0.0, 0.0
        return 1.0 / (free * self.compliance), -(length + self.base_to_actuator) / (free**2 * self.compliance)

    def __call__(self, t, state=None):
        length = self.unloaded_length if state is None else state.cable_length(self.name)
        return self.from_length(t, length)

    def __repr__(self):
        return (f"ActuatorTension(z={self.position!r}, compliance={self.compliance!r}, "
                f"base_to_actuator={self.base_to_actuator!r}, rest_length={self.rest_length!r})")


@dataclass(frozen=True)
class Cable:
    """A cable pulled from the base, by a tension or by an actuator's displacement.

    Parameters
    ----------
    offset : (p_y, p_z), [(s, p_y, p_z), ...] or callable p(s)
        The routing [m], local frame: constant, knots or a function of the
        arc length (:mod:`rodmol.cable_routing`).
    anchor : float
        Arc length s_bar [m] of the anchor, in (0, L].
    tension : tension input
        See the module docstring; negative tensions are errors. Default 0
        (slack). Not with ``displacement``.
    name : str, optional
        Used in messages and outputs.
    outside_body : bool, keyword-only
        The cable runs on spacer disks: offsets beyond the section radius are
        allowed (refused by default).
    displacement : time input, keyword-only
        Actuator position z(t) [m] (constant, ``(t, z)`` knots, CSV path or
        callable of t), negative when the actuator reels the cable in: the
        tension then follows from the path length (:class:`ActuatorTension`).
    compliance : float, keyword-only
        Tendon compliance [1/N] (stretch per unit length per newton), > 0;
        with ``displacement`` only.
    base_to_actuator : float, keyword-only
        Tendon length [m] from the actuator to the base, >= 0.
    rest_length : float, keyword-only
        Unstretched tendon length [m] from the actuator to the anchor at
        z = 0; default: the path length on the rod at rest plus
        ``base_to_actuator`` (slack-free and unloaded in the rod's rest
        shape; the model measures it on its rod, :meth:`on_rod`).
    friction : float, keyword-only
        Coefficient of friction [-] between the cable and the body (capstan
        law, see docs/model.md), >= 0; 0 (default) is frictionless.
    slip_speed : float, keyword-only
        Sliding speed [m/s] below which friction is regularised (its
        direction fades linearly to zero), > 0; default 1e-4 m/s.
    """

    offset: Any
    anchor: float
    tension: Any = None
    name: str = field(default="cable")
    outside_body: bool = field(default=False, kw_only=True)
    displacement: Any = field(default=None, kw_only=True)
    compliance: float | None = field(default=None, kw_only=True)
    base_to_actuator: float = field(default=0.0, kw_only=True)
    rest_length: float | None = field(default=None, kw_only=True)
    friction: float = field(default=0.0, kw_only=True)
    slip_speed: float = field(default=1e-4, kw_only=True)

    def __post_init__(self):
        label = f"cable {self.name!r}"
        object.__setattr__(self, "offset", cable_routing.as_offset(self.offset, self.name))
        object.__setattr__(self, "anchor", _checks.positive(f"{label} anchor", self.anchor, " m"))
        object.__setattr__(self, "outside_body", _checks.flag(f"{label} outside_body", self.outside_body))
        object.__setattr__(self, "friction", _checks.non_negative(f"{label} friction", self.friction))
        object.__setattr__(self, "slip_speed", _checks.positive(f"{label} slip_speed", self.slip_speed, " m/s"))
        self.offset_at(np.linspace(0.0, self.anchor, 65))  # a failing offset function fails here
        if self.displacement is None:
            for key in ("compliance", "rest_length"):
                if getattr(self, key) is not None:
                    raise ParameterError(f"{label}: `{key}` belongs to a displacement-controlled cable "
                                         f"(give `displacement`), got {getattr(self, key)!r}")
            if self.base_to_actuator != 0.0:
                raise ParameterError(f"{label}: `base_to_actuator` belongs to a displacement-controlled "
                                     f"cable (give `displacement`), got {self.base_to_actuator!r}")
            tension = 0.0 if self.tension is None else self.tension
            object.__setattr__(self, "tension", as_tension(tension, f"{label} tension"))
        else:
            self._actuate(label)

    def _actuate(self, label):
        if self.tension is not None and not isinstance(self.tension, ActuatorTension):
            raise ParameterError(f"{label}: give either `tension` or `displacement`, not both "
                                 f"(got tension={_checks.short(self.tension)})")
        position = self.displacement
        if isinstance(position, ActuatorTension):
            position = position.position
        position = as_time_input(f"{label} displacement", position, 1, "m")
        if self.compliance is None:
            raise ParameterError(f"{label}: a displacement-controlled cable needs `compliance` [1/N] > 0")
        compliance = _checks.positive(f"{label} compliance", self.compliance, " 1/N")
        base = _checks.non_negative(f"{label} base_to_actuator", self.base_to_actuator, " m")
        straight = self.straight_length()
        default_rest = self.rest_length is None
        rest = straight + base if default_rest else _checks.positive(
            f"{label} rest_length", self.rest_length, " m")
        object.__setattr__(self, "displacement", position)
        object.__setattr__(self, "compliance", compliance)
        object.__setattr__(self, "base_to_actuator", base)
        object.__setattr__(self, "rest_length", rest)
        object.__setattr__(self, "tension", ActuatorTension(self.name, position, compliance, base, rest,
                                                            straight, default_rest=default_rest))

    @property
    def actuated(self):
        """True for a displacement-controlled cable."""
        return self.displacement is not None

    @property
    def offset3(self):
        """Offset p = (0, p_y, p_z) [m] at the base, local frame."""
        return np.array([0.0, *self.offset_at(0.0)[0]])

    def offset_at(self, s):
        """(p_y, p_z) [m] at arc lengths ``s`` [m], array (len(s), 2), local frame."""
        return cable_routing.offset_at(self.offset, s, self.name)

    def on_rod(self, rod):
        """This cable on ``rod``: a displacement-controlled cable whose rest length
        was not given gets the path length on the rod's rest shape (plus
        ``base_to_actuator``), so that it is just taut and unloaded there; any
        other cable is returned as it is."""
        tension = self.tension
        if not self.actuated or not tension.default_rest:
            return self
        length = self.rest_path_length(rod)
        if length == tension.unloaded_length:
            return self
        out = copy.copy(self)
        rest = length + self.base_to_actuator
        object.__setattr__(out, "rest_length", rest)
        object.__setattr__(out, "tension", ActuatorTension(self.name, tension.position, self.compliance,
                                                           self.base_to_actuator, rest, length, default_rest=True))
        return out

    def rest_path_length(self, rod):
        """Path length [m] from the base to the anchor on ``rod`` at rest: the
        integral of |q* + k* x p + p'| over s (the path's stretch with the rest
        strains, docs/model.md; 2000 intervals, the rest strains at their
        midpoints); :meth:`straight_length` on a straight rod."""
        if rod.straight:
            return self.straight_length()
        s = np.linspace(0.0, self.anchor, 2001)
        p = np.zeros((s.size, 3))
        p[:, 1:] = self.offset_at(s)
        rest_q, rest_k = rod.rest_strains_at(0.5 * (s[1:] + s[:-1]))
        ds = np.diff(s)[:, None]
        chords = ds * (rest_q + np.cross(rest_k, 0.5 * (p[1:] + p[:-1]))) + np.diff(p, axis=0)
        return float(np.sum(np.linalg.norm(chords, axis=1)))

    def straight_length(self):
        """Path length [m] from the base to the anchor on the straight rod,
        integral of sqrt(1 + |p'|^2) (2000 intervals)."""
        s = np.linspace(0.0, self.anchor, 2001)
        p = self.offset_at(s)
        return float(np.sum(np.sqrt(np.diff(s) ** 2 + np.sum(np.diff(p, axis=0) ** 2, axis=1))))

    def tension_at(self, t, state=None):
        """Tension [N] at time t; an exception or a value that is not a finite
        tension >= 0 is a :class:`UserFunctionError` naming the cable, its input and t."""
        try:
            value = self.tension(t, state)
        except RodmolError:
            raise
        except Exception as exc:  # noqa: BLE001 (the user's function: chained, never lost)
            raise _checks.user_error(self._input_name(), exc, t) from exc
        if not isinstance(value, float):
            number = _checks.floats(value)
            if number is None or number.size != 1:
                raise _checks.bad_return(self._input_name(), value, t, "a tension is one number [N]")
            value = float(number.reshape(()))
        if not 0.0 <= value < math.inf:  # also catches NaN
            raise _checks.bad_return(self._input_name(), value, t, "a tension must be finite and >= 0 N")
        return value

    def _input_name(self):
        """The tension input, as failure messages name it (built only then: tension_at is hot)."""
        return f"cable {self.name!r}: the {self.tension.label}"
