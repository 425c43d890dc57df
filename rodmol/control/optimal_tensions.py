"""The tension history that minimises a loss of a run: :func:`optimal_tensions`.

The cables' tensions are knot inputs (:class:`rodmol.inputs.Knots`, linear between
the knots); their values are found by scipy's L-BFGS-B within ``bounds``, each loss
and its gradient by one adjoint (:func:`rodmol.gradients.gradient`: about the cost
of a few runs, whatever the number of knots).
"""

from dataclasses import dataclass

import numpy as np
from scipy import optimize

from .. import _checks, model_variants, named_parameters, system_variants
from ..cables import Tension
from ..errors import ParameterError
from ..gradients import gradient
from ..inputs import Knots
from ..simulate import simulate
from ..systems import System

#: Options of the gradient that simulate does not take (left out of the final run).
GRADIENT_ONLY = ("checkpoint_every", "adjoint_linsolver")


@dataclass
class TensionPlan:
    """What :func:`optimal_tensions` found.

    Attributes
    ----------
    tensions : dict
        {cable: Knots} the optimal tension input of each cable [N].
    history : list of float
        The loss at the start and after each iteration.
    result : Result or SystemResult
        The run with the optimal tensions.
    model : Model or System
        The model with the optimal tensions.
    success : bool
    message : str
        The optimiser's.
    evaluations : int
        Losses and gradients computed.
    """

    tensions: dict
    history: list
    result: object
    model: object
    success: bool
    message: str
    evaluations: int


def optimal_tensions(model, t_end, loss, cables, knots, bounds=(0.0, None), start=0.0, max_iterations=100,
                     horizons=None, **simulate_options):
    """The knot values of the tensions of ``cables`` that minimise ``loss`` over a run to ``t_end`` [s].

    Parameters
    ----------
    model : Model or System
    t_end : float
        End time [s].
    loss : rodmol.losses.Loss
    cables : list of str
        The cables whose tensions are sought (a Model's names, ``"cable 11"`` or ``"11"``;
        a System's ``"<rod>.<cable>"``); each becomes a knot input on ``knots``.
    knots : (m,) array
        The knot times [s], increasing.
    bounds : (float, float or None)
        Lower and upper bound of every knot value [N] (None: no upper bound).
    start : float or (len(cables), m) array
        The starting values [N] (clipped into ``bounds``).
    max_iterations : int
        L-BFGS-B's iteration cap (per horizon).
    horizons : list of float, optional
        Growing ends [s] of the run, each optimised from the last one's tensions on the
        loss's terms up to it (``Loss.until``), then the whole run: a long track pulls a
        start of zero tension far from the recorded motion, where L-BFGS-B stops in a
        local minimum (the bending test of ``solvers/optimal_tensions.py`` at N = 30 over
        6 s ended at the 5 N bound); a short one does not.
    **simulate_options
        As for :func:`rodmol.gradients.gradient` (``initial``, ``rtol``, ...).

    Returns
    -------
    TensionPlan
    """
    if isinstance(cables, str) or not cables:
        raise ParameterError(f"`cables` must be a non-empty list of cable names, got {_checks.short(cables)}")
    knots = np.asarray(knots, dtype=float)
    if knots.ndim != 1 or len(knots) < 1 or not np.all(np.isfinite(knots)) or np.any(np.diff(knots) <= 0):
        raise ParameterError(f"`knots` must be increasing finite times [s], got {_checks.short(knots)}")
    low, high = _bounds(bounds)
    values = np.broadcast_to(np.asarray(start, dtype=float), (len(cables), len(knots)))
    if not np.all(np.isfinite(values)):
        raise ParameterError(f"`start` must be finite tensions [N], got {_checks.short(start)}")
    values = np.clip(values, low, high if high is not None else np.inf)
    ends = _horizons(horizons, t_end)
    keys = [_key(model, cable) for cable in cables]
    changes = {key: Tension(Knots(knots, v, source=f"{key} planned")) for key, v in zip(keys, values)}
    base = _variant(model, changes)
    chosen = named_parameters.parameters(base, keys)
    history, count = [], [0]

    def at(x):
        m, i = base, 0
        for p in chosen:
            m, i = p.at(m, x[i:i + p.size]), i + p.size
        return m

    x = values.ravel().copy()
    for end in ends:
        part = loss if end == t_end else loss.until(end)
        if part is None:  # no term of the loss before this end
            continue
        x, result = _minimise(at, keys, end, part, x, (low, high), max_iterations, history, count, simulate_options)
        if end < t_end:  # the knots after this end start the next horizon holding the last one's value
            grid = x.reshape(len(cables), len(knots))
            last = max(int(np.searchsorted(knots, end, side="right")) - 1, 0)
            grid[:, last + 1:] = grid[:, last:last + 1]
            x = grid.ravel()
    best = at(x)
    run_options = {k: v for k, v in simulate_options.items() if k not in GRADIENT_ONLY}
    final = simulate(best, t_end, **run_options)
    tensions = {cable: Knots(knots, x[i * len(knots):(i + 1) * len(knots)], source="optimal_tensions")
                for i, cable in enumerate(cables)}
    return TensionPlan(tensions, history, final, best, bool(result.success), str(result.message), count[0])


