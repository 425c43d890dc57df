"""Block preconditioner: an exact O(N) solve of CVODE's Newton matrix (I - gamma J).

Within an element block the unknowns split into the pose P = (u, Q) (7), the
strains X = (q, k) (6) and the velocities Z = (v, w) (6). The elimination
below is exact for every structure that fits :data:`TEMPLATE`:

    P_b <- P_b, Z_b                        (u_t = R v, quaternion rate)
    X_b <- X_b, Z_b, Z_{b-1}               (compatibility)
    Z_b <- P_b, X_b, X_{b+1}, Z_{b-1..b+1} (balance laws, loads)

:func:`check_structure` compares a system's declared dependencies with it, so
a scheme or a load that couples more widely is refused instead of making the
preconditioner silently inexact. The P and X unknowns of each element follow
from its Z and its neighbour's through 7x7 and 6x6 local solves; substituting
them leaves a block-tridiagonal system in Z alone (6x6 blocks), solved by block
elimination. Against the band LU of the full system this is ~10x fewer
operations per solve and ~4x less memory, so it is what CVODE's Newton
iterations use, through scikit-sundae's GMRES with this solve as an exact
preconditioner (scikit-sundae accepts no custom direct solver).

Eliminating the diagonal blocks without pivoting across blocks is safe:
I - gamma J_PP and I - gamma J_XX are the identity plus gamma times rotation
rates (small), and the reduced Z system of a stiff elastic rod behaves like I
plus a positive second-difference operator.
"""

import numba
import numpy as np

from .compiling import jit
from .jacobian import read_only
from .layout import BLOCK, HEADER, span

_POSE, _STRAIN, _VELOCITY = ("u", "Q"), ("q", "k"), ("v", "w")
#: The couplings the elimination handles exactly: row fields -> offset -> allowed columns.
TEMPLATE = {
    **{f: {0: _POSE + _VELOCITY} for f in _POSE},
    **{f: {-1: _VELOCITY, 0: _STRAIN + _VELOCITY} for f in _STRAIN},
    **{f: {-1: _VELOCITY, 0: _POSE + _STRAIN + _VELOCITY, 1: _STRAIN + _VELOCITY}
       for f in _VELOCITY},
}
# Where P, X and Z stand in a block, and their sizes (Z has X's), from the layout.
_P, _X, _Z = span(_POSE), span(_STRAIN), span(_VELOCITY)
_P0, _X0, _Z0 = _P.start, _X.start, _Z.start
NP, NX = _P.stop - _P.start, _X.stop - _X.start
if _Z.stop - _Z.start != NX:
    raise ImportError("the block elimination needs as many velocities as strains per block")

# Per-element factors, one row per element so that a solve streams them from
# one array: AINV 7x7, BINV 6x6, SX 6x6, TX 6x6, WP 7x6, LOW, DINV, FWD 6x6,
# copies of J blocks C0 = J_ZX(b), CP = J_ZX(b+1) 6x6, G = J_ZP 6x7.
_FACTOR_SIZES = (NP * NP, NX * NX, NX * NX, NX * NX, NP * NX, NX * NX, NX * NX, NX * NX, NX * NX, NX * NX, NX * NP)
(F_AINV, F_BINV, F_SX, F_TX, F_WP, F_LOW, F_DINV, F_FWD, F_C0, F_CP, F_G,
 N_FACTORS) = (int(i) for i in np.cumsum((0, *_FACTOR_SIZES)))


def check_structure(depends):
    """Raise ValueError naming the first coupling outside :data:`TEMPLATE`."""
    for row, deps in depends.items():
        for offset, cols in deps.items():
            allowed = TEMPLATE[row].get(offset, ())
            extra = [c for c in cols if c not in allowed]
            if extra:
                raise ValueError(f"the block preconditioner cannot solve exactly a coupling of the "
                                 f"{row!r} rates to {extra} of block offset {offset:+d}")


