"""The backward half of a continuous adjoint: lambda integrated by CVODE from the run's end
back to its start, and the gradient's quadrature along it.

With the forward run y(t) (:class:`rodmol.solve.checkpoints.ForwardRun`), J(t) = df/dy
and F(t) = df/dp at y(t)::

    lambda' = -J(t)^T lambda,   lambda(T+) = 0,   lambda += dL/dy(t_k) at the loss's times,
    dL/dp = integral over [t0, T] of lambda^T F dt  (+ lambda(t0)^T dy0/dp)

lambda is integrated in t going down (SUNDIALS steps either way), CVODE re-initialised
at each jump. J is the system's compiled finite-difference Jacobian on its pattern at
the interpolated state, evaluated once per distinct time (every right-hand side of a
BDF step is at its new time) and handed to the Newton matrix too. The quadrature is
Gauss-Legendre on each backward step, lambda there by CVODE's own interpolant: so F is
evaluated at a few points per step only, and the Newton matrix stays n x n whatever
the number of parameters (with the quadrature as CVODE states, a hundred knots made
it 5x larger and the run 3x slower, measured).
"""

import numpy as np
from scipy import sparse

from ..errors import IntegrationError

#: The backward integration's linear solvers: band LU on J^T's band (a rod's), dense
#: LU, SuperLU on the transposed pattern; "auto": band if the system offers it, else
#: dense up to DENSE_MAX entries, else sparse.
LINEAR_SOLVERS = ("auto", "band", "dense", "sparse")
DENSE_MAX = 1500
#: Times closer than this fraction of the run's span are one stop of the backward steps.
RESOLUTION = 1e-9
#: Gauss-Legendre points per backward step (exact to degree 3 in the step; 3 points changed
#: the gradient by 1e-9 relative and cost 15 % more, measured on the benchmark's arm).
QUADRATURE_POINTS = 2


class AdjointSystem:
    """The rates -J(t)^T lambda (see the module docstring).

    Parameters
    ----------
    system : Discretised
    state : callable
        y(t) of the forward run.
    scale : (n,) array
        Typical magnitudes of the state (the Jacobian's steps).
    """

    def __init__(self, system, state, scale):
        self.system, self.state, self.n = system, state, system.size
        self.jac = system.jacobian(scale, "sparse")
        pattern = sparse.csc_matrix(self.jac.sparsity, dtype=float)
        pattern.sort_indices()
        self._indices, self._indptr = pattern.indices.copy(), pattern.indptr.copy()
        self.JT = sparse.csr_matrix((np.zeros(pattern.nnz), self._indices, self._indptr), shape=pattern.shape)
        self._data = self.JT.data
        # J's CSC arrays read as CSR are J^T; its CSC form, for SuperLU, by a permutation.
        coded = sparse.csr_matrix((np.arange(1.0, pattern.nnz + 1), self._indices, self._indptr), shape=pattern.shape)
        transposed = coded.tocsc()
        transposed.sort_indices()
        self._permutation = transposed.data.astype(np.int64) - 1
        self.sparsity = sparse.csc_matrix((np.ones(pattern.nnz), transposed.indices, transposed.indptr),
                                          shape=pattern.shape)
        self._t = None
        self.evaluations = 0

    def transposed(self, t):
        """J(t)^T (CSR), once per distinct t."""
        if self._t != t:
            y = self.state(t)
            fy = self.system(t, y).copy()
            self.jac(t, y, fy, self._data)  # into J^T's own data (J's CSC order is J^T's CSR order)
            self._t = t
            self.evaluations += 1
        return self.JT

    def rates(self, t, lam, out):
        out[:] = -(self.transposed(t) @ lam)

    def sparse_jacobian(self, t, lam, fy, JJ):
        JJ[:] = -self.transposed(t).data[self._permutation]

    def dense_jacobian(self, t, lam, fy, JJ):
        JJ[:] = -self.transposed(t).toarray()

    def options(self, linsolver):
        """scikit-sundae's options for ``linsolver`` (see :data:`LINEAR_SOLVERS`)."""
        if linsolver == "auto":
            offered = self.system.linear_solvers()
            linsolver = "band" if "band" in offered else ("dense" if self.n <= DENSE_MAX else "sparse")
        if linsolver == "sparse":
            return dict(linsolver="sparse", sparsity=self.sparsity, jacfn=self.sparse_jacobian)
        if linsolver == "band":
            lower, upper = self.system.bandwidths()
            return dict(linsolver="band", lband=int(upper), uband=int(lower), jacfn=self.dense_jacobian)
        return dict(linsolver="dense", jacfn=self.dense_jacobian)


