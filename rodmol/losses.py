"""Loss records: scalar functions of a run that :func:`rodmol.gradient` differentiates.

A loss reads the run's frames at its own times (the state, and what the
result's post-processing makes of it: the tip, the markers, a body's
position) and may read the model alone (:class:`Effort`, the tensions'
integral). Each gives its value, its gradient by the state at each of its
times (dL/dy, the jumps of the adjoint) and its derivative by a parameter
where it reads the model directly. Losses add: ``TipTracking(...) +
Effort(1e-3)``.

* :class:`TipTracking` sum over times of w_k |tip(t_k) - target_k|^2 [m^2];
* :class:`TerminalTarget` w |tip(t) - target|^2 at one time (default: the end);
* :class:`rodmol.calibrate.marker_loss.MarkerTracking` (on the calibration's floor, which
  owns how a measurement names the parts it sees) sum over frames and seen markers of
  |marker - measured|^2 [m^2];
* :class:`Effort` weight * integral of the sum of squared tensions dt [weight N^2 s];
* :class:`BodyTarget` w |x(t) - target|^2 of a System's body's position [m^2];
* :class:`BodyAdvance` -w d . x(t), a System's body moved along d [m];
* :class:`StateLoss` the user's own function of the states at given times, with its gradient.

The gradient of a frame's number by the state is one rule,
:func:`rodmol.frame_gradient.frame_gradient` (central differences of the
result's own post-processing), for every loss that reads the result.
"""

import numpy as np

from . import _checks
from .errors import ParameterError
from .frame_gradient import frame_gradient
from .parameter_rates import hats, is_tension_value
from .systems import System

#: Gauss-Legendre points per interval between the tensions' knots: exact for the square of a
#: piecewise-linear tension (degree 2; 3 points are exact to degree 5).
GAUSS_POINTS = 3


class Loss:
    """A scalar loss of a run (see the module docstring). Subclasses define
    :meth:`times`, :meth:`evaluate` and, if they read the model itself,
    :meth:`direct` and :meth:`direct_gradient`."""

    def times(self, t0, t_end):
        """The times [s] where the loss reads the state (sorted; may be empty)."""
        return np.empty(0)

    def check(self, model, t0, t_end):
        """Refuse, before any work, a loss that ``model``'s run over [t0, t_end] cannot give."""
        times = self.times(t0, t_end)
        if len(times) and (times[0] < t0 - 1e-12 or times[-1] > t_end + 1e-12):
            raise ParameterError(f"{type(self).__name__}: its times [{times[0]!r}, {times[-1]!r}] s must lie in "
                                 f"the run's [{t0!r}, {t_end!r}] s")

    def evaluate(self, kind, system, t, states, span=None):
        """(value, dL/dy (len(t), size)) of the frames ``states`` at this loss's times ``t``
        of a run over ``span`` = (t0, t_end) [s]."""
        return 0.0, np.zeros_like(np.asarray(states, dtype=float))

    def direct(self, model, t0, t_end):
        """The part of the value that reads the model, not the state."""
        return 0.0

    def until(self, t):
        """This loss over a run that ends at ``t`` [s]: its terms at times up to ``t`` (None if
        none is left), for a growing horizon (:func:`rodmol.optimal_tensions`' ``horizons``)."""
        return self

    def direct_gradient(self, model, parameter, t0, t_end):
        """d :meth:`direct` / d ``parameter`` (a :class:`rodmol.named_parameters.Parameter`), (m,)."""
        return np.zeros(parameter.size)

    def __add__(self, other):
        if not isinstance(other, Loss):
            return NotImplemented
        return LossSum([*_parts(self), *_parts(other)])

    def __radd__(self, other):
        if isinstance(other, (int, float)) and other == 0:  # sum([loss_a, loss_b])
            return self
        return NotImplemented


def _parts(loss):
    return loss.parts if isinstance(loss, LossSum) else [loss]


