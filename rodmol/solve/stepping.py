"""CVODE kept alive between calls: the integrator of a stepping simulation.

:class:`Stepper` builds scikit-sundae's CVODE once for a system (options from
:func:`rodmol.solve.cvode.solver_options`, so the linear solver, the compiled
Jacobian or block preconditioner and the tolerances are those of
:func:`rodmol.solve.cvode.cvode`) and advances it from its current time to the
next on request. Between calls the caller may change the system's inputs;
:meth:`Stepper.restart` then re-initialises CVODE at the current state
(``CVodeReInit``: the memory, the linear solver and the kernels are kept, only
the BDF history is dropped), which :meth:`Stepper.advance` does on its own when
asked. Each internal step is checked by :class:`rodmol.solve.watch.Watch`, as
in a run of :func:`rodmol.simulate`.
"""

import numpy as np

from .cvode import _small_pages, solver_options
from .outputs import cause, step_size_stats
from .watch import Watch


class StepFailed(Exception):
    """Raised inside :meth:`Stepper.advance` to end it; carries the reason and the exception."""

    def __init__(self, reason, error=None):
        super().__init__(reason)
        self.reason, self.error = reason, error


class Stepper:
    """CVODE (BDF) over ``system`` from state ``y0`` at ``t0`` [s].

    ``rtol``, ``atol`` and ``options`` (the CVODE backend's options:
    ``linsolver``, ``jacobian``, ``max_order``, ``max_step``,
    ``max_nonlin_iters``) as for :func:`rodmol.solve.cvode.cvode`.
    """

    def __init__(self, system, t0, y0, *, rtol, atol, **options):
        from sksundae.cvode import CVODE

        self.system = system
        options, self.linsolver, self.precond = solver_options(system, rtol, atol, **options)
        self.evals = 0
        self.sizes = []  # of the internal steps taken [s]
        self.restarts, self._njev, self._njev_before = 0, 0, 0  # CVODE's Jacobian count restarts with it
        self._solver = CVODE(self._rhs, **options)
        self.t, self.y = float(t0), np.array(y0, dtype=float)
        self._fresh = False  # CVODE holds no history to continue from
        self.restart(self.t, self.y)

    def _rhs(self, t, y, yp):
        self.evals += 1
        self.system(t, y, yp)  # an input's exception stops CVODE at once, as in cvode()

    def restart(self, t, y):
        """Re-initialise CVODE at state ``y`` at time ``t`` [s] (its BDF history is dropped)."""
        self.t, self.y = float(t), np.array(y, dtype=float)
        self._njev_before, self._njev = self._njev_before + self._njev, 0
        with _small_pages():  # the first call allocates the solver's memory
            self._solver.init_step(self.t, self.y)
        self.restarts += 1
        self._fresh = True

    def advance(self, t_end, restart=False, max_wall_time=None, progress=None):
        """Integrate to ``t_end`` [s]; ``restart`` re-initialises CVODE first (the inputs
        jumped). Returns None if all went well, else (reason, exception or None); the
        stepper then stays at its state before the call (re-initialised there)."""
        t_start, y_start = self.t, self.y
        if restart and not self._fresh:
            self.restart(t_start, y_start)
        watch = Watch(self.system, (t_start, t_end), max_wall_time, progress)
        try:
            self._steps(t_end, watch)
        except StepFailed as failed:
            self.restart(t_start, y_start)
            return failed.reason, failed.error
        except KeyboardInterrupt:
            self.restart(t_start, y_start)
            return "interrupted", None
        except Exception as exc:  # noqa: BLE001 (a user callback's: reported, the state kept)
            self.restart(t_start, y_start)
            return cause(exc, t_start), exc
        return None

    def _steps(self, t_end, watch):
        solver, t_last = self._solver, self.t
        while True:
            r = solver.step(t_end, method="onestep", tstop=t_end)
            self._fresh, self._njev = False, int(r.njev)
            if not r.success:
                raise StepFailed(_why(watch, r.message))
            if r.t > t_last:
                self.sizes.append(r.t - t_last)
                t_last = r.t
                broken = watch.state(r.t, self.sizes[-1], r.y)
                if broken:
                    raise StepFailed(_why(watch, broken))
            if r.t >= t_end:
                # unit quaternions, as simulate's frames (the dynamics do not see |Q|)
                self.t, self.y = float(t_end), np.array(r.y)
                self.system.layout.project_quaternions(self.y)
                return
            slow = watch.pace(r.t, r.y)
            if slow:
                raise StepFailed(_why(watch, slow))

    def stats(self):
        """Steps, evaluations and step sizes so far, as a run's ``stats``."""
        info = dict(steps=len(self.sizes), rhs_evals=self.evals, linear_solver=self.linsolver,
                    restarts=self.restarts, **step_size_stats(self.sizes))
        if self.precond is not None:
            info.update(jac_evals=self.precond.jac_evals, prec_setups=self.precond.setups,
                        prec_solves=self.precond.solves)
        else:
            info["jac_evals"] = self._njev_before + self._njev
        return info


def _why(watch, reason):
    """Why a step failed, with how far CVODE got (``watch``: its :class:`Watch`)."""
    return (f"CVODE reached t = {watch.t:.6g} s in {watch.steps} steps "
            f"(last step {watch.h_last:.3g} s): {reason}")
