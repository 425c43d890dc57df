"""Generalized-alpha for first-order systems: fixed steps, controllable numerical damping.

The scheme of Jansen, Whiting and Hulbert (Comput. Methods Appl. Mech. Engrg.
190, 2000) for dy/dt = f(t, y), with the rate ydot carried as its own
variable. One step from (y_n, ydot_n) to (y_n+1, ydot_n+1):

    y_n+1          = y_n + dt ((1 - gamma) ydot_n + gamma ydot_n+1)
    ydot_n+alpha_m = f(t_n + alpha_f dt, y_n + alpha_f (y_n+1 - y_n))

with ydot_n+alpha_m = ydot_n + alpha_m (ydot_n+1 - ydot_n) and, from the
spectral radius rho_inf in [0, 1] of the amplification at dt -> infinity,

    alpha_m = (3 - rho_inf) / (2 (1 + rho_inf)),  alpha_f = 1 / (1 + rho_inf),
    gamma = 1/2 + alpha_m - alpha_f   (second order for every rho_inf).

rho_inf = 1 is the implicit midpoint rule: no numerical damping, quadratic
invariants (the linear rod's energy) kept exactly; rho_inf < 1 damps the
modes with omega dt >> 1 by rho_inf per step and the resolved ones by
O((omega dt)^3) per step; rho_inf = 0 is BDF2-like (L-stable).

In the unknown Y = y_n+alpha_f the step is Y - g f(t*, Y) = b with
g = gamma alpha_f dt / alpha_m: a Newton matrix I - g J of the same form as
CVODE's, with g fixed while the step is. It is factored once and reused
(modified Newton) until the iterations slow down; the factorisation is the
system's exact block solve (``system.preconditioner``), or a sparse LU where
the structure does not fit it (:mod:`rodmol.solve.newton_matrix`). A step
whose iterations fail even with a fresh Jacobian is halved, up to
``MAX_HALVINGS`` times, and the full step resumes on the next full-step
boundary.
"""

from functools import partial

import numpy as np

from ..errors import ParameterError
from .newton_matrix import CONVERGED, DIVERGED, NOT_FINITE, SLOW, newton_matrix
from .outputs import Outputs, run_steps, step_size_stats
from .watch import STALL_STEP, Watch

#: Steps per first bending period of the rod when ``dt="auto"`` (period
#: error of the midpoint rule about (2 pi / 100)^2 / 12 = 0.03%).
STEPS_PER_PERIOD = 100
#: Weighted RMS norm (in units of the tolerances rtol |y| + atol) below which
#: the Newton iteration counts as converged.
NEWTON_TOLERANCE = 0.1
#: Newton iterations per attempt; a step that needs more is retried once with
#: a fresh Jacobian, and one that needed more than ``SLOW_ITERATIONS``
#: refreshes the Jacobian for the next step (measured on the steel
#: cantilever: fewer refreshes cost more iterations than they save).
MAX_NEWTON_ITERATIONS = 6
SLOW_ITERATIONS = 3
#: Most halvings of a step whose Newton iterations fail (down to dt / 1024).
MAX_HALVINGS = 10
#: Factor by which the estimated convergence rate may fall per iteration (CVODE's).
RATE_DECAY = 0.3
#: Convergence rate above which the iteration is abandoned as diverging.
MAX_RATE = 0.9


def coefficients(rho_inf):
    """(alpha_m, alpha_f, gamma) of spectral radius ``rho_inf``."""
    alpha_m = (3.0 - rho_inf) / (2.0 * (1.0 + rho_inf))
    alpha_f = 1.0 / (1.0 + rho_inf)
    return alpha_m, alpha_f, 0.5 + alpha_m - alpha_f


def auto_dt(system):
    """The step of ``dt="auto"`` [s]: the system's first bending period over STEPS_PER_PERIOD
    (of a system of rods, the shortest rod's)."""
    return system.bending_period() / STEPS_PER_PERIOD


