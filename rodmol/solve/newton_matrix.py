"""The Newton matrix I - g J of an implicit fixed-step scheme, factored once
and reused across steps (modified Newton) until :meth:`refresh` is called.

The Jacobian is the system's compiled one. Where the system's structure fits
the block elimination, the factorisation is the exact O(N) block solve that
CVODE's GMRES uses as preconditioner (``system.preconditioner``), and the
Newton iterations of a step run compiled (:func:`block_newton`) unless the
inputs read the state (feedback tensions); otherwise a sparse LU (SuperLU)
of the matrix on the system's Jacobian pattern.
"""

import math

import numpy as np
from scipy import sparse
from scipy.sparse.linalg import splu

from ..discretise.physics import jit
from ..discretise.preconditioner import block_solve

# The right-hand side is a global, not an argument, so that numba caches the
# loop (see rodmol/discretise/jacobian.py).
from ..discretise.stencil import rhs

#: Outcomes of a Newton iteration.
CONVERGED, DIVERGED, SLOW, NOT_FINITE = range(4)


def newton_matrix(system, scale):
    """The factorable I - g J of ``system`` (``scale``: typical size of each entry)."""
    try:
        return BlockNewton(system, scale)
    except ValueError:  # a coupling the block elimination cannot take
        return SparseNewton(system, scale)


def converged(size, rate, tolerance):
    """CVODE's test: the correction ``size``, scaled by the error left after a
    linearly converging iteration of ``rate``, within ``tolerance``."""
    return size * (min(1.0, rate / (1.0 - rate)) if rate < 1.0 else 1.0) <= tolerance


@jit
def block_newton(y, b, g, f, r, x, weight, tolerance, max_iters, max_rate, decay,
                 gamma, head, fac, s_x, s_p, s_h, args):
    """Modified Newton iterations for y - g rhs(y) = b, in place, with the
    block factors of I - gamma J; the same test as :func:`converged`, the
    rate estimated from 1 by max(decay rate, size / previous size).
    Returns (outcome, iterations)."""
    n = y.size
    previous, rate = -1.0, 1.0
    for k in range(1, max_iters + 1):
        rhs(y, f, *args)
        for i in range(n):
            if not np.isfinite(f[i]):
                return NOT_FINITE, k
            r[i] = b[i] + g * f[i] - y[i]
        block_solve(gamma, head, fac, r, x, s_x, s_p, s_h)
        total = 0.0
        for i in range(n):
            y[i] += x[i]
            e = x[i] * weight[i]
            total += e * e
        size = math.sqrt(total / n)
        if previous > 0.0:
            rate = max(decay * rate, size / previous)
        elif previous == 0.0:
            rate = decay * rate
        if size * (min(1.0, rate / (1.0 - rate)) if rate < 1.0 else 1.0) <= tolerance:
            return CONVERGED, k
        if previous >= 0.0 and size > max_rate * previous:
            return DIVERGED, k
        previous = size
    return SLOW, max_iters


class BlockNewton:
    name = "block"

    def __init__(self, system, scale):
        self._block = system.preconditioner(scale)
        self._jnew = np.zeros(1, dtype=np.int32)
        self._args = system.kernel_arguments()
        self._r, self._x = np.empty(system.size), np.empty(system.size)
        #: True if :meth:`iterate` can run: the inputs depend on time only.
        self.compiled = not system.global_coupling

    @property
    def jac_evals(self):
        return self._block.jac_evals

    def refresh(self, t, y, fy, g):
        """Evaluate J at (t, y) (``fy`` = f(t, y)) and factor I - g J."""
        self._block.setup(t, y, fy, False, self._jnew, g)

    def refactor(self, g):
        """Factor I - g J with the Jacobian of the last refresh."""
        self._block.factor(g)

    def solve(self, r):
        return self._block.apply(r)

    def iterate(self, y, b, g, f, weight, tolerance, max_iters, max_rate, decay):
        """:func:`block_newton` with the current factors; the caller has set the inputs."""
        gamma, head, fac, (s_x, s_p, s_h) = self._block.factors
        return block_newton(y, b, g, f, self._r, self._x, weight, tolerance, max_iters, max_rate,
                            decay, gamma, head, fac, s_x, s_p, s_h, self._args)


class SparseNewton:
    name = "sparse"
    compiled = False

    def __init__(self, system, scale):
        self._jacobian = system.jacobian(scale, "sparse")
        self._matrix = self._jacobian.sparsity.copy().astype(float)
        self._identity = sparse.identity(system.size, format="csc")
        self._lu = None
        self.jac_evals = 0

    def refresh(self, t, y, fy, g):
        self._jacobian(t, y, fy, self._matrix.data)
        self.jac_evals += 1
        self.refactor(g)

    def refactor(self, g):
        self._lu = splu((self._identity - g * self._matrix).tocsc())

    def solve(self, r):
        return self._lu.solve(r)
