"""Compiled Jacobian of the right-hand side and the block preconditioner of CVODE's
Newton systems (used by ``linsolver="gmres"`` and ``jacobian="compiled"``).

See :mod:`rodmol.kernels` for the packed model arrays these routines share
with the compiled right-hand side.
"""

import contextlib

import numpy as np

from .upwind import (
    N_PASSIVE,
    P_QUAT,
    _jit,
    rhs,
)
from .layout import BLOCK, HEADER

# ---------------------------------------------------------------------------
# Jacobian
# ---------------------------------------------------------------------------

@_jit
def jacobian_blocks(y, f0, scale, params, consts, offsets, weights, tensions, base, work,
                    ybuf, fbuf, jb, jh):
    """Finite-difference Jacobian of :func:`rhs`, in element blocks.

    ``jb[b, d, i, j]`` = d f(element b, entry i) / d y(element b + d - 1,
    entry j), entries in storage order within the block (u, Q, q, k, v, w);
    ``jh`` (7, 7) is the base pose's own block. ``f0`` = rhs(y). Columns are
    perturbed together when they touch disjoint rows (a colouring of the
    structure: nothing depends on u; Q reaches only its own element; q, k
    reach elements b - 1, b; v, w reach b - 1, b, b + 1), so the whole
    Jacobian costs 4 + 2*6 + 3*6 = 34 evaluations, whatever N, against 43
    for a band colouring. The increments follow SUNDIALS: sqrt(eps)
    max(|y_j|, scale_j). Feedback tensions are held fixed (their coupling is
    global). Entries the structure never reaches (u columns, Q beyond its
    element, ...) are not written: ``jb`` and ``jh`` must start zeroed.
    """
    n = params.shape[0]
    srur = np.sqrt(np.finfo(np.float64).eps)
    for j in range(y.shape[0]):
        ybuf[j] = y[j]
    for f in range(P_QUAT, BLOCK):  # u columns (f < 3) are zero
        if f < N_PASSIVE:
            period, lo, hi = 1, 0, 0
        elif f < N_PASSIVE + 6:
            period, lo, hi = 2, 0, 1
        else:
            period, lo, hi = 3, -1, 1
        for r in range(period):
            for b in range(r, n, period):
                j = HEADER + BLOCK * b + f
                ybuf[j] = y[j] + srur * max(abs(y[j]), scale[j])
            if f < N_PASSIVE and r == 0:  # the base quaternion reaches the header only
                ybuf[f] = y[f] + srur * max(abs(y[f]), scale[f])
            rhs(ybuf, fbuf, params, consts, offsets, weights, tensions, base, work)
            for row in range(n):
                for d in range(lo, hi + 1):
                    b = row + d
                    if b < 0 or b >= n or b % period != r:
                        continue
                    j = HEADER + BLOCK * b + f
                    inv_h = 1.0 / (ybuf[j] - y[j])
                    k0 = HEADER + BLOCK * row
                    for i in range(BLOCK):
                        jb[row, d + 1, i, f] = (fbuf[k0 + i] - f0[k0 + i]) * inv_h
            for b in range(r, n, period):
                j = HEADER + BLOCK * b + f
                ybuf[j] = y[j]
            if f < N_PASSIVE and r == 0:
                inv_h = 1.0 / (ybuf[f] - y[f])
                for i in range(HEADER):
                    jh[i, f] = (fbuf[i] - f0[i]) * inv_h
                ybuf[f] = y[f]


@_jit
def fill_band(jb, jh, jj):
    """Write the block Jacobian into a (size, size) array (scikit-sundae's
    template for the band and dense solvers, which read only what they store).

    Every entry the block structure can reach is written, zeros included, so
    reusing jj needs no clearing.
    """
    n = jb.shape[0]
    for i in range(HEADER):
        for j in range(HEADER):
            jj[i, j] = jh[i, j]
    for row in range(n):
        r0 = HEADER + BLOCK * row
        for d in range(3):
            b = row + d - 1
            if b < 0 or b >= n:
                continue
            c0 = HEADER + BLOCK * b
            for i in range(BLOCK):
                for f in range(BLOCK):
                    jj[r0 + i, c0 + f] = jb[row, d, i, f]