@jit(by_value=True)  # block sizes as constants: unrolled loops, 15% faster setups
def _invert(a, out, n, work):
    """out[:n, :n] = inverse of a[:n, :n] by Gauss-Jordan with partial pivoting."""
    for i in range(n):
        for j in range(n):
            work[i, j] = a[i, j]
            work[i, n + j] = 1.0 if i == j else 0.0
    for c in range(n):
        p = c
        best = abs(work[c, c])
        for r in range(c + 1, n):
            if abs(work[r, c]) > best:
                best, p = abs(work[r, c]), r
        if p != c:
            for j in range(2 * n):
                work[c, j], work[p, j] = work[p, j], work[c, j]
        piv = 1.0 / work[c, c]
        for j in range(2 * n):
            work[c, j] *= piv
        for r in range(n):
            if r != c:
                f = work[r, c]
                if f != 0.0:
                    for j in range(2 * n):
                        work[r, j] -= f * work[c, j]
    for i in range(n):
        for j in range(n):
            out[i, j] = work[i, n + j]


@jit(by_value=True)  # block sizes as constants: unrolled loops, 15% faster setups
def _shifted_inverse(jac, first, size, gamma, m, out, work):
    """out[:size, :size] = (I - gamma J)^-1 of the diagonal block of ``jac``
    starting at row and column ``first``; ``m`` and ``work`` are scratch."""
    for i in range(size):
        for j in range(size):
            m[i, j] = (1.0 if i == j else 0.0) - gamma * jac[first + i, first + j]
    _invert(m, out, size, work)


@jit(by_value=True)  # block sizes as constants: unrolled loops, 15% faster setups
def _store(a, size, row, at):
    """Copy a[:size, :size] row-major into ``row[at:]``."""
    for i in range(size):
        for j in range(size):
            row[at + size * i + j] = a[i, j]


_F8, _F8C1, _F8C2 = numba.types.float64, numba.types.float64[::1], numba.types.float64[:, ::1]


@jit(signature=numba.types.void(numba.types.float64[:, :, :, ::1], _F8C2, _F8, _F8C2, _F8C2), ahead=True)
def block_setup(jb, jh, gamma, head, fac):
    """Factor (I - gamma J) for :func:`block_solve`; J in the blocks of
    :func:`rodmol.discretise.jacobian.jacobian_blocks`. ``head`` (7, 7) receives
    (I - gamma J_hh)^-1 of the base pose."""
    n = jb.shape[0]
    g = gamma
    m = np.empty((NP, NP))
    up = np.empty((NX, NX))
    inv = np.empty((NP, NP))
    work = np.empty((NP, 2 * NP))
    _shifted_inverse(jh, 0, NP, g, m, head, work)
    for b in range(n):
        f = fac[b]
        for i in range(NX):
            for j in range(NX):
                f[F_C0 + NX * i + j] = jb[b, 1, _Z0 + i, _X0 + j]
                f[F_CP + NX * i + j] = jb[b, 2, _Z0 + i, _X0 + j] if b + 1 < n else 0.0
            for j in range(NP):
                f[F_G + NP * i + j] = jb[b, 1, _Z0 + i, _P0 + j]
        _shifted_inverse(jb[b, 1], _P0, NP, g, m, inv, work)
        _store(inv, NP, f, F_AINV)
        _shifted_inverse(jb[b, 1], _X0, NX, g, m, inv, work)  # leaves BINV in inv for SX, TX
        _store(inv, NX, f, F_BINV)
        for i in range(NX):
            for j in range(NX):
                sv = 0.0
                tv = 0.0
                for k in range(NX):
                    sv += inv[i, k] * jb[b, 1, _X0 + k, _Z0 + j]
                    tv += inv[i, k] * jb[b, 0, _X0 + k, _Z0 + j]
                f[F_SX + NX * i + j] = sv
                f[F_TX + NX * i + j] = tv
        for i in range(NP):
            for j in range(NX):
                sv = 0.0
                for k in range(NP):
                    sv += f[F_AINV + NP * i + k] * jb[b, 1, _P0 + k, _Z0 + j]
                f[F_WP + NX * i + j] = sv
    for b in range(n):
        f = fac[b]
        fn = fac[min(b + 1, n - 1)]
        # Reduced blocks: J_ZZ plus what the eliminated P_b, X_b, X_{b+1} carry.
        for i in range(NX):
            for j in range(NX):
                lv = jb[b, 0, _Z0 + i, _Z0 + j]
                dv = jb[b, 1, _Z0 + i, _Z0 + j]
                uv = 0.0
                for k in range(NX):
                    c = f[F_C0 + NX * i + k]
                    lv += g * c * f[F_TX + NX * k + j]
                    dv += g * c * f[F_SX + NX * k + j]
                for k in range(NP):
                    dv += g * f[F_G + NP * i + k] * f[F_WP + NX * k + j]
                if b + 1 < n:
                    uv = jb[b, 2, _Z0 + i, _Z0 + j]
                    for k in range(NX):
                        c = f[F_CP + NX * i + k]
                        dv += g * c * fn[F_TX + NX * k + j]
                        uv += g * c * fn[F_SX + NX * k + j]
                f[F_LOW + NX * i + j] = -g * lv
                m[i, j] = (1.0 if i == j else 0.0) - g * dv
                up[i, j] = -g * uv
        if b > 0:  # forward elimination of z_{b-1}
            fp = fac[b - 1]
            for i in range(NX):
                for j in range(NX):
                    sv = 0.0
                    for k in range(NX):
                        sv += f[F_LOW + NX * i + k] * fp[F_FWD + NX * k + j]
                    m[i, j] -= sv
        _invert(m, inv, NX, work)
        for i in range(NX):
            for j in range(NX):
                f[F_DINV + NX * i + j] = inv[i, j]
                sv = 0.0
                for k in range(NX):
                    sv += inv[i, k] * up[k, j]
                f[F_FWD + NX * i + j] = sv


