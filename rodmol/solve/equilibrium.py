"""Static equilibrium of the discrete rod: damped Newton with load continuation.

Unknowns per element b: the strains q_b, k_b and the orientation Q_{b+1} of the
next velocity node. Equations: the discrete force and torque balance of the
dynamic right-hand side at rest (v = w = 0), and the pose compatibility
Q_{b+1} = Q_b exp(ds k_b). The Jacobian is banded, built by grouped finite
differences and factorised with ``scipy.linalg.solve_banded``, so the cost
grows linearly with the number of elements.
"""

import numpy as np
from scipy.linalg import solve_banded

from ..discretise import centreline, rotations
from ..errors import EquilibriumError
from ..model import Q_STAR, Model
from ..discretise.system import SemiDiscrete

_BLOCK = 10  # q (3), k (3), Q (4)
# Half-bandwidths of the residual's Jacobian: the balance at node b+1 (rows 0-5
# of block b) reads q, k of block b+1 (columns 0-5 of the next block); the
# compatibility of Q_{b+1} (rows 6-9) reads Q_b (columns 6-9 of the block before).
_LOWER, _UPPER = 9 - (6 - _BLOCK), (_BLOCK + 5) - 0


def equilibrium(model, t=0.0, *, tol=1e-10, max_iter=40):
    """Static equilibrium of ``model`` under its loads at time ``t``.

    Gravity, buoyancy and the cable tensions at ``t`` are applied; velocities
    are zero. Newton's method is tried on the full load first and, if it
    fails, on a continuation path that ramps the loads from zero.

    Parameters
    ----------
    model : Model
    t : float
        Time [s] at which the cable tensions are evaluated.
    tol : float
        Required max-norm of the force and torque residuals, relative to
        the load scale (net weight plus tensions, see ``Model.load_scale``);
        raised to the round-off floor of the difference quotients on very
        fine grids (about 2e-9 at N = 800 for the paper's arm).

    Returns
    -------
    numpy.ndarray
        A state vector (see ``rodmol.layout``) that is a rest state of the
        dynamic right-hand side.

    Raises
    ------
    EquilibriumError
        If no equilibrium is found (e.g. a buckling load).
    """
    if not isinstance(model, Model):
        raise TypeError(f"`model` must be a rodmol.Model, got {model!r}")
    system = SemiDiscrete(model)
    n = model.n_elements
    scale = model.load_scale(t)
    # Feedback tensions get state=None here: there is no motion yet to feed back.
    tensions = model.tensions(t, None)
    quat0 = rotations.from_matrix(model.base.rotation)
    z = np.tile(np.concatenate([Q_STAR, np.zeros(3), quat0]), n)
    if scale == 0.0:
        return _state(model, system, z, quat0)

    f_scale = scale / model.rod.length
    # Differencing stresses of size EA * strain over ds loses digits as N grows:
    # never ask for less than ten times that round-off floor.
    tol = max(tol, 10 * np.finfo(float).eps * np.max(model.kl) / (model.ds * f_scale))
    zeros = np.zeros((n, 3))

    def residual(z, lam):
        zb = z.reshape(n, _BLOCK)
        q, k, quat = zb[:, :3], zb[:, 3:6], zb[:, 6:]
        _, _, force, torque = system.balance(q, k, quat, zeros, zeros, zeros[0], zeros[0],
                                             lam * tensions, lam * model.gravity, (zeros, zeros))
        prev = np.vstack([quat0, quat[:-1]])
        compat = quat - rotations.multiply(prev, rotations.from_rotation_vector(model.ds * k))
        return np.hstack([force / f_scale, torque / scale, compat]).ravel()

    lam, step = 0.0, 1.0
    while lam < 1.0:
        target = min(1.0, lam + step)
        z_new = _newton(lambda x, lam=target: residual(x, lam), z, tol, max_iter)
        if z_new is not None:
            z, lam, step = z_new, target, min(1.0, 2.0 * step)
        else:
            step *= 0.5
            if step < 1e-4:
                raise EquilibriumError(
                    f"no static equilibrium found beyond {lam:.4g} of the loads at t = {t} s "
                    "(the rod may buckle under these loads)")
    return _state(model, system, z, quat0)


def _newton(fun, z, tol, max_iter):
    """Damped Newton on a banded system; None if it does not converge."""
    f = fun(z)
    norm = np.linalg.norm(f)
    for _ in range(max_iter):
        if np.max(np.abs(f)) < tol:
            return z
        try:
            dz = solve_banded((_LOWER, _UPPER), _banded_jacobian(fun, z, f), -f)
        except (np.linalg.LinAlgError, ValueError):
            return None
        alpha = 1.0
        while True:
            z_try = z + alpha * dz
            f_try = fun(z_try)
            norm_try = np.linalg.norm(f_try)
            if np.isfinite(norm_try) and norm_try <= (1.0 - 1e-4 * alpha) * norm:
                break
            alpha *= 0.5
            if alpha < 1.0 / 256:
                return None
        z, f, norm = z_try, f_try, norm_try
    return z if np.max(np.abs(f)) < tol else None


def _banded_jacobian(fun, z, f0):
    """Finite-difference Jacobian in ``solve_banded`` storage, one group of
    columns per evaluation (columns further apart than the band never share rows)."""
    lo, up = _LOWER, _UPPER
    width = lo + up + 1
    size = z.size
    ab = np.zeros((width, size))
    h = 1.5e-8 * np.maximum(np.abs(z), 1.0)
    for group in range(min(width, size)):
        cols = np.arange(group, size, width)
        zp = z.copy()
        zp[cols] += h[cols]
        df = fun(zp) - f0
        for d in range(-up, lo + 1):
            rows = cols + d
            ok = (rows >= 0) & (rows < size)
            ab[up + d, cols[ok]] = df[rows[ok]] / h[cols[ok]]
    return ab


def _state(model, system, z, quat0):
    """Full state vector: pose rebuilt from the strains, velocities zero."""
    n, ds = model.n_elements, model.ds
    zb = z.reshape(n, _BLOCK)
    q, k, quat = zb[:, :3], zb[:, 3:6], zb[:, 6:]
    quat = quat / np.linalg.norm(quat, axis=1, keepdims=True)
    u0 = np.asarray(model.base.position, dtype=float)
    u = centreline.positions(u0, np.vstack([quat0, quat]), q, k, ds)[1:]
    zeros = np.zeros((n, 3))
    return system.layout.pack(u0, quat0, u, quat, q, k, zeros, zeros)