class CompiledJacobian:
    """The compiled finite-difference Jacobian of a ``SemiDiscrete``, as a
    scikit-sundae ``jacfn(t, y, fy, JJ)``.

    Parameters
    ----------
    system : SemiDiscrete
        With ``kernel="numba"``.
    scale : (size,) array
        Typical magnitude of each state entry, for the increments;
        ``atol / rtol`` is a good choice.
    matrix : "band", "dense", "sparse" or None
        The template scikit-sundae hands to ``jacfn``: a (size, size) array
        ("band", "dense") or the CSC values of :attr:`sparsity` ("sparse");
        None if only the blocks are used (:class:`BlockPreconditioner`).
    """

    def __init__(self, system, scale, matrix="band"):
        if matrix not in ("band", "dense", "sparse", None):
            raise ValueError(f"unknown matrix {matrix!r}")
        n = system.model.n_elements
        self.system, self.matrix, self.size = system, matrix, system.size
        self._args = system.kernel_arguments()
        self._feedback = system.model.feedback
        self._scale = np.broadcast_to(np.asarray(scale, dtype=float), (self.size,)).copy()
        self._ybuf, self._fbuf = np.empty(self.size), np.empty(self.size)
        # One flat buffer, so that the sparse values are a single gather from it.
        nb = n * 3 * BLOCK * BLOCK
        self._flat = np.zeros(nb + HEADER * HEADER)
        self._jb = self._flat[:nb].reshape(n, 3, BLOCK, BLOCK)
        self._jh = self._flat[nb:].reshape(HEADER, HEADER)
        self.sparsity = self._source = None
        if matrix == "sparse":
            self.sparsity, self._source = _sparse_structure(n, self.size)

    @property
    def blocks(self):
        """(jb, jh) of the last evaluation (see :func:`jacobian_blocks`)."""
        return self._jb, self._jh

    def evaluate(self, t, y, fy):
        """Evaluate the Jacobian blocks at (t, y), ``fy`` = f(t, y)."""
        # If the inputs fail here, the right-hand side has already met the failure
        # and answered with NaN rates, so CVODE will retry a shorter step; the
        # Jacobian is only an approximation and may use the last good inputs.
        with contextlib.suppress(Exception):
            self.system.update_inputs(t, y)
        jacobian_blocks(y, fy, self._scale, *self._args, self._ybuf, self._fbuf,
                        self._jb, self._jh)

    def __call__(self, t, y, fy, jj):
        """d f / d y at (t, y), with ``fy`` = f(t, y), into the template ``jj``."""
        self.evaluate(t, y, fy)
        if self.matrix == "sparse":
            jj[:] = self._flat[self._source]
        else:
            fill_band(self._jb, self._jh, jj)

    def dense(self, t, y):
        """The Jacobian at (t, y) as a dense array (for tests and studies)."""
        fy = self.system(t, y)
        if self.matrix == "sparse":
            data = np.empty(self.sparsity.nnz)
            self(t, y, fy, data)
            jac = self.sparsity.copy()
            jac.data = data
            return jac.toarray()
        jj = np.zeros((self.size, self.size))
        self(t, y, fy, jj)
        return jj


def _sparse_structure(n, size):
    """CSC structural pattern of the Jacobian (``layout.pattern``'s, built
    block by block so that it stays linear in N), and for each stored value
    its index in CompiledJacobian's flat (jb, jh) buffer."""
    from scipy import sparse

    from .layout import StateLayout

    # The pattern is block-periodic: read an interior block row of 3 elements.
    small = StateLayout(3).pattern()
    block_mask = small[HEADER + BLOCK:HEADER + 2 * BLOCK, HEADER:].reshape(BLOCK, 3, BLOCK)
    d, i, f = np.nonzero(block_mask.transpose(1, 0, 2))  # d = column element - row element + 1
    flat = (d * BLOCK + i) * BLOCK + f
    rows, cols, src = [], [], []
    for row in range(n):
        b = row + d - 1
        ok = (b >= 0) & (b < n)
        rows.append(HEADER + BLOCK * row + i[ok])
        cols.append(HEADER + BLOCK * b[ok] + f[ok])
        src.append(row * 3 * BLOCK * BLOCK + flat[ok])
    hi, hf = np.nonzero(small[:HEADER, :HEADER])
    rows.append(hi)
    cols.append(hf)
    src.append(n * 3 * BLOCK * BLOCK + hi * HEADER + hf)
    rows, cols, src = (np.concatenate(a) for a in (rows, cols, src))
    order = np.lexsort((rows, cols))  # CSC: by column, then row
    rows, cols, src = rows[order], cols[order], src[order]
    pattern = sparse.csc_matrix((np.ones(len(rows)), (rows, cols)), shape=(size, size))
    pattern.sort_indices()
    return pattern, src


