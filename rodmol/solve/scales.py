"""Physical parameters out of any meaningful range, refused before a run.

A medium density of 1e308 kg/m^3 or a gravity of 1e300 m/s^2 are finite, so
every constructor takes them, but no solver can step such a model: the rates
at the straight rod, in units of the tolerances, overflow once the solver
squares them in its error norm (CVODE's weighted root-mean-square norm), and
the run stops at t = 0 with "Convergence tests failed". :func:`check_scales`
evaluates the rates there once (the model's own right-hand side, no physics
of its own) and names the inputs responsible, by evaluating the model with
each of them alone.
"""

import inspect

import numpy as np

from ..discretise.system import SemiDiscrete, straight_state
from ..errors import ParameterError

#: The Model arguments that bring a load, each with the value that removes it.
SOURCES = {"gravity": (0.0, 0.0, 0.0), "medium": None, "cables": (), "loads": (), "base": None}


def check_scales(system, t, atol):
    """Raise a :class:`ParameterError` if the rates of ``system`` at the straight rod at
    time ``t`` [s], divided by the absolute tolerances ``atol`` (per state entry),
    overflow when squared and summed, as the solver's error norm does. A user
    function that fails here is left for the run to report in its own way."""
    worst = _worst(system, t, atol)
    if worst is None or np.isfinite(worst):
        return
    causes = _causes(system, t, atol)
    what = (", ".join(causes) if causes else
            "no input alone: their combination with the rod's material and geometry")
    largest = _largest(system, t, atol)
    size = f"up to {largest:.3g} tolerances per second" if np.isfinite(largest) else "beyond the largest float"
    raise ParameterError(
        f"physical parameters out of any meaningful range: at the straight rod (t = {float(t):g} s) "
        f"the state's rates ({size}) overflow the solver's error norm, so no step can be taken; "
        f"it comes from {what}")


def _rates(system, t):
    """dy/dt at the straight rod at time t, or None if a user function fails there."""
    try:
        with np.errstate(all="ignore"):
            return system(t, straight_state(system.model))
    except Exception:  # noqa: BLE001 (the run reports the user's function, with its time)
        return None


def _worst(system, t, atol):
    """Sum of the squared rates in tolerance units (inf when they overflow), or None."""
    rates = _rates(system, t)
    if rates is None:
        return None
    with np.errstate(all="ignore"):
        return float(np.sum((rates / atol) ** 2))


def _largest(system, t, atol):
    with np.errstate(all="ignore"):
        return float(np.max(np.abs(_rates(system, t) / atol)))


def _causes(system, t, atol):
    """The inputs that overflow on their own, as text: each kept, the others removed, and
    gravity, which buoyancy and weight need, at the Model's default for all but itself."""
    model, found = system.model, []
    standard = inspect.signature(type(model)).parameters["gravity"].default
    for name in SOURCES:
        alone = model.replace(**{**SOURCES, "gravity": standard, name: getattr(model, name)})
        worst = _worst(SemiDiscrete(alone, system.scheme), t, atol)
        if worst is not None and not np.isfinite(worst):
            found.append(_describe(model, name, t))
    return found


def _describe(model, name, t):
    if name == "gravity":
        return f"`gravity` = {tuple(model.gravity.tolist())} m/s^2"
    if name == "medium":
        return f"the medium's density `rho` = {model.medium.rho!r} kg/m^3"
    if name == "cables":
        return f"the cables' tensions at t = {float(t):g} s ({', '.join(repr(c.name) for c in model.cables)})"
    if name == "loads":
        return f"the loads ({', '.join(repr(getattr(x, 'name', x)) for x in model.loads)})"
    return "the base's motion (`base`)"
