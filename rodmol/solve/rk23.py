"""scipy's explicit RK23, the cross-check backend."""

import numpy as np
from scipy.integrate import RK23

from .outputs import Outputs, step_size_stats


def rk23(system, y0, t_out, *, rtol, atol, progress=None, max_step=np.inf):
    """scipy's explicit Bogacki-Shampine RK23 on the same right-hand side (cross-check).

    Its step is bounded by the explicit stability limits, so it is slow on
    fine grids.
    """
    evals = [0]

    def rhs(t, y):
        evals[0] += 1
        return system(t, y)

    out = Outputs(t_out, y0, progress)
    sizes = []

    def stats():
        return dict(steps=len(sizes), rhs_evals=evals[0], jac_evals=0, **step_size_stats(sizes))

    try:
        solver = RK23(rhs, float(t_out[0]), np.array(y0, dtype=float), float(t_out[-1]),
                      rtol=rtol, atol=atol, max_step=max_step or np.inf)
        while not out.done:
            message = solver.step()
            if solver.status == "failed":
                return out.solution(False, f"RK23 failed at t = {solver.t:.6g} s: {message}",
                                    **stats())
            sizes.append(solver.t - solver.t_old)
            if out.t_out[out.next_index] <= solver.t:  # the interpolant only when needed
                dense = solver.dense_output()
                while not out.done and out.t_out[out.next_index] <= solver.t:
                    out.add(dense(out.t_out[out.next_index]))
    except (Exception, KeyboardInterrupt) as exc:
        reached = out.t_out[out.next_index - 1]
        reason = "interrupted" if isinstance(exc, KeyboardInterrupt) else f"{type(exc).__name__}: {exc}"
        return out.solution(False, f"RK23 stopped after t = {reached:.6g} s: {reason}", **stats())
    return out.solution(True, "The solver reached the end time.", **stats())