# ---------------------------------------------------------------------------
# Block preconditioner: an exact solve of (I - gamma J) in O(N)
# ---------------------------------------------------------------------------
#
# Within an element block (storage order) the entries split into
#   U = u (0..2), QQ = Q (3..6), X = (q, k) (7..12), Z = (v, w) (13..18),
# and the structure of J (rodmol.layout._DEPENDS) is
#   U_b  <- QQ_b, Z_b          (u_t = R v)
#   QQ_b <- QQ_b, Z_b          (quaternion rate)
#   X_b  <- X_b, Z_b, Z_{b-1}  (compatibility)
#   Z_b  <- QQ_b, X_b, X_{b+1}, Z_{b-1}, Z_b, Z_{b+1}  (balance laws)
# Nothing depends on U. So in (I - gamma J) x = r, the X and QQ unknowns of
# each element follow from its Z and its neighbour's Z through 6x6 and 4x4
# local solves; substituting them leaves a block-tridiagonal system in the
# Z = (v, w) unknowns alone, with 6x6 blocks, solved by block elimination
# (block Thomas); U follows last. Against the band LU of the full 19-per-
# element system (half-bandwidths 21), this is ~10x fewer operations per
# solve and ~4x less memory (which stays in cache), so it is what CVODE's
# Newton iterations use, through scikit-sundae's GMRES with this solve as
# an exact preconditioner (scikit-sundae accepts no custom direct solver).
#
# Eliminating the diagonal blocks X_b, QQ_b without pivoting across blocks
# is safe: I - gamma J_XX and I - gamma J_QQ are identity plus gamma times
# rotation rates (small), and the reduced Z system of a stiff elastic rod
# behaves like I plus a positive second-difference operator.

_U0, _Q0, _X0, _Z0 = 0, 3, 7, 13


@_jit
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


# Per-element factors, packed in one row per element so that a solve streams
# ~3 kB per element from one array (it stays in cache at N = 400, where the
# Jacobian blocks themselves, 8.7 kB per element, do not).
F_AINV, F_BINV, F_SX, F_TX, F_WQ = 0, 16, 52, 88, 124  # 4x4, 6x6, 6x6, 6x6, 4x6
F_LOW, F_DINV, F_FWD = 148, 184, 220  # 6x6 each
F_C0, F_CP, F_G, F_UQ, F_UZ = 256, 292, 328, 352, 364  # copies of J blocks: 6x6, 6x6, 6x4, 3x4, 3x6
N_FACTORS = 382


