"""The Jacobian of a system of rods and rigid bodies
(:class:`rodmol.discretise.assembly.Assembly`) by coloured finite
differences over its structural pattern (``Assembly.pattern``), for the
sparse Newton matrix of the fixed-step schemes
(:class:`rodmol.solve.newton_matrix.SparseNewton`).

The columns are grouped greedily so that no two columns of a group share a
row of the pattern: one right-hand side per group gives all of their
entries. The rods' banded blocks need about their bandwidth in groups, the
coupling blocks a few more.
"""

import numpy as np

#: Relative step of the differences, times max(|y_j|, the entry's scale).
STEP = np.sqrt(np.finfo(float).eps)


def column_groups(pattern):
    """Greedy colouring of the columns of ``pattern`` (scipy CSC, bool):
    a list of int arrays, no two columns of one sharing a row."""
    n_rows = pattern.shape[0]
    groups, taken = [], []
    for j in range(pattern.shape[1]):
        rows = pattern.indices[pattern.indptr[j]:pattern.indptr[j + 1]]
        for members, used in zip(groups, taken):
            if not used[rows].any():
                members.append(j)
                used[rows] = True
                break
        else:
            used = np.zeros(n_rows, dtype=bool)
            used[rows] = True
            groups.append([j])
            taken.append(used)
    return [np.array(g, dtype=np.int64) for g in groups]


class SystemJacobian:
    """J = df/dy of ``assembly`` on its pattern (the interface of
    :class:`rodmol.discretise.jacobian.CompiledJacobian` with a sparse matrix:
    ``sparsity``, ``__call__``, ``dense``).

    Parameters
    ----------
    assembly : Assembly
    scale : ndarray (size,)
        Typical magnitude of each entry (atol / rtol): it sets the steps.
    """

    def __init__(self, assembly, scale):
        self.assembly = assembly
        self.sparsity = assembly.pattern()
        self.sparsity.sort_indices()
        self.groups = column_groups(self.sparsity)
        self._scale = np.maximum(np.broadcast_to(np.asarray(scale, dtype=float), (assembly.size,)), 1e-300)
        self._f = np.empty(assembly.size)

    def __call__(self, t, y, fy, jj):
        """Fill ``jj`` (the data of a copy of ``sparsity``, CSC order) with J at
        (t, y), ``fy`` = f(t, y); the assembly is left evaluated at y."""
        indptr, indices = self.sparsity.indptr, self.sparsity.indices
        z = np.array(y, dtype=float)
        steps = STEP * np.maximum(np.abs(z), self._scale)
        for group in self.groups:
            z[group] += steps[group]
            self.assembly(t, z, self._f)
            for j in group:
                lo, hi = indptr[j], indptr[j + 1]
                rows = indices[lo:hi]
                jj[lo:hi] = (self._f[rows] - fy[rows]) / steps[j]
            z[group] = y[group]
        self.assembly(t, np.asarray(y, dtype=float), self._f)

    def dense(self, t, y):
        """J at (t, y) as a dense (size, size) array (for tests)."""
        fy = self.assembly(t, np.asarray(y, dtype=float)).copy()
        matrix = self.sparsity.astype(float)
        self(t, y, fy, matrix.data)
        return matrix.toarray()
