"""The Newton matrix I - g J of an implicit fixed-step scheme, factored once
and reused across steps (modified Newton) until :meth:`refresh` is called.

The Jacobian is the system's compiled one. Where the system's structure fits
the block elimination, the factorisation is the exact O(N) block solve that
CVODE's GMRES uses as preconditioner (``system.preconditioner``); otherwise a
sparse LU (SuperLU) of the matrix on the system's Jacobian pattern.
"""

import numpy as np
from scipy import sparse
from scipy.sparse.linalg import splu


def newton_matrix(system, scale):
    """The factorable I - g J of ``system`` (``scale``: typical size of each entry)."""
    try:
        return BlockNewton(system, scale)
    except ValueError:  # a coupling the block elimination cannot take
        return SparseNewton(system, scale)


class BlockNewton:
    name = "block"

    def __init__(self, system, scale):
        self._block = system.preconditioner(scale)
        self._jnew = np.zeros(1, dtype=np.int32)

    @property
    def jac_evals(self):
        return self._block.jac_evals

    def refresh(self, t, y, fy, g):
        """Evaluate J at (t, y) (``fy`` = f(t, y)) and factor I - g J."""
        self._block.setup(t, y, fy, False, self._jnew, g)

    def solve(self, r):
        return self._block.apply(r)


class SparseNewton:
    name = "sparse"

    def __init__(self, system, scale):
        self._jacobian = system.jacobian(scale, "sparse")
        self._matrix = self._jacobian.sparsity.copy().astype(float)
        self._identity = sparse.identity(system.size, format="csc")
        self._lu = None
        self.jac_evals = 0

    def refresh(self, t, y, fy, g):
        self._jacobian(t, y, fy, self._matrix.data)
        self.jac_evals += 1
        self._lu = splu((self._identity - g * self._matrix).tocsc())

    def solve(self, r):
        return self._lu.solve(r)