@_jit
def block_setup(jb, jh, gamma, head, fac):
    """Factor (I - gamma J) for :func:`block_solve`; J in the blocks of :func:`jacobian_blocks`.

    Per element b (row ``fac[b]``): AINV = (I - g J_QQ)^-1, BINV =
    (I - g J_XX)^-1, SX = BINV J_XZ(b), TX = BINV J_XZ(b-1), WQ = AINV J_QZ;
    the reduced system LOW_b z_{b-1} + diag_b z_b + up_b z_{b+1} = ... is
    eliminated forward: DINV = (diag_b - LOW_b FWD_{b-1})^-1, FWD = DINV up_b.
    C0 = J_ZX(b), CP = J_ZX(b+1), G = J_ZQ, UQ = J_UQ, UZ = J_UZ are copied for
    the solve. ``head`` (4, 4) = (I - g J_QQ)^-1 of the base quaternion.
    """
    n = jb.shape[0]
    g = gamma
    m6 = np.empty((6, 6))
    m4 = np.empty((4, 4))
    up = np.empty((6, 6))
    inv = np.empty((6, 6))
    work = np.empty((6, 12))
    for i in range(4):
        for j in range(4):
            m4[i, j] = (1.0 if i == j else 0.0) - g * jh[_Q0 + i, _Q0 + j]
    _invert(m4, head, 4, work)
    for b in range(n):
        f = fac[b]
        for i in range(6):
            for j in range(6):
                f[F_C0 + 6 * i + j] = jb[b, 1, _Z0 + i, _X0 + j]
                f[F_CP + 6 * i + j] = jb[b, 2, _Z0 + i, _X0 + j] if b + 1 < n else 0.0
            for j in range(4):
                f[F_G + 4 * i + j] = jb[b, 1, _Z0 + i, _Q0 + j]
        for i in range(3):
            for j in range(4):
                f[F_UQ + 4 * i + j] = jb[b, 1, _U0 + i, _Q0 + j]
            for j in range(6):
                f[F_UZ + 6 * i + j] = jb[b, 1, _U0 + i, _Z0 + j]
        for i in range(4):
            for j in range(4):
                m4[i, j] = (1.0 if i == j else 0.0) - g * jb[b, 1, _Q0 + i, _Q0 + j]
        _invert(m4, inv, 4, work)
        for i in range(4):
            for j in range(4):
                f[F_AINV + 4 * i + j] = inv[i, j]
        for i in range(6):
            for j in range(6):
                m6[i, j] = (1.0 if i == j else 0.0) - g * jb[b, 1, _X0 + i, _X0 + j]
        _invert(m6, inv, 6, work)
        for i in range(6):
            for j in range(6):
                f[F_BINV + 6 * i + j] = inv[i, j]
        for i in range(6):
            for j in range(6):
                sv = 0.0
                tv = 0.0
                for k in range(6):
                    sv += inv[i, k] * jb[b, 1, _X0 + k, _Z0 + j]
                    tv += inv[i, k] * jb[b, 0, _X0 + k, _Z0 + j]
                f[F_SX + 6 * i + j] = sv
                f[F_TX + 6 * i + j] = tv
        for i in range(4):
            for j in range(6):
                sv = 0.0
                for k in range(4):
                    sv += f[F_AINV + 4 * i + k] * jb[b, 1, _Q0 + k, _Z0 + j]
                f[F_WQ + 6 * i + j] = sv
    for b in range(n):
        f = fac[b]
        fn = fac[min(b + 1, n - 1)]
        # Reduced blocks: J_ZZ plus what the eliminated X_b, X_{b+1}, QQ_b carry.
        for i in range(6):
            for j in range(6):
                lv = jb[b, 0, _Z0 + i, _Z0 + j]
                dv = jb[b, 1, _Z0 + i, _Z0 + j]
                uv = 0.0
                for k in range(6):
                    c = f[F_C0 + 6 * i + k]
                    lv += g * c * f[F_TX + 6 * k + j]
                    dv += g * c * f[F_SX + 6 * k + j]
                for k in range(4):
                    dv += g * f[F_G + 4 * i + k] * f[F_WQ + 6 * k + j]
                if b + 1 < n:
                    uv = jb[b, 2, _Z0 + i, _Z0 + j]
                    for k in range(6):
                        c = f[F_CP + 6 * i + k]
                        dv += g * c * fn[F_TX + 6 * k + j]
                        uv += g * c * fn[F_SX + 6 * k + j]
                f[F_LOW + 6 * i + j] = -g * lv
                m6[i, j] = (1.0 if i == j else 0.0) - g * dv
                up[i, j] = -g * uv
        if b > 0:  # forward elimination of z_{b-1}
            fp = fac[b - 1]
            for i in range(6):
                for j in range(6):
                    sv = 0.0
                    for k in range(6):
                        sv += f[F_LOW + 6 * i + k] * fp[F_FWD + 6 * k + j]
                    m6[i, j] -= sv
        _invert(m6, inv, 6, work)
        for i in range(6):
            for j in range(6):
                f[F_DINV + 6 * i + j] = inv[i, j]
                sv = 0.0
                for k in range(6):
                    sv += inv[i, k] * up[k, j]
                f[F_FWD + 6 * i + j] = sv


