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

import weakref

import numpy as np
from scipy.linalg import lu_factor, lu_solve, solve_banded

from ..discretise import centreline, external, rotations
from ..discretise.assembly import Assembly
from ..discretise.jacobian import BandedDifferences
from ..discretise.layout import BlockLayout
from ..discretise.load_entries import load_scale
from ..discretise.schemes import DEFAULT_SCHEME, get_scheme
from ..discretise.system import SemiDiscrete
from ..errors import EquilibriumError, ParameterError
from ..loads import P_STIFFNESS
from ..model import Model
from ..systems import System
from .watch import state_problem

#: Unknowns per element, and the equation each row of a block carries:
#: u -> position compatibility, Q -> orientation compatibility, q -> force
#: balance, k -> torque balance.
STATIC_FIELDS = {"u": 3, "Q": 4, "q": 3, "k": 3}
#: Largest continuation step over the held points' displacements: a long jump
#: from the sagging rod could land a slack one on another branch (an S-shape).
HELD_STEP = 0.125
_COMPATIBILITY = {"u": {-1: ("u", "Q"), 0: ("u", "q", "k")}, "Q": {-1: ("Q",), 0: ("Q", "k")}}


def static_dependencies(depends):
    """The equilibrium's dependency table, from the system's."""
    def at_rest(row):
        return {off: tuple(c for c in cols if c in STATIC_FIELDS) for off, cols in depends[row].items()}
    return {**_COMPATIBILITY, "q": at_rest("v"), "k": at_rest("w")}


def equilibrium(model, t=0.0, *, scheme=None, tol=1e-10, max_iter=40):
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
    solve = _closed_loop if system.model.feedback else _rest_state
    y = solve(system, t, tol, max_iter)
    problem = state_problem(system.layout, system.model.ds, t, y)
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
    if system.free or system.rod_joints:  # coupled; same floor: the coupled equations build on this module's
        from .system_equilibrium import free_rest_state

        return free_rest_state(system, t, tol, max_iter)
    y = system.initial_state()
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
_STRUCTURES = weakref.WeakKeyDictionary()


def _structure(system):
    """(static ``BlockLayout``, its ``BandedDifferences``) of ``system``, built once."""
    found = _STRUCTURES.get(system)
    if found is None:
        static = BlockLayout(system.layout.n_blocks, dict(STATIC_FIELDS))
        found = _STRUCTURES[system] = static, BandedDifferences(static, static_dependencies(system.depends))
    return found


class RestEquations:
    """The rest equations R(z; T) = 0 of ``system`` at time t, in the static
    unknowns z (the u, Q, q, k blocks of the state).

    The force and torque rows are divided by the load scale of the tensions
    the equations are built with, so R is dimensionless and its scale does
    not move with T (the implicit-function theorem then needs no correction).

    Parameters
    ----------
    system : SemiDiscrete
    t : float
        Time [s] at which the loads are read.
    tensions : (n_cables,) array [N] or None
        The cable tensions (None: the model's inputs at t).
    """

    def __init__(self, system, t, tensions=None):
        model = system.model
        self.system, self.t, self.tensions = system, t, tensions
        self.layout = system.layout
        self.static, self.differences = _structure(system)
        self.bands = self.differences.bands
        base = model.base
        self._quat0 = rotations.from_matrix(base.rotation)
        self._u0 = np.asarray(base.position, dtype=float)
        self._y = system.undeformed_state()
        self._rates = np.empty(self.layout.size)
        # Views and slices made once: the residual runs thousands of times per solve.
        self._sl, self._state_sl = self.static.slices(), self.layout.slices()
        self._y_blocks, self._rate_blocks = self.layout.blocks(self._y), self.layout.blocks(self._rates)
        self._mass, self._inertia = system.sampled.mass, system.sampled.inertia
        self.scale = load_scale(model, t, tensions, system.grid_loads)
        self.unloaded = self.scale == 0.0 and not model.loads
        grid = system.grid_loads
        moved = np.isin(grid.kind, (external.PIN, external.CLAMP)) & np.any(grid.initial != 0.0, axis=1)
        self.holds_moved = bool(np.any(moved))
        self._force_scale = (self.scale or 1.0) / model.rod.length  # contact alone: forces of about 1 N

    def tolerance(self, tol):
        """``tol`` raised to the round-off floor of the difference quotients, per
        residual row: differencing stresses of size EA * strain over ds loses
        digits as N grows; a hold's stiff penalty (rodmol.Hold) sees positions of
        size L rounded, which raises the floor of its node's force rows only (the
        compatibility rows keep theirs, or the positions would loosen with k)."""
        model, grid = self.system.model, self.system.grid_loads
        floor = 10 * np.finfo(float).eps / self._force_scale
        elastic = max(tol, floor * np.max(self.system.sampled.kl) / model.ds)
        out = self.static.blocks(np.full(self.static.size, elastic))
        for e in np.flatnonzero(np.isin(grid.kind, (external.PIN, external.CLAMP))):
            hold_density = grid.params[e, P_STIFFNESS] * grid.weight[e]
            out[grid.node[e] - 1, self._sl["q"]] = max(elastic, floor * hold_density * model.rod.length)
        return out.ravel()

    @property
    def base(self):
        """(position [m], quaternion) of the base, global: the clamp the rod is at rest on."""
        return self._u0, self._quat0

    def place(self, position, quaternion):
        """Clamp the base at ``position`` [m] with ``quaternion`` (base to global frame),
        both global: a free body's pose moves its rods' bases (:mod:`.system_equilibrium`)."""
        self._u0, self._quat0 = position, quaternion

    def unknowns(self, y):
        """The static unknowns z of a state vector ``y``."""
        return np.hstack([self.layout.field(y, f) for f in STATIC_FIELDS]).ravel()

    def residual(self, z, lam=1.0, tensions=None, held=None):
        """R(z) with the loads scaled by ``lam`` and the held points' displacements
        from rest by ``held`` (default: ``lam``), under ``tensions`` [N] (default:
        the equations' own)."""
        sl, state_sl, model = self._sl, self._state_sl, self.system.model
        ds = model.ds
        zb = self.static.blocks(z)
        for f in STATIC_FIELDS:
            self._y_blocks[:, state_sl[f]] = zb[:, sl[f]]
        tensions = self.tensions if tensions is None else tensions
        self.system.rest_rates(self.t, self._y, self._rates, lam, tensions, held)
        u, quat, q, k = (zb[:, sl[f]] for f in STATIC_FIELDS)
        u_prev = np.vstack([self._u0, u[:-1]])
        q_prev = np.vstack([self._quat0, quat[:-1]])
        out = np.empty_like(zb)
        out[:, sl["u"]] = (u - u_prev - centreline.chords(q_prev, q, k, ds)) / ds
        out[:, sl["Q"]] = quat - rotations.multiply(q_prev, rotations.from_rotation_vector(ds * k))
        out[:, sl["q"]] = self._rate_blocks[:, state_sl["v"]] * self._mass / self._force_scale
        out[:, sl["k"]] = self._rate_blocks[:, state_sl["w"]] * self._inertia / (self.scale or 1.0)
        return out.ravel()

    def state(self, z):
        """The state vector at rest of the static unknowns z: unit quaternions, and
        the positions rebuilt from the strains as ``Result.positions`` does."""
        zb = self.static.blocks(z)
        sl = self.static.slices()
        n = self.system.model.n_elements
        quat = zb[:, sl["Q"]] / np.linalg.norm(zb[:, sl["Q"]], axis=1, keepdims=True)
        q, k = zb[:, sl["q"]], zb[:, sl["k"]]
        u = centreline.positions(self._u0, np.vstack([self._quat0, quat]), q, k, self.system.model.ds)[1:]
        zeros = np.zeros((n, 3))
        return self.layout.pack(self._u0, self._quat0, u, quat, q, k, zeros, zeros)

    def jacobian(self, z):
        """dR/dz at full load, in ``solve_banded`` storage with :attr:`bands`."""
        fun = self.residual
        return self.differences(fun, z, fun(z))


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
        z_warm = _newton(residual, equations.unknowns(start), tol, max_iter, jacobian)
        if z_warm is not None:
            return equations.state(z_warm)
    z = continuation(at, z, tol, max_iter, jacobian, t, end)
    return equations.state(z)