class LossSum(Loss):
    """The sum of losses (``loss_a + loss_b``): each reads its own times' frames."""

    def __init__(self, parts):
        self.parts = list(parts)

    def times(self, t0, t_end):
        every = [p.times(t0, t_end) for p in self.parts]
        return np.unique(np.concatenate(every)) if every else np.empty(0)

    def check(self, model, t0, t_end):
        for part in self.parts:
            part.check(model, t0, t_end)

    def evaluate(self, kind, system, t, states, span=None):
        value, gradient = 0.0, np.zeros_like(np.asarray(states, dtype=float))
        t0, t_end = span if span is not None else ((t[0], t[-1]) if len(t) else (0.0, 0.0))
        for part in self.parts:
            own = part.times(t0, t_end) if len(t) else np.empty(0)
            rows = np.searchsorted(t, own)
            v, g = part.evaluate(kind, system, t[rows], states[rows], span)
            value += v
            np.add.at(gradient, rows, g)
        return value, gradient

    def direct(self, model, t0, t_end):
        return sum(p.direct(model, t0, t_end) for p in self.parts)

    def until(self, t):
        kept = [w for w in (p.until(t) for p in self.parts) if w is not None]
        return None if not kept else kept[0] if len(kept) == 1 else LossSum(kept)

    def direct_gradient(self, model, parameter, t0, t_end):
        return sum(p.direct_gradient(model, parameter, t0, t_end) for p in self.parts)

    def __repr__(self):
        return " + ".join(map(repr, self.parts))


class FrameLoss(Loss):
    """A loss of numbers the result's post-processing reads from each frame: a
    subclass defines :meth:`term` (its k-th time's number on every frame of a result)."""

    def term(self, result, k):
        raise NotImplementedError

    def evaluate(self, kind, system, t, states, span=None):
        states = np.asarray(states, dtype=float)
        result = kind.result(system, t, states, True, "", {})
        value = float(sum(self.term(result, k)[k] for k in range(len(t))))
        gradient = np.array([frame_gradient(kind, system, t[k], states[k], lambda r, k=k: self.term(r, k))
                             for k in range(len(t))]).reshape(states.shape)
        return value, gradient


class TipTracking(FrameLoss):
    """sum_k w_k |tip(t_k) - target_k|^2 [m^2]: the tip at ``times`` (m,) [s] near
    ``targets`` (m, 3) [m], global frame; ``weights`` (m,) [-] default 1. Of a
    System: the tip of the rod named ``rod``."""

    def __init__(self, times, targets, weights=None, rod=None):
        self._times = _increasing("times", times)
        m = len(self._times)
        self.targets = _finite_array("targets", targets, (m, 3))
        self.weights = np.ones(m) if weights is None else _finite_array("weights", weights, (m,))
        if np.any(self.weights < 0):
            raise ParameterError(f"`weights` must be >= 0, got {_checks.short(weights)}")
        self.rod = rod

    def times(self, t0, t_end):
        return self._times

    def check(self, model, t0, t_end):
        super().check(model, t0, t_end)
        _check_rod(model, self.rod, type(self).__name__)

    def until(self, t):
        keep = self._times <= t
        if not keep.any():
            return None
        return TipTracking(self._times[keep], self.targets[keep], self.weights[keep], self.rod)

    def term(self, result, k):
        tip = (result if self.rod is None else result[self.rod]).tip
        return self.weights[k] * np.sum((tip - self.targets[k]) ** 2, axis=-1)

    def __repr__(self):
        return f"TipTracking({len(self._times)} times)"


class TerminalTarget(TipTracking):
    """w |tip(t) - target|^2 [m^2] at ``t`` [s] (None: the run's end), ``target`` (3,) [m] global."""

    def __init__(self, target, t=None, weight=1.0, rod=None):
        self.at = None if t is None else _checks.non_negative("t", t, " s")
        super().__init__([0.0], [target], [_checks.non_negative("weight", weight)], rod)

    def times(self, t0, t_end):
        return np.array([t_end if self.at is None else self.at])

    def until(self, t):
        return self if self.at is not None and self.at <= t else None

    def __repr__(self):
        return f"TerminalTarget(t={'end' if self.at is None else self.at})"


