"""The Newton matrix I - g J of an implicit fixed-step scheme, factored once
and reused across steps (modified Newton) until :meth:`refresh` is called.

The Jacobian is the system's compiled one. Where the system is one rod whose
structure fits the block elimination, the factorisation is the exact O(N)
block solve that CVODE's GMRES uses as preconditioner
(``system.preconditioner``, a :class:`BlockPreconditioner`), and the
Newton iterations of a step run compiled (:func:`block_newton`) unless the
inputs read the state (feedback tensions); otherwise a sparse LU (SuperLU)
of the matrix on the system's Jacobian pattern (``system.jacobian(scale,
"sparse")``; a system of rods and bodies, whose preconditioner is not an
exact solve). Compiled or run by Python,
the iterations are one loop, :func:`modified_newton`.
"""

import math

import numpy as np
from numba import types
from numba.extending import overload
from scipy import sparse
from scipy.sparse.linalg import splu

from ..discretise.physics import jit
from ..discretise.preconditioner import BlockPreconditioner, block_solve

# The right-hand side is a global, not an argument, so that numba caches the
# loop (see rodmol/discretise/jacobian.py).
from ..discretise.stencil import rhs
from ..errors import ParameterError

#: Outcomes of a Newton iteration.
CONVERGED, DIVERGED, SLOW, NOT_FINITE = range(4)


def newton_matrix(system, scale):
    """The factorable I - g J of ``system`` (``scale``: typical size of each entry); a system
    that refuses the sparse solver (its pattern misses a coupling: rod contacts) is refused."""
    why = getattr(system, "refused_solvers", {}).get("sparse")
    if why:
        raise ParameterError("backend='galpha' is refused for this system: its Newton matrix is a sparse LU on "
                             f"the Jacobian's pattern, and {why} (with backend='cvode', or 'rk23')")
    try:
        return BlockNewton(system, scale)
    except ValueError:  # a coupling the block elimination cannot take
        return SparseNewton(system, scale)


@jit
def converged(size, rate, tolerance):
    """CVODE's test: the correction ``size``, scaled by the error left after a
    linearly converging iteration of ``rate``, within ``tolerance``."""
    return size * (min(1.0, rate / (1.0 - rate)) if rate < 1.0 else 1.0) <= tolerance


def rates(inputs, y, f):
    """f = the right-hand side at y: run by Python, ``inputs(y, f)`` (a callable);
    compiled, the kernel's ``rhs`` with its arguments ``inputs`` (a tuple)."""
    inputs(y, f)


def solve(factors, r, x):
    """x = (I - g J)^-1 r: run by Python, ``factors(r, x)`` (a callable);
    compiled, the block solve with the factors ``factors`` (a tuple)."""
    factors(r, x)


@overload(rates, jit_options=dict(cache=True))
def _compiled_rates(inputs, y, f):
    if isinstance(inputs, types.BaseTuple):
        def kernel(inputs, y, f):
            rhs(y, f, *inputs)
        return kernel
    return None


@overload(solve, jit_options=dict(cache=True))
def _compiled_solve(factors, r, x):
    if isinstance(factors, types.BaseTuple):
        def block(factors, r, x):
            gamma, head, fac, s_x, s_p, s_h = factors
            block_solve(gamma, head, fac, r, x, s_x, s_p, s_h)
        return block
    return None


def modified_newton(y, b, g, f, r, x, weight, tolerance, max_iters, max_rate, decay, inputs, factors):
    """Modified Newton iterations for y - g rhs(y) = b, in place, with a fixed
    factorisation of I - g J (:func:`rates` and :func:`solve` with ``inputs``
    and ``factors``); the test of :func:`converged`, the rate estimated from 1
    by max(decay rate, size / previous size). Returns (outcome, iterations).

    The one Newton loop of the fixed-step schemes: compiled
    (:func:`block_newton`) where the inputs depend on time only, run by
    Python where they read the state or the factors are a sparse LU."""
    previous, rate = -1.0, 1.0
    for k in range(1, max_iters + 1):
        rates(inputs, y, f)
        if not _residual(b, g, f, y, r):
            return NOT_FINITE, k
        solve(factors, r, x)
        size = _correct(y, x, weight)
        if previous > 0.0:
            rate = max(decay * rate, size / previous)
        elif previous == 0.0:
            rate = decay * rate
        if converged(size, rate, tolerance):
            return CONVERGED, k
        if previous >= 0.0 and size > max_rate * previous:
            return DIVERGED, k
        previous = size
    return SLOW, max_iters


block_newton = jit(modified_newton)


# The loop's vector work as compiled helpers, so that run by Python it costs
# a call each, and compiled it is the loop it always was (no temporaries).
@jit
def _residual(b, g, f, y, r):
    """r = b + g f - y; False (r unfinished) if f has a non-finite entry."""
    for i in range(y.size):
        if not np.isfinite(f[i]):
            return False
        r[i] = b[i] + g * f[i] - y[i]
    return True


@jit
def _correct(y, x, weight):
    """y += x; returns the weighted RMS norm of the correction x."""
    total = 0.0
    for i in range(y.size):
        y[i] += x[i]
        e = x[i] * weight[i]
        total += e * e
    return math.sqrt(total / y.size)


class _Matrix:
    """What both factorisations share: the Newton iterations of a step."""

    def _solve_into(self, r, x):
        x[:] = self.solve(r)

    def iterate(self, y, b, g, f, weight, tolerance, max_iters, max_rate, decay, rates=None):
        """:func:`modified_newton` with the current factors, run by Python with
        ``rates(y, f)`` (the right-hand side with its inputs at the step's time)."""
        return modified_newton(y, b, g, f, self._r, self._x, weight, tolerance, max_iters, max_rate,
                               decay, rates, self._solve_into)


class BlockNewton(_Matrix):
    name = "block"

    def __init__(self, system, scale):
        self._block = system.preconditioner(scale)
        if not isinstance(self._block, BlockPreconditioner):
            raise ValueError("the system's preconditioner is not one rod's exact block elimination")
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

    def iterate(self, y, b, g, f, weight, tolerance, max_iters, max_rate, decay, rates=None):
        """:func:`modified_newton` with the current factors: compiled
        (:func:`block_newton`, the caller has set the inputs) if ``rates`` is
        None, else run by Python with ``rates(y, f)``."""
        if rates is not None:
            return super().iterate(y, b, g, f, weight, tolerance, max_iters, max_rate, decay, rates)
        gamma, head, fac, (s_x, s_p, s_h) = self._block.factors
        return block_newton(y, b, g, f, self._r, self._x, weight, tolerance, max_iters, max_rate,
                            decay, self._args, (gamma, head, fac, s_x, s_p, s_h))


class SparseNewton(_Matrix):
    name = "sparse"
    compiled = False

    def __init__(self, system, scale):
        self._r, self._x = np.empty(system.size), np.empty(system.size)
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
