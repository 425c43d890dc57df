"""Finite-difference Jacobians: the compiled one of the semi-discrete
right-hand side, and :class:`BandedDifferences` for any function of a block
layout (the static equilibrium's).

Columns are perturbed in groups that touch disjoint rows; the groups come from
the dependency table (``BlockLayout.colouring``), so a load that reads a new
field or a wider stencil changes the colouring by itself. The compiled blocks are
``jb[b, d, i, j]`` = d f(element b, entry i) / d y(element b + d - 1, entry j)
(storage order within the block) and ``jh``, the base pose's own block.
"""

import contextlib

import numpy as np

from .layout import BLOCK, HEADER
from .physics import jit

# The right-hand side is a global, not an argument: numba cannot cache a
# function that takes a compiled function as an argument (its type differs
# in every process), and recompiling costs seconds per run. A second scheme
# gets its own instance of this loop.
from .stencil import rhs


@jit
def jacobian_blocks(y, f0, scale, groups, header_group, args, ybuf, fbuf, jb, jh):
    """Fill ``jb`` and ``jh`` by differences of the scheme's ``rhs(y, out, *args)``.

    ``groups`` (G, 4) = (entry j, residue r, period p, lowest row offset lo):
    entry j of the blocks b = r, r + p, ... is perturbed at once and reaches
    the row blocks b + lo .. b + lo + p - 1. ``header_group[g]`` is the header
    column perturbed with group g (or -1): header columns reach header rows
    only. Increments follow SUNDIALS: sqrt(eps) max(|y_j|, scale_j).
    """
    n = jb.shape[0]
    srur = np.sqrt(np.finfo(np.float64).eps)
    for j in range(y.shape[0]):
        ybuf[j] = y[j]
    for g in range(groups.shape[0]):
        f, r, period, lo = groups[g, 0], groups[g, 1], groups[g, 2], groups[g, 3]
        for b in range(r, n, period):
            j = HEADER + BLOCK * b + f
            ybuf[j] = y[j] + srur * max(abs(y[j]), scale[j])
        h = header_group[g]
        if h >= 0:
            ybuf[h] = y[h] + srur * max(abs(y[h]), scale[h])
        rhs(ybuf, fbuf, *args)
        for b in range(r, n, period):
            j = HEADER + BLOCK * b + f
            inv_h = 1.0 / (ybuf[j] - y[j])
            for row in range(max(0, b + lo), min(n, b + lo + period)):
                k0 = HEADER + BLOCK * row
                for i in range(BLOCK):
                    jb[row, b - row + 1, i, f] = (fbuf[k0 + i] - f0[k0 + i]) * inv_h
            ybuf[j] = y[j]
        if h >= 0:
            inv_h = 1.0 / (ybuf[h] - y[h])
            for i in range(HEADER):
                jh[i, h] = (fbuf[i] - f0[i]) * inv_h
            ybuf[h] = y[h]


@jit
def fill_matrix(jb, jh, jj):
    """Write the blocks into a (size, size) array (scikit-sundae's template
    for the band and dense solvers, which read only what they store). Every
    reachable entry is written, zeros included, so ``jj`` needs no clearing."""
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


def read_only(a):
    """A read-only view of ``a``: CVODE hands its vectors over read-only, and
    typing every call alike keeps numba at one compilation per kernel."""
    if not a.flags.writeable:
        return a
    view = a.view()
    view.flags.writeable = False
    return view


def _header_groups(groups, header_pattern):
    """Attach each header column that anything reads to a block group."""
    columns = np.flatnonzero(np.any(header_pattern, axis=0))
    if len(columns) > len(groups):
        raise ValueError("more header columns than column groups")
    out = np.full(len(groups), -1, dtype=np.int64)
    out[:len(columns)] = columns
    return out