def continuation(at, z, tol, max_iter, jacobian, t, end=1.0):
    """The root of ``at(z, lam)`` at ``lam = end``, followed from the root ``z`` at
    lam = 0 by damped Newton steps (:func:`_newton`) whose length halves on
    failure: loads ``lam`` <= 1, then held displacements ``lam - 1``."""
    lam, step = 0.0, 1.0
    while lam < end:
        target = min(end, lam + step)
        z_new = _newton(lambda x, lam=target: at(x, lam), z, tol, max_iter, jacobian)
        if z_new is not None:
            z, lam, step = z_new, target, min(1.0 if target < 1.0 else HELD_STEP, 2.0 * step)
        else:
            step *= 0.5
            if step < 1e-4:
                what = (f"{lam:.4g} of the loads" if lam < 1.0 else
                        f"the loads and {lam - 1.0:.4g} of the held points' displacements")
                raise EquilibriumError(
                    f"no static equilibrium found beyond {what} at t = {t} s "
                    "(the rod may buckle under these loads)")
    return z


def _newton(fun, z, tol, max_iter, jacobian):
    """Damped Newton with the difference Jacobian ``jacobian``: banded
    (:class:`BandedDifferences`), the step accepted when it lowers |R|, or
    dense (``bands`` None: a system's coupled equations), the step accepted
    when it lowers the Newton correction |J^-1 R| (Deuflhard's natural
    monotonicity test: blind to the rows' scales, where a stiff penalty
    joint's rows would otherwise make |R| rise along every step); None if it
    does not converge."""
    f = fun(z)
    norm = np.linalg.norm(f)
    for _ in range(max_iter):
        if np.all(np.abs(f) < tol):
            return z
        try:
            matrix = jacobian(fun, z, f)
            if jacobian.bands is None:
                factors = lu_factor(matrix, check_finite=False)

                def measure(g, factors=factors):
                    return np.linalg.norm(lu_solve(factors, g, check_finite=False))

                dz = -lu_solve(factors, f, check_finite=False)
                norm = np.linalg.norm(dz)
            else:
                measure, dz = np.linalg.norm, solve_banded(jacobian.bands, matrix, -f)
        except (np.linalg.LinAlgError, ValueError):
            return None
        alpha = 1.0
        while True:
            z_try = z + alpha * dz
            f_try = fun(z_try)
            norm_try = measure(f_try) if np.all(np.isfinite(f_try)) else np.inf
            if np.isfinite(norm_try) and norm_try <= (1.0 - 1e-4 * alpha) * norm:
                break
            alpha *= 0.5
            if alpha < 1.0 / 256:
                return None
        z, f, norm = z_try, f_try, norm_try
    return z if np.all(np.abs(f) < tol) else None
