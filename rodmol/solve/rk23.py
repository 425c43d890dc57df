"""scipy's explicit RK23, the cross-check backend."""

import numpy as np
from scipy.integrate import RK23

from .outputs import Outputs, run_steps, step_size_stats
from .watch import Watch


def rk23(system, y0, t_out, *, rtol, atol, progress=None, max_wall_time=None, max_step=np.inf):
    """scipy's explicit Bogacki-Shampine RK23 on the same right-hand side (cross-check).

    Its step is bounded by the explicit stability limits, so it is slow on
    fine grids. Every step is checked by :class:`rodmol.solve.watch.Watch`. ``system``: any
    :class:`rodmol.discretise.protocol.Discretised`.
    """
    evals = [0]

    def rhs(t, y):
        evals[0] += 1
        return system(t, y)

    watch = Watch(system, t_out, max_wall_time, progress)
    out = Outputs(t_out, y0, progress, system, "RK23", watch)
    sizes = []

    def stats():
        return dict(steps=len(sizes), rhs_evals=evals[0], jac_evals=0, **step_size_stats(sizes))

    def stop(reason, error=None):
        return out.stopped(reason, error, **stats())

    def steps():
        solver = RK23(rhs, float(t_out[0]), np.array(y0, dtype=float), float(t_out[-1]),
                      rtol=rtol, atol=atol, max_step=max_step or np.inf)
        while not out.done:
            message = solver.step()
            if solver.status == "failed":
                return stop(message)
            sizes.append(solver.t - solver.t_old)
            broken = watch.state(solver.t, sizes[-1], solver.y)
            if broken:
                return stop(broken)
            if out.t_out[out.next_index] <= solver.t:  # the interpolant only when needed
                dense = solver.dense_output()
                while not out.done and out.t_out[out.next_index] <= solver.t:
                    out.add(dense(out.t_out[out.next_index]))
            slow = watch.pace(solver.t, solver.y)
            if slow and not out.done:
                return stop(slow)
    return run_steps(steps, stop, out, stats)