# Compiled here, after the right-hand side (the helper, which imports rodmol first, has more to do).
@jit(signature=numba.types.void(_F8, _F8C2, _F8C2, _F8C1.copy(readonly=True), _F8C1, _F8C2, _F8C2, _F8C2))
def block_solve(gamma, head, fac, r, x, y_x, y_p, h):
    """x = (I - gamma J)^-1 r with the factors of :func:`block_setup` (same gamma).

    ``y_x`` (N, 6), ``y_p`` (N, 7), ``h`` (N, 6) are scratch.
    """
    n = fac.shape[0]
    g = gamma
    for i in range(HEADER):
        sv = 0.0
        for k in range(HEADER):
            sv += head[i, k] * r[k]
        x[i] = sv
    # Local parts of the eliminated unknowns, the reduced right-hand side
    # (which needs y_x of the next element: one element behind) and the
    # forward elimination.
    rz = np.empty(NX)
    for b in range(n + 1):
        if b < n:
            f = fac[b]
            o = HEADER + BLOCK * b
            for i in range(NX):
                sv = 0.0
                for k in range(NX):
                    sv += f[F_BINV + NX * i + k] * r[o + _X0 + k]
                y_x[b, i] = sv
            for i in range(NP):
                sv = 0.0
                for k in range(NP):
                    sv += f[F_AINV + NP * i + k] * r[o + _P0 + k]
                y_p[b, i] = sv
        c = b - 1
        if c < 0:
            continue
        f = fac[c]
        o = HEADER + BLOCK * c
        for i in range(NX):
            sv = 0.0
            for k in range(NX):
                sv += f[F_C0 + NX * i + k] * y_x[c, k]
            for k in range(NP):
                sv += f[F_G + NP * i + k] * y_p[c, k]
            if c + 1 < n:
                for k in range(NX):
                    sv += f[F_CP + NX * i + k] * y_x[c + 1, k]
            rz[i] = r[o + _Z0 + i] + g * sv
        if c > 0:
            for i in range(NX):
                sv = 0.0
                for k in range(NX):
                    sv += f[F_LOW + NX * i + k] * h[c - 1, k]
                rz[i] -= sv
        for i in range(NX):
            sv = 0.0
            for k in range(NX):
                sv += f[F_DINV + NX * i + k] * rz[k]
            h[c, i] = sv
    # Back substitution for Z = (v, w), then the eliminated unknowns.
    for b in range(n - 1, -1, -1):
        f = fac[b]
        o = HEADER + BLOCK * b
        for i in range(NX):
            sv = h[b, i]
            if b + 1 < n:
                for k in range(NX):
                    sv -= f[F_FWD + NX * i + k] * x[o + BLOCK + _Z0 + k]
            x[o + _Z0 + i] = sv
    for b in range(n):
        f = fac[b]
        o = HEADER + BLOCK * b
        for i in range(NX):
            sv = 0.0
            for k in range(NX):
                sv += f[F_SX + NX * i + k] * x[o + _Z0 + k]
                if b > 0:
                    sv += f[F_TX + NX * i + k] * x[o - BLOCK + _Z0 + k]
            x[o + _X0 + i] = y_x[b, i] + g * sv
        for i in range(NP):
            sv = 0.0
            for k in range(NX):
                sv += f[F_WP + NX * i + k] * x[o + _Z0 + k]
            x[o + _P0 + i] = y_p[b, i] + g * sv


