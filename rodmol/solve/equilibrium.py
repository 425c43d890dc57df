"""Static equilibrium of the discrete rod: damped Newton with load continuation.

Unknowns per element b: the pose (u, Q) of velocity node b + 1 and the strains
(q, k) of strain node b. Equations: the force and torque balance of the
system's own right-hand side at rest (v = w = 0), so every load the dynamics
sees acts here too, and the pose compatibility of the element, Q_{b+1} =
Q_b exp(ds k_b) and u_{b+1} = u_b + the chord of ``centreline.chords`` (so
the resting state's positions are the ones ``Result.positions`` rebuilds).
The Jacobian is banded: its half-bandwidths and the column groups of its
finite differences are the block layout's, derived from the system's
dependency table (``BlockLayout.bandwidths``, ``BlockLayout.colouring``, as
the compiled Jacobian of the dynamics takes them), and it is factorised with
``scipy.linalg.solve_banded``: the cost grows linearly with N.
"""


import numpy as np

from ..discretise.assembly import Assembly
from ..discretise.load_entries import load_scale
from ..discretise.schemes import DEFAULT_SCHEME, get_scheme
from ..discretise.system import SemiDiscrete
from ..errors import EquilibriumError, ParameterError
from ..model import Model
from ..systems import System
from .rest_equations import RestEquations, continuation, damped_newton
from .system_equilibrium import free_rest_state


def equilibrium(model, t=0.0, *, scheme=None, tol=1e-10, max_iter=40, start=None):
    """Static equilibrium of ``model`` under its loads at time ``t``.

    Gravity, buoyancy, the cable tensions and the external loads at ``t`` are
    applied (contact included); velocities are zero. Newton's method is tried
    on the full load first and, if it fails, on a continuation path that
    ramps the loads from zero.

    Parameters
    ----------
    model : Model, SemiDiscrete, System or Assembly
        The model, or its system if one is built already (``simulate`` passes
        its own; a loop over many equilibria of one model saves the build and
        the Jacobian's structure, kept per system). A :class:`rodmol.System`
        (or its :class:`~rodmol.discretise.assembly.Assembly`): the rods'
        rest states and the free bodies' poses (see :func:`system_rest_state`).
    t : float
        Time [s] at which the time-dependent inputs are evaluated.
    scheme : str, optional
        The spatial scheme (``rodmol.SCHEMES``) whose rest state is sought: a
        state at rest for one scheme is not at rest for the other. Default:
        ``"centred"`` for a Model, the system's own for a system (another
        one is refused).
    tol : float
        Required max-norm of the force and torque residuals, relative to the
        load scale (:func:`rodmol.discretise.load_entries.load_scale`);
        raised to the round-off floor of the difference quotients on very
        fine grids.
    start : array, optional
        A nearby rest state of a rod (e.g. of the same rod at a slightly other
        parameter value), tried first by Newton at the full loads; the
        continuation from the undeformed rod is the fallback. Ignored for a
        System and under feedback tensions.

    Returns
    -------
    numpy.ndarray
        A state vector that is a rest state of the dynamic right-hand side
        (of a System: the assembled state, ``Assembly.parts``).

    Feedback tensions T(t, state) read the rest state: the tensions are
    iterated (Newton's method on the feedback cables' tensions, each step an
    equilibrium under frozen tensions) until the law, evaluated on the rest
    state, gives back the tensions that hold it there.

    Raises
    ------
    EquilibriumError
        If no equilibrium is found (e.g. a buckling load), or the one found
        has degenerate elements (see :mod:`rodmol.solve.watch`).
    """
    if isinstance(model, (System, Assembly)):
        return system_rest_state(model, t, scheme=scheme, tol=tol, max_iter=max_iter)
    if isinstance(model, SemiDiscrete):  # a system built already (simulate's): its scheme
        system = model
        if scheme is not None and get_scheme(scheme) != system.scheme:
            raise ParameterError(f"`scheme` {scheme!r}: the system given is built with the "
                                 f"{system.scheme.name!r} scheme (leave `scheme` out, or pass the model)")
    elif isinstance(model, Model):
        system = SemiDiscrete(model, DEFAULT_SCHEME if scheme is None else scheme)
    else:
        raise ParameterError(f"`model` must be a rodmol.Model or its SemiDiscrete, got {model!r}")
    if system.model.feedback:
        y = _closed_loop(system, t, tol, max_iter)
    else:
        y = _rest_state(system, t, tol, max_iter, start=start)
    problem = system.state_problem(t, y)
    if problem:
        raise EquilibriumError(f"the static equilibrium is not a valid state of the rod: {problem}")
    return y