class Effort(Loss):
    """``weight`` * integral over the run of the sum of every cable's squared tension dt
    [``weight`` N^2 s] (a System's: every rod's cables). It reads the model's tension
    inputs, not the state: a feedback tension is refused."""

    def __init__(self, weight=1.0):
        self.weight = _checks.non_negative("weight", weight)

    def check(self, model, t0, t_end):
        for cable in _cables(model):
            if cable.tension.feedback or cable.displacement is not None:
                raise ParameterError(f"Effort: cable {cable.name!r} has a tension that reads the state; the "
                                     "effort integrates tension inputs of time only")

    def direct(self, model, t0, t_end):
        t, w = _quadrature(model, t0, t_end)
        total = sum(np.square([cable.tension_at(ti) for ti in t]) @ w for cable in _cables(model))
        return self.weight * float(total)

    def direct_gradient(self, model, parameter, t0, t_end):
        if is_tension_value(parameter):  # T(t) = sum of v_k b_k(t): d/dv_k = 2 weight * integral of T b_k
            t, w = _quadrature(model, t0, t_end)
            b = np.array([hats(parameter, ti) for ti in t])
            return 2.0 * self.weight * ((w * (b @ parameter.value)) @ b)
        if not any("tension" in field.split(".") for field in parameter.fields):
            return np.zeros(parameter.size)
        # A tension's scale or offset: the central difference of the value.
        out = np.empty(parameter.size)
        for j in range(parameter.size):
            up, down, h = parameter.pair(model, j)
            out[j] = (self.direct(up, t0, t_end) - self.direct(down, t0, t_end)) / (2.0 * h)
        return out

    def __repr__(self):
        return f"Effort({self.weight!r})"


def _cables(model):
    if isinstance(model, System):
        return [c for rod in model.given_rods.values() for c in rod.cables]
    return list(model.cables)


def _quadrature(model, t0, t_end):
    """Gauss-Legendre points and weights over [t0, t_end], split at the inputs' knots."""
    from .inputs import knot_times

    models = model.given_rods.values() if isinstance(model, System) else [model]
    knots = np.concatenate([np.asarray(knot_times(m), dtype=float) for m in models] + [np.empty(0)])
    edges = np.unique(np.concatenate([[t0, t_end], knots[(knots > t0) & (knots < t_end)]]))
    x, w = np.polynomial.legendre.leggauss(GAUSS_POINTS)
    half, middle = np.diff(edges) / 2.0, (edges[1:] + edges[:-1]) / 2.0
    return (middle[:, None] + half[:, None] * x).ravel(), (half[:, None] * w).ravel()


class BodyLoss(Loss):
    """A loss of the position of the origin of the body ``body`` of a System at one time
    ``t`` [s] (None: the run's end): a subclass gives :meth:`of` (the value and its gradient
    by the position). The position is entries of the state, so dL/dy is exact."""

    def __init__(self, body, t=None, weight=1.0):
        if not isinstance(body, str):
            raise ParameterError(f"{type(self).__name__}: `body` must be a body's name, got {_checks.short(body)}")
        self.body = body
        self.at = None if t is None else _checks.non_negative("t", t, " s")
        self.weight = _checks.non_negative("weight", weight)

    def of(self, position):
        """(value, d value / d position (3,)) at the body's ``position`` (3,) [m]."""
        raise NotImplementedError

    def times(self, t0, t_end):
        return np.array([t_end if self.at is None else self.at])

    def check(self, model, t0, t_end):
        super().check(model, t0, t_end)
        bodies = list(model.bodies) if isinstance(model, System) else []
        if self.body not in bodies:
            raise ParameterError(f"{type(self).__name__}: `body` must name a body of a System "
                                 f"({', '.join(bodies) or 'this model has none'}), got {self.body!r}")

    def until(self, t):
        return self if self.at is not None and self.at <= t else None

    def evaluate(self, kind, system, t, states, span=None):
        states = np.asarray(states, dtype=float)
        entries = system.bodies[self.body].fields["x"]
        value, by_position = self.of(states[0, entries])
        gradient = np.zeros_like(states)
        gradient[0, entries] = by_position
        return float(value), gradient

    def __repr__(self):
        return f"{type(self).__name__}({self.body!r}, t={'end' if self.at is None else self.at})"