def _minimise(at, keys, t_end, loss, x0, bounds, max_iterations, history, count, options):
    """L-BFGS-B from ``x0`` on the run to ``t_end`` [s]: (the values found, scipy's result);
    ``history`` gets the loss at the start and after each iteration, ``count`` the evaluations."""
    cache = {}

    def evaluate(x):
        key = x.tobytes()
        if key not in cache:
            value, grads = gradient(at(x), t_end, loss, keys, **options)
            cache.clear()
            cache[key] = (value, np.concatenate([grads[k] for k in keys]))
            count[0] += 1
        return cache[key]

    first = evaluate(x0)[0]
    norm = first if first > 0 else 1.0  # the optimiser sees the loss relative to the start's
    history.append(first)

    def fun(x):
        value, grad = evaluate(x)
        return value / norm, grad / norm

    result = optimize.minimize(fun, x0, jac=True, method="L-BFGS-B", bounds=[bounds] * len(x0),
                               callback=lambda xk: history.append(evaluate(xk)[0]),
                               options=dict(maxiter=int(max_iterations), ftol=1e-12, gtol=1e-10))
    return result.x, result


def _horizons(horizons, t_end):
    """The run's ends to optimise over, increasing, the last ``t_end``."""
    if horizons is None:
        return [float(t_end)]
    ends = _checks.floats(horizons)
    if ends is None or ends.ndim != 1 or not np.all(np.isfinite(ends)) or np.any(ends <= 0) \
            or np.any(np.diff(ends) <= 0) or (len(ends) and ends[-1] > t_end):
        raise ParameterError(f"`horizons` must be increasing times in (0, t_end = {t_end!r}] s, "
                             f"got {_checks.short(horizons)}")
    return [float(e) for e in ends if e < t_end] + [float(t_end)]


def _bounds(bounds):
    try:
        low, high = bounds
    except (TypeError, ValueError):
        raise ParameterError(f"`bounds` must be (low, high) [N], got {_checks.short(bounds)}") from None
    low = _checks.non_negative("bounds[0]", low, " N")
    if high is not None:
        high = _checks.finite("bounds[1]", high)
        if high <= low:
            raise ParameterError(f"`bounds` must have high > low, got {_checks.short(bounds)}")
    return low, high


def _key(model, cable):
    if not isinstance(cable, str):
        raise ParameterError(f"`cables`: a cable's name must be a string, got {_checks.short(cable)}")
    if isinstance(model, System):
        rod, _, name = cable.partition(".")
        if not name:
            raise ParameterError(f"`cables`: a System's cable is '<rod>.<cable>', got {cable!r}")
        return f"rods.{rod}.tension.{name}"
    return f"tension.{cable}"


def _variant(model, changes):
    if isinstance(model, System):
        return system_variants.variant(model, changes)
    return model_variants.variant(model, changes)