class BlockPreconditioner:
    """An exact solve of CVODE's Newton matrix (I - gamma J), for its GMRES.

    :meth:`setup` and :meth:`solve` are scikit-sundae's ``precond`` callbacks
    (``CVODEPrecond(bp.setup, bp.solve)``): ``setup`` re-evaluates the
    compiled Jacobian blocks when CVODE says they are stale (``jok`` false)
    and factors ``I - gamma J``; ``solve`` applies the factors. GMRES then
    converges in one or two iterations; its products J v are SUNDIALS'
    differences of the full right-hand side, so nothing the blocks leave out
    (feedback tensions) is lost, only slower to converge.

    Raises ValueError if the system's structure does not fit :data:`TEMPLATE`.
    """

    def __init__(self, system, scale):
        check_structure(system.depends)
        n = system.layout.n_blocks
        self.jacobian = system.jacobian(scale, matrix=None)
        self.gamma = np.nan
        self.jac_evals = self.setups = self.solves = 0
        self._head = np.zeros((HEADER, HEADER))
        self._fac = np.zeros((n, N_FACTORS))
        self._scratch = (np.zeros((n, NX)), np.zeros((n, NP)), np.zeros((n, NX)))

    def setup(self, t, y, fy, jok, jnew, gamma):
        """scikit-sundae ``psetup``: refresh J if needed, factor I - gamma J."""
        if jok:
            jnew[0] = 0
        else:
            self.jacobian.evaluate(t, y, fy)
            self.jac_evals += 1
            jnew[0] = 1
        self.factor(gamma)

    def factor(self, gamma):
        """Factor I - gamma J with the current Jacobian blocks."""
        jb, jh = self.jacobian.blocks
        block_setup(jb, jh, gamma, self._head, self._fac)
        self.gamma = gamma
        self.setups += 1

    def factor_into(self, head, fac):
        """Keep the factors in ``head`` (HEADER, HEADER) and ``fac`` (N, N_FACTORS) from now on:
        views of a system's rods' stacked factors, solved in one compiled call
        (:class:`rodmol.discretise.rod_blocks.RodBlocks`)."""
        head[:], fac[:] = self._head, self._fac
        self._head, self._fac = head, fac

    @property
    def factors(self):
        """(gamma, head, fac, (y_x, y_p, h)): the last factorisation and the
        scratch of :func:`block_solve`, for solves inside compiled loops."""
        return self.gamma, self._head, self._fac, self._scratch

    def solve(self, t, y, fy, r, z, gamma, delta, lr):
        """scikit-sundae ``psolve``: z = (I - gamma_setup J)^-1 r."""
        block_solve(self.gamma, self._head, self._fac, read_only(r), z, *self._scratch)
        self.solves += 1

    def apply(self, r):
        """(I - gamma J)^-1 r with the current factors (for tests)."""
        x = np.empty_like(r)
        block_solve(self.gamma, self._head, self._fac, read_only(r), x, *self._scratch)
        return x
