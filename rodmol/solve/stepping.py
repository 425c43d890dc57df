"""CVODE kept alive between calls: scikit-sundae's CVODE for a system, its
options, and the one step loop every CVODE run takes, of a rod or of a system
of rods and bodies (any :class:`rodmol.discretise.protocol.Discretised`).

:func:`solver_options` turns the CVODE backend's options into scikit-sundae's
(the linear solver the system offers, its compiled Jacobian or
preconditioner, the tolerances). :class:`Stepper` builds CVODE once for a
system and takes its internal steps (:meth:`Stepper.step`, each checked by
:class:`rodmol.solve.watch.Watch`, the right-hand sides by
:class:`rodmol.solve.watch.RatesWatch`): :func:`rodmol.solve.cvode.cvode`
drives it through a run's output times, and the stepping simulator advances
it from its current time to the next on request (:meth:`Stepper.advance`).
Between calls the caller may change the system's inputs;
:meth:`Stepper.restart` then re-initialises CVODE at the current state
(``CVodeReInit``: the memory, the linear solver and the kernels are kept,
only the BDF history is dropped), which :meth:`Stepper.advance` does on its
own when asked.
"""

import contextlib
import warnings
from bisect import bisect_right

import numpy as np
from scipy import sparse

from ..discretise.protocol import JACOBIANS, LINEAR_SOLVERS
from ..errors import ParameterError
from .outputs import cause, step_size_stats
from .watch import RatesNotFinite, RatesWatch, Watch

#: GMRES's Krylov dimension with the preconditioner (SUNDIALS' default): with left
#: preconditioning the fastest of {left, right} x {1, 5} on the bending test.
KRYLOV_DIM = 5
#: The reason :meth:`Stepper.advance` gives for a Ctrl-C.
INTERRUPTED = "interrupted"


class StepFailed(Exception):
    """Raised inside :meth:`Stepper.advance` to end it; carries the reason and the exception."""

    def __init__(self, reason, error=None):
        super().__init__(reason)
        self.reason, self.error = reason, error


