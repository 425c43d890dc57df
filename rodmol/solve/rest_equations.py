"""The static equations of a rod at rest and their damped Newton solution with
load continuation, shared by the single rod's equilibrium
(:mod:`rodmol.solve.equilibrium`), the systems' (:mod:`rodmol.solve.system_equilibrium`)
and the tension-driven rest states (:mod:`rodmol.solve.tension_statics`).

The unknowns of element b are its node's pose and its cell's strains
(u, Q, q, k: :data:`STATIC_FIELDS`); the rows are the kinematic compatibility
of the pose with the strains and the force and torque balances at rest (the
dynamics' v, w rows with zero velocities).
"""

import weakref

import numpy as np
from scipy import sparse
from scipy.linalg import lu_factor, lu_solve, solve_banded
from scipy.sparse.linalg import splu

from ..discretise import centreline, external, rotations
from ..discretise.jacobian import BandedDifferences
from ..discretise.layout import BlockLayout
from ..discretise.load_entries import load_scale
from ..errors import EquilibriumError
from ..loads import P_STIFFNESS

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
        moved = np.isin(grid.kind, external.HOLDS) & np.any(grid.initial != 0.0, axis=1)
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
        for e in np.flatnonzero(np.isin(grid.kind, external.HOLDS)):
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


def continuation(at, z, tol, max_iter, jacobian, t, end=1.0):
    """The root of ``at(z, lam)`` at ``lam = end``, followed from the root ``z`` at
    lam = 0 by damped Newton steps (:func:`damped_newton`) whose length halves on
    failure: loads ``lam`` <= 1, then held displacements ``lam - 1``."""
    lam, step = 0.0, 1.0
    while lam < end:
        target = min(end, lam + step)
        z_new = damped_newton(lambda x, lam=target: at(x, lam), z, tol, max_iter, jacobian)
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


def damped_newton(fun, z, tol, max_iter, jacobian):
    """Damped Newton with the difference Jacobian ``jacobian``: banded
    (:class:`BandedDifferences`), the step accepted when it lowers |R|, or
    unbanded (``bands`` None: a system's coupled equations, a scipy sparse
    matrix or a dense array), the step accepted
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
                inverse = _factored(matrix)

                def measure(g, inverse=inverse):
                    return np.linalg.norm(inverse(g))

                dz = -inverse(f)
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


def _factored(matrix):
    """g -> matrix^-1 g by an LU of ``matrix``: sparse (scipy's SuperLU) or dense."""
    if sparse.issparse(matrix):
        try:
            return splu(sparse.csc_matrix(matrix)).solve
        except RuntimeError as exc:  # SuperLU's "Factor is exactly singular"
            raise np.linalg.LinAlgError(str(exc)) from exc
    factors = lu_factor(matrix, check_finite=False)
    return lambda g: lu_solve(factors, g, check_finite=False)
