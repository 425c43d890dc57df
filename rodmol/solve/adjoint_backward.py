"""The backward half of a continuous adjoint: lambda and the gradient's quadrature,
integrated by CVODE from the run's end back to its start.

With the forward run y(t) (:class:`rodmol.solve.checkpoints.ForwardRun`), J(t) = df/dy
and F(t) = df/dp at y(t), the state Lambda = [lambda, q] obeys::

    lambda' = -J(t)^T lambda,     q' = -F(t)^T lambda,     lambda(T+) = 0, q(T) = 0

with jumps lambda += dL/dy(t_k) at the loss's times (CVODE re-initialised there), so
that q(t0) = integral of lambda^T F dt and lambda(t0) is dL/dy(t0). Both are
integrated in t going down (SUNDIALS steps either way). J is the system's compiled
finite-difference Jacobian on its pattern, at the interpolated state; J and F are
evaluated once per distinct time (every right-hand side of a BDF step is at its
new time), and the Newton matrix's Jacobian is the same J^T and F^T. The linear
solver is SuperLU on the transposed pattern (``"sparse"``) or dense LU.
q's entries are left out of CVODE's error test (its weights ~0): they do not feed
back, and their integrand is as smooth as lambda's.
"""

import numpy as np
from scipy import sparse

from ..errors import IntegrationError

#: q's absolute tolerance: large, so that its entries carry no weight in the error test.
QUADRATURE_ATOL = 1e20
#: The backward integration's linear solvers.
LINEAR_SOLVERS = ("sparse", "dense")


class AdjointSystem:
    """The rates of Lambda = [lambda, q] (see the module docstring).

    Parameters
    ----------
    system : Discretised
    state : callable
        y(t) of the forward run.
    scale : (n,) array
        Typical magnitudes of the state (the Jacobian's steps).
    columns : callable
        ``columns(t, y, fy)`` -> F (n, P) = df/dp at (t, y).
    width : int
        P, the number of quadrature entries.
    """

    def __init__(self, system, state, scale, columns, width):
        self.system, self.state, self.columns, self.n, self.p = system, state, columns, system.size, width
        self.size = self.n + self.p
        self.jac = system.jacobian(scale, "sparse")
        pattern = sparse.csc_matrix(self.jac.sparsity, dtype=float)
        pattern.sort_indices()
        self._j = pattern
        self._data = np.zeros(pattern.nnz)
        # The transposed pattern's values in J's CSC order, and the augmented matrix
        # [[-J^T, 0], [-F^T, 0]] (CSC) with the source of each stored value.
        coded = sparse.csc_matrix((np.arange(1, pattern.nnz + 1, dtype=float), pattern.indices, pattern.indptr),
                                  shape=pattern.shape)
        quadrature = sparse.csc_matrix(-np.arange(1, self.p * self.n + 1, dtype=float).reshape(self.p, self.n))
        full = sparse.bmat([[coded.T, None], [quadrature, None]], format="csc",
                           dtype=float) if self.p else sparse.bmat([[coded.T]], format="csc", dtype=float)
        full.resize((self.size, self.size))
        full.sort_indices()
        codes = full.data.astype(np.int64)
        self.sparsity = sparse.csc_matrix((np.ones_like(full.data), full.indices, full.indptr), shape=full.shape)
        self._from_j = np.flatnonzero(codes > 0), codes[codes > 0] - 1
        self._from_f = np.flatnonzero(codes < 0), -codes[codes < 0] - 1  # into F^T (p, n) row-major
        self._t = None
        self.evaluations = 0

    def _at(self, t):
        """J (CSC values) and F at time t, once per distinct t."""
        if self._t != t:
            y = self.state(t)
            fy = self.system(t, y).copy()
            self.jac(t, y, fy, self._data)
            self.J = sparse.csc_matrix((self._data.copy(), self._j.indices, self._j.indptr), shape=self._j.shape)
            self.F = np.asarray(self.columns(t, y, fy), dtype=float).reshape(self.n, self.p)
            self._t = t
            self.evaluations += 1
        return self.J, self.F

    def rates(self, t, Y, out):
        J, F = self._at(t)
        lam = Y[:self.n]
        out[:self.n] = -(J.T @ lam)
        out[self.n:] = -(F.T @ lam)

    def sparse_jacobian(self, t, Y, fy, JJ):
        J, F = self._at(t)
        rows, source = self._from_j
        JJ[rows] = -J.data[source]
        rows, source = self._from_f
        JJ[rows] = -F.T.ravel()[source]

    def dense_jacobian(self, t, Y, fy, JJ):
        J, F = self._at(t)
        JJ[:] = 0.0
        JJ[:self.n, :self.n] = -J.T.toarray()
        JJ[self.n:, :self.n] = -F.T


def integrate_backward(adjoint, t0, t_end, jumps, stops, *, rtol, atol, linsolver="sparse", max_order=5):
    """lambda(t0) and q(t0): Lambda integrated from ``t_end`` down to ``t0`` [s].

    ``jumps`` is a list of (t [s], dL/dy (n,)) added to lambda at t; ``stops`` [s] are
    times the steps end at (the inputs' knots, the bounded forward run's segments);
    ``atol`` (n,) lambda's absolute tolerances. Returns (lambda (n,), q (p,), stats)."""
    from sksundae.cvode import CVODE

    n = adjoint.n
    jumps = sorted(((float(t), np.asarray(g, dtype=float)) for t, g in jumps), key=lambda j: -j[0])
    options = dict(method="BDF", rtol=rtol, atol=np.concatenate([atol, np.full(adjoint.p, QUADRATURE_ATOL)]),
                   max_num_steps=1_000_000, max_order=int(max_order))
    if linsolver == "sparse":
        options.update(linsolver="sparse", sparsity=adjoint.sparsity, jacfn=adjoint.sparse_jacobian)
    else:
        options.update(linsolver="dense", jacfn=adjoint.dense_jacobian)
    solver = CVODE(adjoint.rates, **options)
    Y = np.zeros(adjoint.size)
    times = sorted({float(t) for t in stops if t0 < t < t_end} | {j[0] for j in jumps if t0 < j[0] < t_end} | {t0},
                   reverse=True)
    t = float(t_end)
    for j in [j for j in jumps if j[0] >= t_end]:
        Y[:n] += j[1]
    solver.init_step(t, Y)
    jumps = [j for j in jumps if j[0] < t_end]
    for stop in times:
        if np.any(Y[:n]):  # else lambda stays 0 and q constant down to the next jump
            r = solver.step(stop, tstop=stop)
            if not r.success:
                raise IntegrationError(f"the adjoint's backward integration failed at t = {t:.6g} s: {r.message}")
            Y = np.array(r.y, dtype=float)
        t = stop
        added = [g for tj, g in jumps if tj == stop]
        if added:
            for g in added:
                Y[:n] += g
            solver.init_step(t, Y)
    return Y[:n], Y[n:], dict(backward_evaluations=adjoint.evaluations)