class Stepper:
    """CVODE (BDF) over ``system`` from state ``y0`` at ``t0`` [s].

    ``rtol``, ``atol`` and ``options`` (the CVODE backend's options:
    ``linsolver``, ``jacobian``, ``max_order``, ``max_step``,
    ``max_nonlin_iters``) as for :func:`rodmol.solve.cvode.cvode`; they are
    checked here, before any work.
    """

    def __init__(self, system, t0, y0, *, rtol, atol, **options):
        from sksundae.cvode import CVODE

        self.system = system
        options, self.linsolver, self.precond = solver_options(system, rtol, atol, **options)
        self.evals = 0
        self.sizes = []  # of the internal steps taken [s]
        self.restarts, self._njev, self._njev_before = 0, 0, 0  # CVODE's Jacobian count restarts with it
        #: Time [s] of the last right-hand side that raised (None: none did).
        self.failed_at = None
        self._watch = None  # the first advance's, renewed for each
        self.rates_watch = RatesWatch(system)
        # An exception raised through scikit-sundae's sparse (SuperLU_MT) path crashes the
        # process (a segmentation fault, found by review): there the right-hand side keeps
        # it, returns NaN rates, which fail CVODE's step at once, and step raises it.
        self._kept = None
        rates = self._kept_rhs if self.linsolver == "sparse" else self._rhs
        with warnings.catch_warnings():
            # scikit-sundae warns that its own coloured differences are not used
            # when both `sparsity` and `jacfn` are given: that is the point.
            warnings.filterwarnings("ignore", "Custom sparse Jacobian", UserWarning)
            self._solver = CVODE(rates, **options)
        self.t, self.y = float(t0), np.array(y0, dtype=float)
        self.knots = np.unique(np.asarray(system.knot_times(), dtype=float))  # the inputs' kinks [s], sorted
        self._knots = self.knots.tolist()  # for bisect: stop_time runs at every step, numpy's call costs 1 us
        #: Time [s] CVODE's steps have reached (beyond ``t`` inside an advance).
        self.reached = self.t
        self._fresh = False  # CVODE holds no history to continue from
        self.restart(self.t, self.y)

    def _rhs(self, t, y, yp):
        self.evals += 1
        try:
            self.system(t, y, yp)
        except Exception:
            # Only the inputs raise (a function of the user's): shorter steps would
            # not help, so the exception stops CVODE at once (scikit-sundae hands
            # it on); the frames of a step that reached past the failure are
            # integrated again by outputs.keep_before_failure.
            self.failed_at = t
            raise
        if self.evals > self.rates_watch.watched_from:
            self.rates_watch.check(t, y, yp)

    def _kept_rhs(self, t, y, yp):
        if self._kept is None:
            try:
                return self._rhs(t, y, yp)
            except BaseException as exc:  # noqa: BLE001 (raised again by step)
                self._kept = exc
        yp[:] = np.nan

    def mark(self):
        """An output frame was reached: the right-hand sides' watch counts afresh."""
        self.rates_watch.mark(self.evals)

    def restart(self, t, y):
        """Re-initialise CVODE at state ``y`` at time ``t`` [s] (its BDF history is dropped)."""
        self.t, self.y = float(t), np.array(y, dtype=float)
        self.reached = self.t
        self._kept = None
        self.mark()
        self._njev_before, self._njev = self._njev_before + self._njev, 0
        with _small_pages():  # the first call allocates the solver's memory
            self._solver.init_step(self.t, self.y)
        self.restarts += 1
        self._fresh = True

    def step(self, tout, tstop, watch):
        """One internal CVODE step towards ``tout`` [s] (the first step is sized by the
        distance to it), ending at ``tstop`` [s] at the latest, checked by ``watch``:
        returns (scikit-sundae's result, None) or (the result or None, why the
        integration must stop)."""
        try:
            r = self._solver.step(tout, method="onestep", tstop=tstop)
            if self._kept is not None:
                raise self._kept
        except RatesNotFinite as exc:
            return None, str(exc)
        self._fresh, self._njev = False, int(r.njev)
        if not r.success:
            return r, r.message
        # After output times were interpolated inside the last step, CVODE's
        # next one-step call hands that step back again: count real steps only.
        if r.t > self.reached:
            self.sizes.append(r.t - self.reached)
            self.reached = r.t
            broken = watch.state(r.t, self.sizes[-1], r.y)
            if broken:
                return r, broken
        return r, None

    def interpolate(self, t):
        """The state at ``t`` [s] inside the last step, by CVODE's interpolant."""
        return self._solver.step(t).y

    def advance(self, t_end, restart=False, max_wall_time=None, progress=None, exact_end=True):
        """Integrate to ``t_end`` [s]. Returns None if all went well, else (reason, exception
        or None); the stepper then stays at its state before the call (re-initialised there).

        ``restart`` re-initialises CVODE first (the inputs jumped). ``exact_end`` ends the
        last internal step at ``t_end`` (the inputs may jump there); False lets the steps go
        on past it, as one run's do past an output time, and the state at ``t_end`` is
        CVODE's interpolant: a caller holding its inputs over many calls then costs what one
        run costs. A following call that restarts drops the steps taken past its start. A
        call without ``exact_end`` that fails is tried once more with it (from the same
        start), so a step past ``t_end`` does not fail a call that stops before it.
        """
        t_start, y_start = self.t, self.y
        if restart and not self._fresh:
            self.restart(t_start, y_start)
        self.mark()
        if self._watch is None:
            self._watch = Watch(self.system, (t_start, t_end))
        watch = self._watch.again((t_start, t_end), max_wall_time, progress)
        failed = self._attempt(t_end, watch, exact_end)
        if failed and not exact_end and failed[0] != INTERRUPTED:
            self.restart(t_start, y_start)
            failed = self._attempt(t_end, watch, True)
        if failed:
            self.restart(t_start, y_start)
        return failed

    def _attempt(self, t_end, watch, exact_end):
        """Steps to ``t_end`` [s] from where CVODE is: None, or (reason, exception or None)."""
        t_start = self.t
        try:
            self._steps(t_end, watch, exact_end)
        except StepFailed as failed:
            return failed.reason, failed.error
        except KeyboardInterrupt:
            return INTERRUPTED, None
        except Exception as exc:  # noqa: BLE001 (a user callback's: reported, the state kept)
            return cause(exc, t_start), exc
        return None

    def _steps(self, t_end, watch, exact_end):
        r = None
        while self.reached < t_end:
            r, problem = self.step(t_end, self.stop_time(t_end, exact_end), watch)
            if problem:
                raise StepFailed(_why(watch, problem))
            slow = watch.pace(r.t, r.y)
            if slow and r.t < t_end:
                raise StepFailed(_why(watch, slow))
        # At a step's end its state, else CVODE's interpolant inside the last step.
        y = r.y if r is not None and r.t == t_end else self.interpolate(t_end)
        # unit quaternions, as simulate's frames (the dynamics do not see |Q|)
        self.t, self.y = float(t_end), np.array(y)
        self.system.project_quaternions(self.y)

    def stop_time(self, t_end, exact_end=True):
        """Where the next internal step must end at the latest [s]: the first knot of the
        inputs after the steps reached (the system's ``knot_times()``: a long step must not
        stride over a short ramp), and ``t_end`` if ``exact_end``; None: anywhere."""
        k = bisect_right(self._knots, self.reached)
        knot = self._knots[k] if k < len(self._knots) else None
        if exact_end and (knot is None or knot > t_end):
            return float(t_end)
        return knot

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