@_jit
def block_solve(jh, gamma, head, fac, r, x, y_x, y_q, h):
    """x = (I - gamma J)^-1 r with the factors of :func:`block_setup` (same gamma).

    ``y_x`` (N, 6), ``y_q`` (N, 4), ``h`` (N, 6) are scratch.
    """
    n = fac.shape[0]
    g = gamma
    # Base pose: Q0 from its own 4x4 block, then u0.
    for i in range(4):
        sv = 0.0
        for k in range(4):
            sv += head[i, k] * r[_Q0 + k]
        x[_Q0 + i] = sv
    for i in range(3):
        sv = r[i]
        for k in range(4):
            sv += g * jh[i, _Q0 + k] * x[_Q0 + k]
        x[i] = sv
    # Local parts of the eliminated unknowns, the reduced right-hand side
    # (which needs y_x of the next element: one element behind) and the
    # forward elimination.
    rz = np.empty(6)
    for b in range(n + 1):
        if b < n:
            f = fac[b]
            o = HEADER + BLOCK * b
            for i in range(6):
                sv = 0.0
                for k in range(6):
                    sv += f[F_BINV + 6 * i + k] * r[o + _X0 + k]
                y_x[b, i] = sv
            for i in range(4):
                sv = 0.0
                for k in range(4):
                    sv += f[F_AINV + 4 * i + k] * r[o + _Q0 + k]
                y_q[b, i] = sv
        c = b - 1
        if c < 0:
            continue
        f = fac[c]
        o = HEADER + BLOCK * c
        for i in range(6):
            sv = 0.0
            for k in range(6):
                sv += f[F_C0 + 6 * i + k] * y_x[c, k]
            for k in range(4):
                sv += f[F_G + 4 * i + k] * y_q[c, k]
            if c + 1 < n:
                for k in range(6):
                    sv += f[F_CP + 6 * i + k] * y_x[c + 1, k]
            rz[i] = r[o + _Z0 + i] + g * sv
        if c > 0:
            for i in range(6):
                sv = 0.0
                for k in range(6):
                    sv += f[F_LOW + 6 * i + k] * h[c - 1, k]
                rz[i] -= sv
        for i in range(6):
            sv = 0.0
            for k in range(6):
                sv += f[F_DINV + 6 * i + k] * rz[k]
            h[c, i] = sv
    # Back substitution for Z = (v, w), then the eliminated unknowns and u.
    for b in range(n - 1, -1, -1):
        f = fac[b]
        o = HEADER + BLOCK * b
        for i in range(6):
            sv = h[b, i]
            if b + 1 < n:
                for k in range(6):
                    sv -= f[F_FWD + 6 * i + k] * x[o + BLOCK + _Z0 + k]
            x[o + _Z0 + i] = sv
    for b in range(n):
        f = fac[b]
        o = HEADER + BLOCK * b
        for i in range(6):
            sv = 0.0
            for k in range(6):
                sv += f[F_SX + 6 * i + k] * x[o + _Z0 + k]
                if b > 0:
                    sv += f[F_TX + 6 * i + k] * x[o - BLOCK + _Z0 + k]
            x[o + _X0 + i] = y_x[b, i] + g * sv
        for i in range(4):
            sv = 0.0
            for k in range(6):
                sv += f[F_WQ + 6 * i + k] * x[o + _Z0 + k]
            x[o + _Q0 + i] = y_q[b, i] + g * sv
        for i in range(3):
            sv = 0.0
            for k in range(4):
                sv += f[F_UQ + 4 * i + k] * x[o + _Q0 + k]
            for k in range(6):
                sv += f[F_UZ + 6 * i + k] * x[o + _Z0 + k]
            x[o + _U0 + i] = r[o + _U0 + i] + g * sv


class BlockPreconditioner:
    """An exact solve of CVODE's Newton matrix (I - gamma J), for its GMRES.

    :meth:`setup` and :meth:`solve` are scikit-sundae's ``precond`` callbacks
    (``CVODEPrecond(bp.setup, bp.solve)``): ``setup`` re-evaluates the
    compiled Jacobian blocks when CVODE says they are stale (``jok`` false)
    and factors ``I - gamma J`` (:func:`block_setup`); ``solve`` applies the
    factors (:func:`block_solve`). GMRES then converges in one or two
    iterations; its products J v are SUNDIALS' finite differences of the
    full right-hand side, so nothing the blocks leave out (feedback
    tensions) is lost, only slower to converge.

    Parameters
    ----------
    system : SemiDiscrete
        With ``kernel="numba"``.
    scale : (size,) array
        Typical magnitude of each state entry, for the Jacobian's increments.
    """

    def __init__(self, system, scale):
        n = system.model.n_elements
        self.jacobian = CompiledJacobian(system, scale, matrix=None)
        self.gamma = np.nan
        self.jac_evals = 0
        self.setups = 0
        self.solves = 0
        self._head = np.zeros((4, 4))
        self._fac = np.zeros((n, N_FACTORS))
        self._scratch = (np.zeros((n, 6)), np.zeros((n, 4)), np.zeros((n, 6)))

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

    def solve(self, t, y, fy, r, z, gamma, delta, lr):
        """scikit-sundae ``psolve``: z = (I - gamma_setup J)^-1 r."""
        block_solve(self.jacobian.blocks[1], self.gamma, self._head, self._fac, r, z,
                    *self._scratch)
        self.solves += 1

    def apply(self, r):
        """(I - gamma J)^-1 r with the current factors (for tests)."""
        x = np.empty_like(r)
        block_solve(self.jacobian.blocks[1], self.gamma, self._head, self._fac, r, x,
                    *self._scratch)
        return x