class BodyTarget(BodyLoss):
    """w |x(t) - target|^2 [m^2]: the origin of the body ``body`` of a System at ``t`` [s]
    (None: the run's end) near ``target`` (3,) [m], global frame."""

    def __init__(self, body, target, t=None, weight=1.0):
        super().__init__(body, t, weight)
        self.target = _finite_array("target", target, (3,))

    def of(self, position):
        moved = position - self.target
        return self.weight * float(moved @ moved), 2.0 * self.weight * moved


class BodyAdvance(BodyLoss):
    """-w d . x(t) [m]: minus the position of the origin of the body ``body`` of a System
    along the unit ``direction`` d (3,) (normalised here), global frame, at ``t`` [s] (None:
    the run's end); minimised, the body moves along d (a crawl's head forward)."""

    def __init__(self, body, direction, t=None, weight=1.0):
        super().__init__(body, t, weight)
        d = _finite_array("direction", direction, (3,))
        if not np.any(d):
            raise ParameterError(f"BodyAdvance: `direction` must not be zero, got {_checks.short(direction)}")
        self.direction = d / np.linalg.norm(d)

    def of(self, position):
        return -self.weight * float(self.direction @ position), -self.weight * self.direction


class StateLoss(Loss):
    """The user's own loss of the states at ``times`` (m,) [s]: ``value(t, states)`` ->
    float and ``gradient(t, states)`` -> (m, size) its derivative by each state, with
    ``states`` (m, size) the run's frames there (``Result.states``, unit quaternions)."""

    def __init__(self, times, value, gradient):
        self._times = _increasing("times", times)
        for name, fn in (("value", value), ("gradient", gradient)):
            if not callable(fn):
                raise ParameterError(f"StateLoss: `{name}` must be a function (t, states) -> ..., "
                                     f"got {_checks.short(fn)}")
        self.value, self.gradient = value, gradient

    def times(self, t0, t_end):
        return self._times

    def until(self, t):
        keep = self._times <= t
        return StateLoss(self._times[keep], self.value, self.gradient) if keep.any() else None

    def evaluate(self, kind, system, t, states, span=None):
        try:
            value = self.value(t.copy(), states.copy())
            gradient = self.gradient(t.copy(), states.copy())
        except Exception as exc:  # noqa: BLE001 (the user's: chained, never lost)
            raise _checks.user_error("StateLoss's function", exc) from exc
        value = _checks.finite("StateLoss value", value)
        gradient = _checks.floats(gradient)
        if gradient is None or gradient.shape != states.shape or not np.all(np.isfinite(gradient)):
            raise ParameterError(f"StateLoss: `gradient` must return finite numbers of shape {states.shape}, "
                                 f"got {_checks.short(gradient)}")
        return value, gradient

    def __repr__(self):
        return f"StateLoss({len(self._times)} times)"


def _increasing(name, times):
    arr = _checks.floats(times)
    if arr is None or arr.ndim != 1 or len(arr) == 0 or not np.all(np.isfinite(arr)) or np.any(arr < 0):
        raise ParameterError(f"`{name}` must be a non-empty list of finite times >= 0 [s], got {_checks.short(times)}")
    if np.any(np.diff(arr) <= 0):
        raise ParameterError(f"`{name}` must be increasing, got {_checks.short(times)}")
    return arr


def _finite_array(name, value, shape):
    arr = _checks.floats(value)
    if arr is None or arr.shape != shape or not np.all(np.isfinite(arr)):
        raise ParameterError(f"`{name}` must be finite numbers of shape {shape}, got {_checks.short(value)}")
    return arr


def _check_rod(model, rod, what):
    if isinstance(model, System):
        rods = list(model.given_rods)
        if rod is None and len(rods) == 1:
            return
        if rod not in rods:
            raise ParameterError(f"{what}: `rod` must name a rod of the System ({', '.join(rods)}), got {rod!r}")
    elif rod is not None:
        raise ParameterError(f"{what}: `rod` names a rod of a System; this model is one rod, give rod=None")