def linear_solver(system, linsolver):
    """The linear solver ``linsolver`` ("auto" or a name) on ``system``, or a ParameterError
    naming those it offers (:meth:`~rodmol.discretise.protocol.Discretised.linear_solvers`)."""
    offered = system.linear_solvers()
    if linsolver == "auto":
        return next(iter(offered))
    if linsolver not in offered:
        why = getattr(system, "refused_solvers", {}).get(linsolver)
        if why:
            raise ParameterError(f"`linsolver` {linsolver!r} is refused for this system: {why}; valid: "
                                 f"{['auto', *offered]}")
        which = "" if set(offered) == set(LINEAR_SOLVERS) else " for this system"
        raise ParameterError(f"unknown `linsolver` {linsolver!r}{which}; valid: {['auto', *offered]}")
    return linsolver


def solver_options(system, rtol, atol, linsolver="auto", max_step=0.0, jacobian="auto", max_order="auto",
                   max_nonlin_iters=3):
    """scikit-sundae's ``CVODE`` options for ``system`` (see :func:`rodmol.solve.cvode.cvode` for the
    arguments): returns (options, the linear solver chosen, the preconditioner or None)."""
    from sksundae.cvode import CVODEJacTimes, CVODEPrecond

    linsolver = linear_solver(system, linsolver)
    if jacobian == "auto":
        jacobian = system.linear_solvers()[linsolver]
    if jacobian not in JACOBIANS:
        raise ParameterError(f"unknown `jacobian` {jacobian!r}; valid: {['auto', *JACOBIANS]}")
    if linsolver == "gmres" and jacobian != "compiled":
        raise ParameterError("linsolver='gmres' is preconditioned with the compiled Jacobian; "
                             "use jacobian='auto' or 'compiled'")
    if max_order == "auto":
        max_order = 2 if system.lightly_damped else 5
    options = dict(method="BDF", rtol=rtol, atol=atol, linsolver=linsolver,
                   max_num_steps=1_000_000, max_step=max_step, max_order=int(max_order),
                   max_nonlin_iters=int(max_nonlin_iters))
    scale = np.broadcast_to(atol, (system.size,)) / rtol
    precond = None
    if linsolver == "gmres":
        precond = system.preconditioner(scale)
        options["precond"] = CVODEPrecond(precond.setup, precond.solve, "left")
        options["krylov_dim"] = KRYLOV_DIM
        if hasattr(system, "jacobian_times"):  # its own products J v (a system with sensitivities)
            options["jactimes"] = CVODEJacTimes(None, system.jacobian_times(scale))
    elif linsolver in ("band", "lapackband"):
        options["lband"], options["uband"] = system.bandwidths()
    if jacobian == "compiled" and linsolver != "gmres":
        matrix = "band" if linsolver in ("band", "lapackband") else linsolver
        try:
            jac = system.jacobian(scale, matrix)
        except ValueError as exc:
            raise ParameterError(f"jacobian='compiled' with linsolver={linsolver!r}: {exc}") from None
        options["jacfn"] = jac
        if matrix == "sparse":
            options["sparsity"] = jac.sparsity
    elif linsolver == "sparse":
        options["sparsity"] = sparse.csc_matrix(system.pattern())

    return options, linsolver, precond


@contextlib.contextmanager
def _small_pages():
    """Allocate without numpy's transparent-huge-page advice.

    With a ``jacfn``, scikit-sundae allocates a dense (n, n) template for the
    band solver, of which only the band is ever touched; numpy advises 2 MB
    pages for large arrays, so writing the band made the kernel clear every
    2 MB page of it (the whole n^2 array, 460 MB at N = 400, 0.2 s per
    solver start). With 4 kB pages only the band's own pages are cleared.
    """
    core = getattr(np, "_core", None) or getattr(np, "core", None)
    setter = getattr(getattr(core, "multiarray", None), "_set_madvise_hugepage", None)
    if setter is None:  # not a numpy that advises huge pages: nothing to undo
        yield
        return
    previous = setter(False)
    try:
        yield
    finally:
        setter(previous)