def generalized_alpha(system, y0, t_out, *, rtol, atol, progress=None, max_wall_time=None,
                      dt="auto", rho_inf=0.9, python_loop=False):
    """Fixed-step implicit generalized-alpha (see the module docstring).

    ``dt`` [s] is the step, shortened to fit a whole number of steps into
    the run (and halved where the Newton iterations fail); ``"auto"`` is
    the rod's first bending period / 100.
    ``rho_inf`` in [0, 1] is the numerical damping at high frequency: 1 none
    (energy kept), 0 the most. ``rtol``/``atol`` set the accuracy of the
    Newton solve of each step, not the step (there is no error control).
    The outputs are cubic Hermite interpolants of the step ends.
    ``python_loop=True`` runs the Newton iterations' loop by Python even
    where it could run compiled (a cross-check for the tests).
    """
    t0, t_end = float(t_out[0]), float(t_out[-1])
    dt = auto_dt(system) if dt == "auto" else float(dt)
    n_steps = max(1, int(np.ceil((t_end - t0) / dt * (1.0 - 1e-12))))
    if n_steps * STALL_STEP > 1.0:  # the Watch would call it a stall: refuse it before any work
        raise ParameterError(f"`dt` = {dt!r} s asks for {n_steps:.3g} steps over the run of "
                             f"{t_end - t0:.6g} s; at most {1.0 / STALL_STEP:.3g} are allowed")
    h = (t_end - t0) / n_steps
    alpha_m, alpha_f, gamma = coefficients(float(rho_inf))
    kappa = alpha_m * (1.0 - gamma) / gamma - (1.0 - alpha_m)  # weight of ydot_n in b

    watch = Watch(system, t_out, max_wall_time, progress)
    out = Outputs(t_out, y0, progress, system, "generalized-alpha", watch)
    scale = np.broadcast_to(atol, (system.size,)) / rtol
    matrix = newton_matrix(system, scale)
    weight = np.empty(system.size)
    count = dict(rhs_evals=0, newton_iters=0, retries=0, halvings=0)
    sizes = []

    def rates(t, y, into):
        count["rhs_evals"] += 1
        system(t, y, into)
        return into

    def stats():
        return dict(steps=len(sizes), rhs_evals=count["rhs_evals"], jac_evals=matrix.jac_evals,
                    newton_iters=count["newton_iters"], retried_steps=count["retries"],
                    halved_steps=count["halvings"], linear_solver=matrix.name, dt=h,
                    rho_inf=float(rho_inf), **step_size_stats(sizes))

    def stop(reason, error=None):
        return out.stopped(reason, error, **stats())

    def newton(t_star, g, y_n, b, Y, f):
        """Solve Y - g f(t*, Y) = b in place from the guess Y: (outcome, iterations).

        The convergence rate is estimated within the step only: carried over
        from earlier steps (as CVODE does) it underestimated the rate of a
        Jacobian gone stale, ended iterations early and let the energy of
        the steel cantilever's swing grow by 3% in 25 s."""
        np.multiply(np.abs(y_n), rtol, out=weight)
        weight[:] = 1.0 / (weight + atol)
        compiled = matrix.compiled and not python_loop
        if compiled:  # the kernel reads the inputs set here
            system.update_inputs(t_star)
        outcome, k = matrix.iterate(Y, b, g, f, weight, NEWTON_TOLERANCE, MAX_NEWTON_ITERATIONS, MAX_RATE,
                                    RATE_DECAY, rates=None if compiled else partial(system, t_star))
        count["rhs_evals"] += k
        count["newton_iters"] += k
        return outcome, k

    y = np.array(y0, dtype=float)
    t = t0
    f_start, f_end = np.empty_like(y), np.empty_like(y)  # rates at the step ends, for outputs
    def steps():
        nonlocal t, y
        ydot = rates(t0, y, np.empty_like(y))
        g = gamma * alpha_f * h / alpha_m  # the Newton matrix's I - g J, for the step h
        matrix.refresh(t0, y, ydot, g)
        a_previous = ydot.copy()
        stale = False
        Y, f = np.empty_like(y), np.empty_like(y)
        # Position on the grid t0 + (k + j / 2^level) h: a step whose Newton
        # iterations fail even with a fresh Jacobian is halved (level + 1),
        # and the full step is resumed on the next full-step boundary.
        k, j, level = 0, 0, 0
        while k < n_steps:
            h_now = h / 2**level
            t_next = t0 + (k + (j + 1) / 2**level) * h
            if gamma * alpha_f * h_now / alpha_m != g:
                g = gamma * alpha_f * h_now / alpha_m
                matrix.refactor(g)
            b = y + (g * kappa) * ydot
            for attempt in (0, 1):
                if stale or attempt:
                    matrix.refresh(t, y, rates(t, y, f_end), g)
                    stale = False
                # guess: the rate extrapolated linearly from the last two steps
                Y[:] = y + (alpha_f * h_now) * ((1.0 + gamma) * ydot - gamma * a_previous)
                outcome, iters = newton(t + alpha_f * h_now, g, y, b, Y, f)
                if outcome == CONVERGED:
                    break
                count["retries"] += 1
            else:
                if level == MAX_HALVINGS:
                    return stop(_failure(outcome, t, h_now))
                count["halvings"] += 1
                level, j = level + 1, 2 * j
                continue
            stale = iters > SLOW_ITERATIONS
            y_new = y + (Y - y) / alpha_f
            a_previous = ydot
            ydot = ((Y - y) / (alpha_f * h_now) - (1.0 - gamma) * ydot) / gamma
            sizes.append(h_now)
            j += 1
            while level and j % 2 == 0:
                level, j = level - 1, j // 2
            if j == 2**level:
                k, j = k + 1, 0
            broken = watch.state(t_next, h_now, y_new)
            if broken:
                return stop(broken)
            if out.t_out[out.next_index] <= t_next + 1e-9 * h_now:
                f0, f1 = rates(t, y, f_start), rates(t_next, y_new, f_end)
                while not out.done and out.t_out[out.next_index] <= t_next + 1e-9 * h_now:
                    out.add(_hermite(out.t_out[out.next_index], t, h_now, y, y_new, f0, f1))
            y, t = y_new, t_next
            slow = watch.pace(t, y)
            if slow and not out.done:
                return stop(slow)
    return run_steps(steps, stop, out, stats, now=lambda: t)


def _failure(outcome, t, h):
    what = {NOT_FINITE: "met non-finite rates", DIVERGED: "diverged",
            SLOW: f"did not converge in {MAX_NEWTON_ITERATIONS} iterations"}[outcome]
    return (f"the Newton iterations of the step from t = {t:.6g} s {what} with a fresh Jacobian, "
            f"even with the step halved {MAX_HALVINGS} times to {h:.3g} s: the load may be beyond what the rod can carry, or the step too "
            "long for the motion; use a smaller `dt` or a lower `rho_inf`")


def _hermite(t_k, t, h, y0, y1, f0, f1):
    """Cubic Hermite interpolant at t_k of the step [t, t + h] (third order)."""
    s = min(max((t_k - t) / h, 0.0), 1.0)
    if s == 1.0:
        return y1
    h00, h10 = (1 + 2 * s) * (1 - s) ** 2, s * (1 - s) ** 2
    h01, h11 = s * s * (3 - 2 * s), s * s * (s - 1)
    return h00 * y0 + h10 * h * f0 + h01 * y1 + h11 * h * f1
