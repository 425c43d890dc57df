"""Rest states as functions of the cable tensions, for loops over many
nearby equilibria (the inverse statics, :mod:`rodmol.control.inverse_statics`):
the rest state under given tensions and its exact derivative with respect to
them, from the equilibrium's own equations (:mod:`rodmol.solve.equilibrium`)."""

import numpy as np
from scipy.linalg import solve_banded

from .equilibrium import _rest_state
from .rest_equations import RestEquations


def tension_sensitivity(system, y, tensions, t=0.0):
    """d y / d T of the rest state ``y`` under cable ``tensions``, exactly.

    By the implicit-function theorem, R(z(T); T) = 0 gives dR/dz dz/dT =
    -dR/dT: one banded solve with the equilibrium's Jacobian, columns for
    every cable. The right-hand side is affine in the tensions, so dR/dT is
    a difference of residuals without truncation error.

    Parameters
    ----------
    system : SemiDiscrete
        A system whose kernel sees every cable (a cable slack by its constant
        input is left out of the kernel; see
        :func:`rodmol.discretise.hand_tensions.tensions_by_hand`).
    y : (size,) array
        A rest state under ``tensions`` (``rodmol.equilibrium``).
    tensions : (n_cables,) array [N]
    t : float
        Time [s] at which the other loads are read.

    Returns
    -------
    (size, n_cables) array
        d y / d T_j [per N], in the state layout (positions in m per N,
        global frame; strains per N, local frame); zero in the base and
        velocity rows.
    """
    tensions = np.asarray(tensions, dtype=float)
    equations = RestEquations(system, t, tensions)
    z = equations.unknowns(y)
    r0 = equations.residual(z)
    d_r = np.empty((z.size, tensions.size))
    for j in range(tensions.size):
        shifted = tensions.copy()
        shifted[j] += 1.0
        d_r[:, j] = equations.residual(z, tensions=shifted) - r0
    d_z = solve_banded(equations.bands, equations.jacobian(z), -d_r)
    out = np.zeros((tensions.size, system.size))
    blocks = equations.static.blocks(d_z.T)  # (n_cables, N, 13)
    for f, sl in equations.static.slices().items():
        system.layout.field(out, f)[:] = blocks[..., sl]
    return out.T


def rest_state(system, tensions, t=0.0, *, start=None, tol=1e-10, max_iter=40):
    """The rest state of ``system`` under cable ``tensions`` [N] (the other
    loads at t), as :func:`equilibrium` finds it but without its checks:
    Newton's method from ``start`` (a nearby rest state) first, the load
    continuation from the undeformed rod (its rest shape) if that fails. For loops that solve
    many nearby equilibria (the inverse statics); raises
    :class:`EquilibriumError` if none is found."""
    return _rest_state(system, t, tol, max_iter, tensions, start)