class CompiledJacobian:
    """The compiled finite-difference Jacobian of a ``SemiDiscrete``, as a
    scikit-sundae ``jacfn(t, y, fy, JJ)``.

    Parameters
    ----------
    system : SemiDiscrete
    scale : (size,) array
        Typical magnitude of each state entry, for the increments
        (``atol / rtol`` is a good choice).
    matrix : "band", "dense", "sparse" or None
        The template scikit-sundae hands to ``jacfn``: a (size, size) array
        ("band", "dense"), the CSC values of :attr:`sparsity` ("sparse"), or
        None if only the blocks are used (the block preconditioner).
    """

    def __init__(self, system, scale, matrix="band"):
        if matrix not in ("band", "dense", "sparse", None):
            raise ValueError(f"unknown matrix {matrix!r}")
        lay = system.layout
        n = lay.n_blocks
        reach = [r for r in lay.column_reach(system.depends) if r is not None]
        if any(lo < -1 or hi > 1 for lo, hi in reach):
            raise ValueError("the compiled Jacobian stores offsets -1, 0, +1 only")
        self.system, self.matrix, self.size = system, matrix, system.size
        self._groups = lay.colouring(system.depends)
        self._header = _header_groups(self._groups, lay.header_pattern())
        self.evaluations = len(self._groups)
        self._args = system.kernel_arguments()
        self._scale = np.broadcast_to(np.asarray(scale, dtype=float), (self.size,)).copy()
        self._ybuf, self._fbuf = np.empty(self.size), np.empty(self.size)
        # One flat buffer, so that the sparse values are a single gather from it.
        nb = n * 3 * BLOCK * BLOCK
        self._flat = np.zeros(nb + HEADER * HEADER)
        self._jb = self._flat[:nb].reshape(n, 3, BLOCK, BLOCK)
        self._jh = self._flat[nb:].reshape(HEADER, HEADER)
        self.sparsity = self._source = None
        if matrix == "sparse":
            self.sparsity, self._source = _sparse_structure(system.pattern(), n)

    @property
    def blocks(self):
        """(jb, jh) of the last evaluation."""
        return self._jb, self._jh

    def evaluate(self, t, y, fy):
        """Evaluate the Jacobian blocks at (t, y), ``fy`` = f(t, y)."""
        # If the inputs fail here, the right-hand side has already met the failure
        # and answered with NaN rates, so CVODE will retry a shorter step; the
        # Jacobian is only an approximation and may use the last good inputs.
        with contextlib.suppress(Exception):
            self.system.update_inputs(t, y)
        jacobian_blocks(read_only(y), read_only(fy), self._scale, self._groups, self._header, self._args, self._ybuf,
                        self._fbuf, self._jb, self._jh)

    def __call__(self, t, y, fy, jj):
        """d f / d y at (t, y), with ``fy`` = f(t, y), into the template ``jj``."""
        self.evaluate(t, y, fy)
        if self.matrix == "sparse":
            jj[:] = self._flat[self._source]
        else:
            fill_matrix(self._jb, self._jh, jj)

    def dense(self, t, y):
        """The Jacobian at (t, y) as a dense array (for tests and studies)."""
        fy = self.system(t, y)
        self.evaluate(t, y, fy)
        jj = np.zeros((self.size, self.size))
        fill_matrix(self._jb, self._jh, jj)
        return jj


def _sparse_structure(pattern, n):
    """CSC form of ``pattern`` and, for each stored value, its index in
    CompiledJacobian's flat (jb, jh) buffer."""
    from scipy import sparse

    rows, cols = np.nonzero(pattern)
    head = (rows < HEADER) & (cols < HEADER)
    rb, cb = (rows - HEADER) // BLOCK, (cols - HEADER) // BLOCK
    src = ((rb * 3 + (cb - rb + 1)) * BLOCK + (rows - HEADER) % BLOCK) * BLOCK + (cols - HEADER) % BLOCK
    src = np.where(head, n * 3 * BLOCK * BLOCK + rows * HEADER + cols, src)
    order = np.lexsort((rows, cols))  # CSC: by column, then row
    rows, cols, src = rows[order], cols[order], src[order]
    csc = sparse.csc_matrix((np.ones(len(rows)), (rows, cols)), shape=pattern.shape)
    csc.sort_indices()
    return csc, src


class BandedDifferences:
    """The finite-difference Jacobian of a function of a vector laid out as
    ``layout`` (a ``BlockLayout``) with the couplings ``depends``, in
    ``solve_banded`` storage with :attr:`bands`: one evaluation per column
    group of ``layout.colouring(depends)``, the groups
    :class:`CompiledJacobian` perturbs. For functions numba cannot call (the
    static equilibrium's rest equations)."""

    def __init__(self, layout, depends):
        self.bands = lo, up = layout.bandwidths(depends)
        n, block, size = layout.n_blocks, layout.block, layout.size
        self._groups = []  # (columns, their rows, the rows' diagonals in the band storage)
        for entry, residue, period, low in layout.colouring(depends):
            members = np.arange(residue, n, period)
            row_blocks = members[:, None] + low + np.arange(period)  # the blocks each member reaches
            rows = layout.header + block * row_blocks[..., None] + np.arange(block)
            cols = np.broadcast_to((layout.header + block * members + entry)[:, None, None], rows.shape)
            diagonal = up + rows - cols
            ok = ((row_blocks[..., None] >= 0) & (row_blocks[..., None] < n) & (diagonal >= 0)
                  & (diagonal <= lo + up) & (rows < size))
            self._groups.append((layout.header + block * members + entry, rows[ok], cols[ok], diagonal[ok]))
        self._shape = (lo + up + 1, size)

    @property
    def groups(self):
        """The column groups: (columns perturbed together, and for each entry
        they reach its row, its column and its diagonal in the band storage)."""
        return self._groups

    def __call__(self, fun, z, f0):
        """dfun/dz at ``z`` (``f0`` = fun(z)) in ``solve_banded`` storage."""
        ab = np.zeros(self._shape)
        h = 1.5e-8 * np.maximum(np.abs(z), 1.0)
        for members, rows, cols, diagonal in self._groups:
            zp = z.copy()
            zp[members] += h[members]
            ab[diagonal, cols] = (fun(zp) - f0)[rows] / h[cols]
        return ab