def integrate_backward(adjoint, t0, t_end, jumps, stops, integrand, *, rtol, atol, linsolver="auto",
                       max_order=5):
    """lambda(t0) and the quadrature's q = integral of lambda^T F dt over [t0, t_end] [s].

    ``jumps``: (t [s], dL/dy (n,)) added to lambda at t; ``stops`` [s]: times the steps
    end at (the inputs' knots, the bounded forward run's segments); ``integrand(t, lam)``
    -> lambda^T F(t) (p,); ``atol`` (n,) lambda's absolute tolerances. Returns
    (lambda(t0) (n,), q (p,), stats)."""
    from sksundae.cvode import CVODE

    n = adjoint.n
    jumps = sorted(((float(t), np.asarray(g, dtype=float)) for t, g in jumps), key=lambda j: -j[0])
    solver = CVODE(adjoint.rates, method="BDF", rtol=rtol, atol=atol, max_num_steps=1_000_000,
                   max_order=int(max_order), **adjoint.options(linsolver))
    x, w = np.polynomial.legendre.leggauss(QUADRATURE_POINTS)
    lam, q, steps = np.zeros(n), None, 0
    times = _stops(t0, t_end, [*stops, *(j[0] for j in jumps)])
    # Each jump at the stop it falls on (times closer than the resolution are one: a loss
    # time of 3.5000000000000004 s at a knot of 3.5 s would be a step CVODE cannot take).
    jumps = [(min([t_end, *times], key=lambda s: abs(s - tj)), g) for tj, g in jumps]
    t = float(t_end)
    for j in [j for j in jumps if j[0] >= t_end]:
        lam += j[1]
    solver.init_step(t, lam)
    jumps = [j for j in jumps if j[0] < t_end]
    for stop in times:
        while t > stop and np.any(lam):  # else lambda stays 0 down to the next jump
            r = solver.step(stop, method="onestep", tstop=stop)
            if not r.success:
                raise IntegrationError(f"the adjoint's backward integration failed at t = {t:.6g} s: {r.message}")
            if r.t >= t:  # CVODE handing the same step back after an interpolation
                continue
            lam_step, t_step = np.array(r.y, dtype=float), float(r.t)
            half, middle = (t - t_step) / 2.0, (t + t_step) / 2.0
            for xi, wi in zip(x, w):
                tg = middle + half * xi
                part = wi * half * np.asarray(integrand(tg, solver.step(tg).y), dtype=float)
                q = part if q is None else q + part
            lam, t = lam_step, t_step
            steps += 1
        t = stop
        added = [g for tj, g in jumps if tj == stop]
        if added:
            for g in added:
                lam = lam + g
            solver.init_step(t, lam)
    return lam, q, dict(backward_steps=steps, backward_jacobians=adjoint.evaluations)


def _stops(t0, t_end, candidates):
    """The times in [t0, t_end) the backward steps end at, decreasing, ending with t0; times
    closer than :data:`RESOLUTION` of the span to a later one are dropped."""
    gap = RESOLUTION * max(abs(t_end), abs(t0), t_end - t0)
    kept, last = [], float(t_end)
    for c in sorted({float(c) for c in candidates if t0 < c < t_end}, reverse=True):
        if last - c > gap:
            kept.append(c)
            last = c
    if kept and kept[-1] - t0 <= gap:
        kept.pop()
    return [*kept, float(t0)]
