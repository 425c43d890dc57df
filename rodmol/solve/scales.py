"""Physical parameters out of any meaningful range, refused before a run.

A medium density of 1e308 kg/m^3 or a gravity of 1e300 m/s^2 are finite, so
every constructor takes them, but no solver can step such a model: the rates
at the straight rod, in units of the tolerances, or their derivatives
overflow once the solver squares them (in CVODE's weighted root-mean-square
norm, in the Newton iteration), and the run stops at t = 0 with "Convergence
tests failed". :func:`check_scales` evaluates the rates and the Jacobian there
once (the model's own right-hand side and compiled Jacobian, no physics of
its own) and names the inputs responsible, by evaluating the model with each
of them alone.
"""

import inspect

import numpy as np

from ..discretise.system import SemiDiscrete
from ..errors import ParameterError

#: The Model arguments that bring a load, each with the value that removes it.
SOURCES = {"gravity": (0.0, 0.0, 0.0), "medium": None, "cables": (), "loads": (), "base": None}


def check_scales(system, t, atol):
    """Raise a :class:`ParameterError` if the first evaluation of ``system`` at the
    straight rod at time ``t`` [s] overflows what the solver computes from it: the
    rates divided by the absolute tolerances ``atol`` (per state entry), squared and
    summed in its error norm, or the Jacobian's entries, squared in its Newton
    iteration. A user function that fails here is left for the run to report."""
    sizes = _sizes(system, t, atol)
    if sizes is None or not _overflows(sizes):
        return
    causes = _causes(system, t, atol)
    what = ", ".join(causes) if causes else "no input alone: their combination with the rod's material and geometry"
    rates, _, jacobian = sizes
    detail = f"rates of up to {rates:.3g} tolerances per second, their derivatives up to {jacobian:.3g} per second"
    raise ParameterError(
        f"physical parameters out of any meaningful range: at the straight rod (t = {float(t):g} s) the "
        f"first evaluation ({detail}) overflows the solver's norms, so no step can be taken; it comes from "
        f"{what}")


def _sizes(system, t, atol):
    """(largest rate in tolerance units [1/s], the sum of their squares, largest Jacobian
    entry) at the straight rod, inf where they overflow, or None if a user function fails there."""
    y = system.undeformed_state()
    try:
        with np.errstate(all="ignore"):
            rates = system(t, y)
    except Exception:  # noqa: BLE001 (the run reports the user's function, with its time)
        return None
    with np.errstate(all="ignore"):
        scaled = np.abs(rates / atol)
        largest, squares = float(np.max(scaled)), float(np.sum(scaled**2))  # the error norm's squares
        try:
            jacobian = system.jacobian(system.atol_scale(), matrix=None)
            jacobian.evaluate(t, y, rates)
            entries = max(float(np.max(np.abs(b), initial=0.0)) for b in jacobian.blocks)
        except ValueError:  # a structure the compiled Jacobian does not take: the rates decide
            entries = 0.0
    return largest, squares, entries if np.isfinite(entries) else np.inf


def _overflows(sizes):
    _, squares, jacobian = sizes
    with np.errstate(over="ignore"):
        return not (np.isfinite(squares) and np.isfinite(np.float64(jacobian) ** 2))


def _causes(system, t, atol):
    """The inputs that overflow on their own, as text: each kept, the others removed, and
    gravity, which buoyancy and weight need, at the Model's default for all but itself."""
    model, found = system.model, []
    standard = inspect.signature(type(model)).parameters["gravity"].default
    for name in SOURCES:
        alone = model.replace(**{**SOURCES, "gravity": standard, name: getattr(model, name)})
        sizes = _sizes(SemiDiscrete(alone, system.scheme), t, atol)
        if sizes is not None and _overflows(sizes):
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
