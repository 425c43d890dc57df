"""The pieces of the inverse statics shared by a rod's and a system's: the
bounded Levenberg-Marquardt loop over inputs whose every iterate is a static
equilibrium, the bounds' checks, the cables chosen, the verdict, and a model
with the found cable inputs."""

from dataclasses import replace

import numpy as np
from scipy.optimize import lsq_linear

from .. import _checks
from ..errors import EquilibriumError, ParameterError

#: Default reach tolerance [m] on the weighted residual.
REACH_TOLERANCE = 1e-4
#: The loop stops once the residual is this fraction of the reach tolerance.
PRECISION = 1e-3


def levenberg_marquardt(problem, target, inputs, tol, max_iter):
    """Levenberg-Marquardt with bounds from ``inputs``.

    ``problem`` gives ``rest(p)`` (the equilibrium under inputs p, warm-started
    from ``problem.warm``, which the loop sets back to the accepted one after a
    rejected trial; an EquilibriumError shortens the step), ``values(rest)``
    (the weighted outputs), ``jacobian(rest, p)`` (d values / d p), ``low`` and
    ``high`` (the bounds) and counts its ``equilibria``.

    Returns
    -------
    (p, rest, residual vector, accepted steps)
    """
    problem.equilibria = 0
    y = problem.rest(inputs)
    r = problem.values(y) - target
    if max_iter == 0:  # the forward statics
        return inputs, y, r, 0
    jac = problem.jacobian(y, inputs)
    mu = 1e-6 * max(np.max(np.sum(jac**2, axis=0)), 1e-30)
    growth = 2.0  # Nielsen's: each rejection in a row grows the damping twice as fast
    accepted, n = 0, len(inputs)
    for _ in range(max_iter):
        cost = r @ r
        if np.sqrt(cost) <= PRECISION * tol:
            break
        system = np.vstack([jac, np.sqrt(mu) * np.eye(n)])
        step = lsq_linear(system, np.concatenate([-r, np.zeros(n)]),
                          bounds=(problem.low - inputs, problem.high - inputs), method="bvls").x
        linear = r + jac @ step
        predicted = cost - linear @ linear
        if (predicted <= 1e-12 * cost or np.max(np.abs(step)) <= 1e-12 * (1.0 + np.max(np.abs(inputs)))
                or np.sqrt(cost) - np.sqrt(cost - predicted) <= PRECISION * tol):
            break  # a bounded minimum: no step within the bounds lowers the residual by the precision asked
        trial = np.clip(inputs + step, problem.low, problem.high)
        try:
            y_new = problem.rest(trial)
        except EquilibriumError:  # e.g. buckling under the trial inputs: a shorter step
            ratio = -np.inf
        else:
            r_new = problem.values(y_new) - target
            ratio = (cost - r_new @ r_new) / predicted
        if ratio > 1e-4:
            inputs, y, r = trial, y_new, r_new
            jac = problem.jacobian(y, inputs)
            accepted += 1
            mu, growth = mu / 3.0 if ratio > 0.75 else mu * 4.0 if ratio < 0.25 else mu, 2.0
        else:
            problem.warm = y  # the next trial starts from the accepted state
            mu, growth = mu * 2.0 * growth, 2.0 * growth
    return inputs, y, r, accepted


def actuated(names, cables, where="the model"):
    """Indices into ``names`` of the ``cables`` named (a name or names; None: all)."""
    if cables is None:
        return np.arange(len(names))
    if isinstance(cables, str):
        cables = [cables]
    try:
        chosen = list(cables)
    except TypeError:
        raise ParameterError(f"`cables` must name cables of {where}, got {_checks.short(cables)}") from None
    if not chosen or len(set(chosen)) != len(chosen):
        raise ParameterError(f"`cables` must name distinct cables of {where}, got {_checks.short(cables)}")
    for name in chosen:
        if name not in names:
            raise ParameterError(f"`cables`: no cable named {name!r} in {where}" + _checks.did_you_mean(name, names))
    return np.array([names.index(n) for n in chosen], dtype=int)


