"""Forward sensitivities as one larger system: :class:`SensitivitySystem`.

The state Y = [y, s_1, ..., s_P] holds the model's state y and its
derivatives s_i = dy/dp_i by P parameter components. Their rates are
ds_i/dt = J s_i + df/dp_i, taken as ONE central directional difference in
(y, p) of two systems of the model built at p_i + h_i and p_i - h_i
(:meth:`rodmol.named_parameters.Parameter.pair`)::

    D_i = [f(y + h_i s_i; p_i + h_i) - f(y - h_i s_i; p_i - h_i)] / (2 h_i)

so a call costs 1 + 2P right-hand sides and no Jacobian is formed. It is a
:class:`rodmol.discretise.protocol.Discretised`, so every backend that only
reads that protocol integrates it (CVODE, RK23): CVODE's GMRES gets the
block-diagonal product (J v_0, ..., J v_P) by one-sided differences of f
(:meth:`SensitivitySystem.jacobian_times`; CVODE's own difference of the
augmented rates would nest one difference inside another and amplify its
noise) and the system's own preconditioner on every block (the Newton
matrix is block lower-triangular with I - gamma J on its diagonal, as in
CVODES' simultaneous corrector).
"""

import numpy as np

#: Size of the one-sided difference of J v: the largest entry of sigma v is this fraction of its scale.
JV_STEP = 1e-7
#: Size of the difference of the quaternions' projection along s (unit quaternions).
PROJECTION_STEP = 1e-6


