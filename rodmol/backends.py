"""Time-integration backends, chosen by name from one table.

Each backend integrates ``dy/dt = system(t, y)`` from ``t_out[0]`` and returns
a :class:`RawSolution` holding the states at the output times reached, so a
failed or interrupted run keeps what it computed.
"""

import time
from dataclasses import dataclass, field

import numpy as np
from scipy import sparse
from scipy.integrate import RK23

from .errors import ParameterError

DEFAULT_RTOL = 1e-6
LINEAR_SOLVERS = ("band", "lapackband", "sparse", "dense")


@dataclass
class RawSolution:
    t: np.ndarray
    y: np.ndarray
    success: bool
    message: str
    stats: dict = field(default_factory=dict)


class _Outputs:
    """Collects states at the output times and reports progress."""

    def __init__(self, t_out, y0, progress):
        self.t_out, self.progress = t_out, progress
        self.ys = [np.array(y0, dtype=float)]
        self.start = time.perf_counter()

    @property
    def next_index(self):
        return len(self.ys)

    @property
    def done(self):
        return len(self.ys) == len(self.t_out)

    def add(self, y):
        self.ys.append(np.array(y, dtype=float))
        if self.progress is not None:
            self.progress(self.t_out[len(self.ys) - 1], self.t_out[-1])

    def solution(self, success, message, **stats):
        stats["wall_time_s"] = time.perf_counter() - self.start
        n = len(self.ys)
        return RawSolution(self.t_out[:n].copy(), np.array(self.ys), success, message, stats)


def cvode(system, y0, t_out, *, rtol, atol, progress=None, linsolver="band",
          max_step=0.0):
    """SUNDIALS CVODE (BDF) through scikit-sundae, with a banded Jacobian by default.

    ``linsolver`` is ``"band"`` (SUNDIALS' finite-difference band Jacobian,
    the fastest here), ``"lapackband"``, ``"sparse"`` (SuperLU_MT with the
    structural pattern) or ``"dense"`` (small systems only).
    """
    from sksundae.cvode import CVODE

    if linsolver not in LINEAR_SOLVERS:
        raise ParameterError(f"unknown `linsolver` {linsolver!r}; valid: {list(LINEAR_SOLVERS)}")
    options = dict(method="BDF", rtol=rtol, atol=atol, linsolver=linsolver,
                   max_num_steps=1_000_000, max_step=max_step)
    if linsolver in ("band", "lapackband"):
        options["lband"], options["uband"] = system.layout.bandwidths()
    elif linsolver == "sparse":
        options["sparsity"] = sparse.csc_matrix(system.layout.pattern())

    evals = [0]  # counted here: CVODE's own counter leaves out the Jacobian's evaluations

    def rhs(t, y, yp):
        evals[0] += 1
        system(t, y, yp)

    out = _Outputs(t_out, y0, progress)
    t_end = float(t_out[-1])
    steps, r = 0, None
    solver = CVODE(rhs, **options)
    try:
        solver.init_step(float(t_out[0]), y0)
        while not out.done:
            r = solver.step(t_end, method="onestep", tstop=t_end)
            if not r.success:
                return out.solution(False, f"CVODE failed at t = {r.t:.6g} s: {r.message}",
                                    steps=steps, rhs_evals=evals[0], jac_evals=r.njev)
            steps += 1
            while not out.done and out.t_out[out.next_index] <= r.t:
                t_k = out.t_out[out.next_index]
                out.add(r.y if t_k == r.t else solver.step(t_k).y)
    except (Exception, KeyboardInterrupt) as exc:
        reached = out.t_out[out.next_index - 1]
        reason = "interrupted" if isinstance(exc, KeyboardInterrupt) else f"{type(exc).__name__}: {exc}"
        return out.solution(False, f"CVODE stopped after t = {reached:.6g} s: {reason}",
                            steps=steps, rhs_evals=evals[0], jac_evals=int(r.njev) if r else 0)
    return out.solution(True, "The solver reached the end time.", steps=steps,
                        rhs_evals=evals[0], jac_evals=int(r.njev))


def rk23(system, y0, t_out, *, rtol, atol, progress=None, max_step=np.inf):
    """scipy's explicit Bogacki-Shampine RK23 on the same right-hand side (cross-check).

    Its step is bounded by the explicit stability limits, so it is slow on
    fine grids.
    """
    evals = [0]

    def rhs(t, y):
        evals[0] += 1
        return system(t, y)

    out = _Outputs(t_out, y0, progress)
    steps = 0
    try:
        solver = RK23(rhs, float(t_out[0]), np.array(y0, dtype=float), float(t_out[-1]),
                      rtol=rtol, atol=atol, max_step=max_step or np.inf)
        while not out.done:
            message = solver.step()
            if solver.status == "failed":
                return out.solution(False, f"RK23 failed at t = {solver.t:.6g} s: {message}",
                                    steps=steps, rhs_evals=evals[0], jac_evals=0)
            steps += 1
            dense = solver.dense_output()
            while not out.done and out.t_out[out.next_index] <= solver.t:
                out.add(dense(out.t_out[out.next_index]))
    except (Exception, KeyboardInterrupt) as exc:
        reached = out.t_out[out.next_index - 1]
        reason = "interrupted" if isinstance(exc, KeyboardInterrupt) else f"{type(exc).__name__}: {exc}"
        return out.solution(False, f"RK23 stopped after t = {reached:.6g} s: {reason}",
                            steps=steps, rhs_evals=evals[0], jac_evals=0)
    return out.solution(True, "The solver reached the end time.", steps=steps,
                        rhs_evals=evals[0], jac_evals=0)


#: Backends by name.
BACKENDS = {"cvode": cvode, "rk23": rk23}


def get_backend(name):
    try:
        return BACKENDS[name]
    except (KeyError, TypeError):
        raise ParameterError(f"unknown `backend` {name!r}; valid backends are {sorted(BACKENDS)}") from None