def check_bounds(name, bounds, count, what, unit, lowest=None):
    """(low, high), each (count,), of ``bounds`` = (low, high): numbers or one per
    input (``what`` names them); low > ``lowest`` if given, low < high."""
    try:
        low, high = bounds
    except (TypeError, ValueError):
        raise ParameterError(f"`{name}` must be (low, high) [{unit}], got {_checks.short(bounds)}") from None
    out = []
    for side, value in (("low", low), ("high", high)):
        arr = _checks.floats(value)
        if arr is None or arr.ndim > 1 or (arr.ndim == 1 and arr.shape != (count,)):
            raise ParameterError(f"`{name}` {side} must be a number or {count} numbers (one per {what}), "
                                 f"got {_checks.short(value)}")
        if np.any(np.isnan(arr)):
            raise ParameterError(f"`{name}` {side} must not be NaN, got {_checks.short(value)}")
        out.append(np.broadcast_to(arr, (count,)).astype(float))
    low, high = out
    if lowest is not None and (np.any(~np.isfinite(low)) or np.any(low < lowest)):
        raise ParameterError(f"`{name}` low must be finite and >= {lowest:g} {unit} (cables only pull), got "
                             f"{_checks.short(bounds)}")
    if np.any(low >= high):
        raise ParameterError(f"`{name}` low must be < high for every {what}, got {_checks.short(bounds)} "
                             f"(to hold one fixed, leave it out of the inputs)")
    return low, high


def at_bounds(values, low, high, names):
    """{name: "lower" or "upper"} of the inputs at a bound (to 1e-9 of the largest finite bound)."""
    sizes = np.abs(np.concatenate([low, high]))
    scale = 1e-9 * max(1.0, float(np.max(sizes[np.isfinite(sizes)], initial=1.0)))
    active = {}
    for name, value, lo, hi in zip(names, values, low, high):
        if value <= lo + scale:
            active[name] = "lower"
        elif value >= hi - scale:
            active[name] = "upper"
    return active


def verdict(residual, tol, iterations, equilibria, active, high, far=()):
    """The fit's message: the target met, or not and why: ``far``, the tip targets out of
    the rods' reach (:func:`out_of_reach`), the inputs at their bounds (``high`` {name: its
    upper bound as text, with its unit}), or else a local minimum."""
    how = f"in {iterations} step{'' if iterations == 1 else 's'} ({equilibria} equilibria)"
    if residual <= tol:
        return f"target met to {residual:.3g} m {how}"
    upper = [f"{name} ({high[name]})" for name, side in active.items() if side == "upper"]
    why = (f" (out of reach: {'; '.join(far)})" if far else "" if upper
           else " (a local minimum: another `start` may do better)")
    return (f"target not reached within the bounds{why}: residual {residual:.3g} m > tol {tol:.3g} m "
            f"{how}; at an upper bound: {', '.join(upper) or 'none'}; at the lower bound: "
            f"{', '.join(n for n, side in active.items() if side == 'lower') or 'none'}")


def with_cables(model, tensions, displacements):
    """``model`` whose cables pull with ``tensions`` ({name: N}, a constant where it
    differs) or whose actuators sit at ``displacements`` ({name: m})."""
    cables = []
    for c in model.cables:
        if c.name in displacements:
            c = replace(c, tension=None, displacement=displacements[c.name])
        elif c.name in tensions and c.tension.constant != tensions[c.name]:
            c = replace(c, tension=float(tensions[c.name]))
        cables.append(c)
    return model.replace(cables=cables)


def cable_displacements(model, view, index, tensions):
    """{name: actuator position z [m]} holding ``tensions`` (one per cable of ``index``) for
    the displacement-controlled ones among the cables ``index`` of ``model``, over the path
    lengths of the StateView ``view`` (the tendon law inverted)."""
    out = {}
    for i, tension in zip(index, tensions):
        cable = model.cables[i]
        if cable.actuated:
            out[cable.name] = float(cable.tension.position_for(view.cable_length(cable.name), tension))
    return out


def out_of_reach(what, base, target, length):
    """A note if ``target`` [m] is farther from the fixed ``base`` [m] than the rod's
    ``length`` [m] (``what`` names the rod's tip), else None."""
    distance = float(np.linalg.norm(np.asarray(target) - np.asarray(base)))
    if distance <= length:
        return None
    return f"{what} is aimed {distance:.3g} m from its base, farther than the rod's length {length:.3g} m"