class SensitivitySystem:
    """The system of Y = [y, s_1..s_P] (see the module docstring).

    Parameters
    ----------
    base : Discretised
        The model's system (rates f(y; p)).
    pairs : list of (Discretised, Discretised)
        For each parameter component, the systems at p + h and p - h.
    steps : (P,) array
        The steps h_i [unit of p_i].
    """

    def __init__(self, base, pairs, steps):
        self.base, self.pairs = base, list(pairs)
        self.steps = np.asarray(steps, dtype=float)
        self.n, self.columns = base.size, len(self.pairs)
        self.size = self.n * (1 + self.columns)
        self.scheme, self.lightly_damped = base.scheme, base.lightly_damped
        # Work arrays: the right-hand sides run thousands of times.
        self._up, self._down, self._tmp, self._moved = (np.empty(self.n) for _ in range(4))
        probe = np.full(self.n, 2.0)
        base.project_quaternions(probe)
        self._quaternion = probe != 2.0  # the entries the projection moves

    def blocks(self, Y):
        """The views (y, s_1, ..., s_P) of ``Y`` (..., size)."""
        n = self.n
        return [Y[..., k * n:(k + 1) * n] for k in range(1 + self.columns)]

    # ---------------------------------------------------------------- rates

    def __call__(self, t, Y, out=None):
        if out is None:
            out = np.empty(self.size)
        n = self.n
        y = Y[:n]
        self.base(t, y, out[:n])
        moved, move = self._moved, self._tmp
        for i, (plus, minus) in enumerate(self.pairs):
            h, block = self.steps[i], slice((i + 1) * n, (i + 2) * n)
            np.multiply(Y[block], h, out=move)
            plus(t, np.add(y, move, out=moved), self._up)
            minus(t, np.subtract(y, move, out=moved), self._down)
            np.subtract(self._up, self._down, out=out[block])
            out[block] *= 0.5 / h
        return out

    def jacobian_times(self, scale):
        """scikit-sundae's ``jactimes.solvefn``: Jv of each block, J the model's, by one-sided
        differences of f at y (``fy`` the rates CVODE holds); ``scale`` (size,) typical magnitudes."""
        n, base = self.n, self.base
        inverse = 1.0 / np.asarray(scale, dtype=float)[:n]
        work, moved, rates = np.empty(n), np.empty(n), np.empty(n)

        def solve(t, Y, FY, V, JV):
            y, fy = Y[:n], FY[:n]
            for k in range(1 + self.columns):
                v, jv = V[k * n:(k + 1) * n], JV[k * n:(k + 1) * n]
                size = np.multiply(np.abs(v, out=work), inverse, out=work).max()
                if size == 0.0:
                    jv[:] = 0.0
                    continue
                sigma = JV_STEP / size
                np.multiply(v, sigma, out=moved)
                base(t, np.add(moved, y, out=moved), rates)
                np.subtract(rates, fy, out=jv)
                jv *= 1.0 / sigma
        return solve

    def preconditioner(self, scale):
        """The model's preconditioner applied to every block (its Newton matrix's diagonal)."""
        return BlockDiagonal(self, self.base.preconditioner(np.asarray(scale, dtype=float)[:self.n]))

    # ---------------------------------------------------------------- the model's, on y

    @property
    def inputs_vary(self):
        return self.base.inputs_vary

    def update_inputs(self, t, y=None):
        self.base.update_inputs(t, None if y is None else y[:self.n])
        for plus, minus in self.pairs:
            for system in (plus, minus):
                system.update_inputs(t, None if y is None else y[:self.n])

    def undeformed_state(self):
        return np.concatenate([self.base.undeformed_state(), np.zeros(self.size - self.n)])

    def atol_scale(self):
        """The model's scales, and theirs for each s_i (per unit of p_i)."""
        return np.tile(self.base.atol_scale(), 1 + self.columns)

    def entry_name(self, index):
        block, entry = divmod(int(index), self.n)
        name = self.base.entry_name(entry)
        return name if block == 0 else f"d/dp[{block - 1}] of {name}"

    def project_quaternions(self, Y):
        """Unit quaternions in y, and s_i the derivative of that projection along s_i
        (its difference, on the quaternions' entries only)."""
        Y = Y.reshape(-1, self.size)
        y, *sensitivities = self.blocks(Y)
        mask = self._quaternion
        for s in sensitivities:
            size = np.max(np.abs(s[:, mask]), axis=1, initial=0.0)[:, None]
            e = PROJECTION_STEP / np.where(size > 0.0, size, 1.0)
            up, down = y + e * s, y - e * s
            self.base.project_quaternions(up)
            self.base.project_quaternions(down)
            s[:, mask] = ((up - down) / (2.0 * e))[:, mask]
        y_own = np.ascontiguousarray(y)
        self.base.project_quaternions(y_own)
        y[:] = y_own

    def knot_times(self):
        return self.base.knot_times()

    def bending_period(self):
        return self.base.bending_period()

    def linear_solvers(self):
        """GMRES only: the products J v and the preconditioner are per block."""
        return {"gmres": "compiled"}

    def pattern(self):
        raise ValueError("a system with sensitivities has no Jacobian pattern (GMRES only)")

    def bandwidths(self):
        raise ValueError("a system with sensitivities has no band (GMRES only)")

    def jacobian(self, scale, matrix):
        raise ValueError("a system with sensitivities has no assembled Jacobian (GMRES only)")

    def state_problem(self, t, Y):
        return self.base.state_problem(t, Y[:self.n])

    def step_problem(self, t, Y):
        return self.base.step_problem(t, Y[:self.n])

    def describe_stall(self, Y):
        return self.base.describe_stall(Y[:self.n])


class BlockDiagonal:
    """The model's preconditioner ``own`` applied to each block of Y (scikit-sundae's callbacks)."""

    def __init__(self, system, own):
        self.system, self.own = system, own

    def setup(self, t, Y, FY, jok, jnew, gamma):
        n = self.system.n
        self.own.setup(t, Y[:n], FY[:n], jok, jnew, gamma)

    def solve(self, t, Y, FY, R, Z, gamma, delta, lr):
        n = self.system.n
        y, fy = Y[:n], FY[:n]
        for k in range(1 + self.system.columns):
            block = slice(k * n, (k + 1) * n)
            self.own.solve(t, y, fy, R[block], Z[block], gamma, delta, lr)

    @property
    def jac_evals(self):
        return self.own.jac_evals

    @property
    def setups(self):
        return self.own.setups

    @property
    def solves(self):
        return self.own.solves