def system_rest_state(system, t=0.0, *, scheme=None, tol=1e-10, max_iter=40):
    """The rest state of a :class:`rodmol.System` (or its Assembly). With every
    body fixed or driven and no joint between two rods, no rod acts on another,
    so each rod's rest state is a single rod's (:func:`equilibrium`) clamped
    where its joint puts it; the bodies stay at their initial poses. Rods
    joined to each other are solved together, as with a free body, whose pose is not fixed
    by the rates' zeros (its pose rates are its velocities, zero at any pose)
    but by the balance of its loads: the rods and the free bodies' poses are
    solved together (:func:`rodmol.solve.system_equilibrium.free_rest_state`),
    an EquilibriumError if a free body is held by nothing."""
    if isinstance(system, System):
        system = Assembly(system, scheme)
    elif scheme is not None and get_scheme(scheme) != system.scheme:
        raise ParameterError(f"`scheme` {scheme!r}: the system given is built with the "
                             f"{system.scheme.name!r} scheme (leave `scheme` out, or pass the System)")
    if system.free or system.rod_joints or system.rod_pairs is not None:  # coupled
        return free_rest_state(system, t, tol, max_iter)
    y = system.undeformed_state()
    for name, rod in system.rods.items():
        try:
            y[system.parts[name]] = equilibrium(rod, t, tol=tol, max_iter=max_iter)
        except EquilibriumError as exc:
            raise EquilibriumError(f"rod {name!r}: {exc}") from exc
    return y


def _closed_loop(system, t, tol, max_iter, max_rounds=30):
    """The rest state under feedback tensions: Newton on the tensions T of the
    feedback cables, F(T) = law(rest state under T) - T = 0, with differences."""
    model = system.model
    feedback = np.array([c.tension.feedback for c in model.cables])

    def law(y):
        return system.tensions(t, y)

    y = system.undeformed_state()
    tensions = law(y)
    # A displacement-controlled cable's law on the undeformed rod can ask for far
    # more than the arm carries (the rigid-rod tension); start it slack.
    tensions[[c.actuated for c in model.cables]] = 0.0
    scale = max(load_scale(model, t, tensions, system.grid_loads), 1e-12)
    warm = None
    # One feedback cable: F(T) decreases with T for a tendon (more pull, a
    # shorter path, less stretch), so a bracket [low, high] of its root
    # safeguards Newton across the kink where the cable goes slack.
    low, high = 0.0, np.inf
    for _ in range(max_rounds):
        y = _rest_state(system, t, tol, max_iter, tensions, start=warm)
        warm = y
        residual = (law(y) - tensions)[feedback]
        if np.max(np.abs(residual)) <= 1e-9 * scale:
            return y
        if residual.size == 1:
            if residual[0] > 0.0:
                low = max(low, tensions[feedback][0])
            else:
                high = min(high, tensions[feedback][0])
        jac = np.empty((residual.size, residual.size))
        for j, i in enumerate(np.flatnonzero(feedback)):
            h = 1e-6 * max(abs(tensions[i]), scale)
            shifted = tensions.copy()
            shifted[i] += h
            jac[:, j] = ((law(_rest_state(system, t, tol, max_iter, shifted, start=y)) - shifted)[feedback]
                         - residual) / h
        try:
            step = np.linalg.solve(jac, -residual)
        except np.linalg.LinAlgError:
            break
        # On fine grids the law's value carries the rest state's round-off
        # (a stiff tendon amplifies path-length noise): a step below the
        # tension's resolution with a small residual is converged too.
        if (np.max(np.abs(step)) <= 1e-9 * max(np.max(np.abs(tensions)), scale)
                and np.max(np.abs(residual)) <= 1e-6 * scale):
            return y
        tensions = tensions.copy()
        tensions[feedback] = np.maximum(tensions[feedback] + step, 0.0)
        if residual.size == 1 and np.isfinite(high) and not low < tensions[feedback][0] < high:
            tensions[feedback] = 0.5 * (low + high)
    raise EquilibriumError(f"no static equilibrium found for the feedback tensions at t = {t} s "
                           "(the law and the arm have no common rest state, or it is unstable)")


#: The static layout and banded differences of each system, built at its first equilibrium:
#: a loop of equilibria (inverse statics, the closed loop) reuses them.
def _rest_state(system, t, tol, max_iter, tensions=None, start=None):
    """The rest state under the loads at t (cable ``tensions`` [N] if given).
    ``start``, a nearby rest state (the closed loop's last iterate), is tried
    first at the full loads; the continuation from the undeformed rod is the
    fallback."""
    equations = RestEquations(system, t, tensions)
    y = system.undeformed_state()
    if equations.unloaded:
        return y
    z = equations.unknowns(y)
    tol = equations.tolerance(tol)
    residual, jacobian = equations.residual, equations.differences
    # With held points moved off their rest positions the path has two legs: the
    # other loads first (the rod sags as it would held where it rests), then the
    # held displacements; pulled in at once, a slack rod could stay on the
    # straight, compressed branch.
    end = 2.0 if equations.holds_moved else 1.0

    def at(x, lam):
        return residual(x, min(lam, 1.0), held=max(lam - 1.0, 0.0) if end > 1.0 else None)

    if start is not None:
        z_warm = damped_newton(residual, equations.unknowns(start), tol, max_iter, jacobian)
        if z_warm is not None:
            return equations.state(z_warm)
    z = continuation(at, z, tol, max_iter, jacobian, t, end)
    return equations.state(z)
