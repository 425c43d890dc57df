"""Watching a time integration step by step, so a run that blows up, stalls or
overruns its budget ends at once with ``success=False`` and a message that
says where and why, instead of creeping on for hours.

Every accepted step (not only the output times) goes through
:meth:`Watch.state` and :meth:`Watch.pace`:

* the state is checked by the system's own ``step_problem`` (a rod's: one
  compiled scan, about a microsecond, :mod:`rodmol.discretise.state_checks`:
  non-finite entries, elements inverted, collapsed, torn or turning by
  more than :data:`MAX_TURN` rad over one element, orientations off unit
  norm, the tip section crushed by its cables; a system's: each rod's on its
  part, the bodies' for finiteness);
* every :data:`STALL_WINDOW` steps, the time covered by the window is
  compared with the run's span: a mean step below :data:`STALL_STEP` times
  the span means the run would need more than 1e7 steps (an hour or more at
  N = 100; the paper's tests take about 1e3): a stall, which the system
  describes (``describe_stall``);
* the wall-time budget ``max_wall_time`` (optional);
* ``progress(t, t_end)`` is called when :data:`PROGRESS_INTERVAL` seconds of
  wall time passed since the last report, so a stall is seen and can be
  stopped (Ctrl-C) between output times too;
* a stop asked by a signal (:func:`rodmol.solve.interrupts.stop_reason`,
  the command line's Ctrl-C and SIGTERM): the step is where the run stops
  safely.

CVODE's right-hand sides are watched too (:class:`RatesWatch`): rates that
stay non-finite, which CVODE cannot be told of, end the run naming the
entries. The system's ``state_problem`` checks the static equilibrium and a
user's initial state the same way. The system is any
:class:`rodmol.discretise.protocol.Discretised`.
"""

import copy
import math
import time

import numpy as np

# A rod's limits, here for the solvers' readers (tests, docs): the checks are the system's.
from ..discretise.state_checks import (  # noqa: F401
    MAX_QUATERNION_DRIFT,
    MAX_STRETCH,
    MAX_TURN,
    MIN_STRETCH,
    state_problem,  # noqa: F401
)
from .interrupts import stop_reason

#: Steps per stall check, and the mean step [fraction of the run's span]
#: below which the window counts as a stall (1e8 steps or more to go).
STALL_WINDOW = 1000
STALL_STEP = 1e-7
#: Wall time [s] between progress reports on internal steps.
PROGRESS_INTERVAL = 0.5
#: Non-finite right-hand sides since the last output frame after which CVODE's run stops:
#: CVODE (scikit-sundae's right-hand side cannot report a recoverable failure) would
#: otherwise retry ever shorter steps without end; a sound run meets none, or a few in
#: wild Newton iterates.
NONFINITE_RATES = 200
#: Right-hand sides since the last output frame before their rates are checked: a sound
#: run takes a few to a few hundred, and is not slowed by the check (2 % of the octopus's).
WATCHED_AFTER = 1000


class Watch:
    """The per-step checks of one integration of ``system`` (see the module docstring).

    ``t_span`` is (t0, t_end) [s]; ``max_wall_time`` [s] or None;
    ``progress(t, t_end)`` or None. :meth:`state` and :meth:`pace` return
    None while all is well, else the cause of the stop (a sentence).
    """

    def __init__(self, system, t_span, max_wall_time=None, progress=None):
        self.system, self._step_problem = system, system.step_problem
        self._begin(t_span, max_wall_time, progress)

    def again(self, t_span, max_wall_time=None, progress=None):
        """A new watch of the same system over ``t_span`` (its constants not derived again:
        a stepping simulator starts one per step)."""
        watch = copy.copy(self)
        watch._begin(t_span, max_wall_time, progress)
        return watch

    def _begin(self, t_span, max_wall_time, progress):
        self.t0, self.t_end = float(t_span[0]), float(t_span[-1])
        self.max_wall_time, self.progress = max_wall_time, progress
        self.start = time.perf_counter()
        self.reported = self.start
        self.steps, self.h_last, self.t = 0, 0.0, self.t0
        self._window_start, self._checked = self.t0, 0

    def state(self, t, h, y):
        """Check the state ``y`` at the end ``t`` [s] of an accepted step of size ``h`` [s]."""
        self.steps += 1
        self.t, self.h_last = t, h
        return self._step_problem(t, y)

    def pace(self, t, y):
        """After the outputs of a step: a stop asked by a signal, the stall test, the wall-time
        budget, progress."""
        asked = stop_reason()
        if asked:
            return asked
        if self.steps and self.steps % STALL_WINDOW == 0 and self.steps != self._checked:
            self._checked = self.steps
            covered, self._window_start = t - self._window_start, t
            if covered < STALL_WINDOW * STALL_STEP * (self.t_end - self.t0):
                return self._stall(covered, y)
        now = time.perf_counter()
        if self.max_wall_time is not None and now - self.start > self.max_wall_time:
            return (f"the wall-time budget max_wall_time = {self.max_wall_time:g} s is used up "
                    f"at t = {t:.6g} s")
        if self.progress is not None and now - self.reported >= PROGRESS_INTERVAL:
            self.reported = now
            self.progress(t, self.t_end)
        return None

    def _stall(self, covered, y):
        mean = covered / STALL_WINDOW
        to_go = (self.t_end - self.t) / mean if mean > 0 else math.inf
        return (f"stalled at t = {self.t:.6g} s: the last {STALL_WINDOW} steps covered only "
                f"{covered:.3g} s (mean step {mean:.3g} s, about {to_go:.3g} more steps to go). "
                + self.system.describe_stall(y) + self._stiff_hint())

    def _stiff_hint(self):
        if not self.system.lightly_damped:
            return ""
        return ("; or the rod is stiff and lightly damped (no mode of the grid is damped): try "
                "max_order=2 with CVODE or backend='galpha' (docs/troubleshooting.md)")


class RatesNotFinite(Exception):
    """Raised inside CVODE's right-hand side by :class:`RatesWatch`: its message says where and why."""


class RatesWatch:
    """Counts CVODE's right-hand sides with non-finite rates of ``system`` since the
    last :meth:`mark` (an output frame); :meth:`check` raises :class:`RatesNotFinite`
    at the :data:`NONFINITE_RATES`-th of them after :data:`WATCHED_AFTER` evaluations,
    naming the entries where they turned non-finite from a finite state."""

    def __init__(self, system):
        self.system = system
        self.mark(0)

    def mark(self, evals):
        """Start counting afresh after ``evals`` right-hand sides (the run's count so far)."""
        self.watched_from, self.count, self.origin = evals + WATCHED_AFTER, 0, None

    def check(self, t, y, rates):
        """Count the ``rates`` at (``t`` [s], ``y``) if non-finite (the caller checks
        ``watched_from`` first: the cheap test of every right-hand side)."""
        if math.isfinite(rates.sum()) or np.all(np.isfinite(rates)):
            return
        self.count += 1
        if self.origin is None and np.isfinite(y.sum()):  # where they turned so from a finite state
            self.origin = self._where(t, rates)
        if self.count >= NONFINITE_RATES:
            raise RatesNotFinite(self.origin or self._where(t, rates))

    def _where(self, t, rates):
        bad = np.flatnonzero(~np.isfinite(rates))
        # The first few and the last: of a system, the first rod's and the last body's.
        names = list(dict.fromkeys(self.system.entry_name(int(i)) for i in [*bad[:3], bad[-1]]))
        where = ", ".join(names[:-1]) + (" ... " if len(bad) > len(names) else ", ") + names[-1] \
            if len(names) > 1 else names[0]
        return (f"the rates of {len(bad)} entries ({where}) were non-finite at t = {t:.6g} s (from a finite "
                f"state; {NONFINITE_RATES} non-finite right-hand sides among the "
                f"{WATCHED_AFTER + NONFINITE_RATES} or more since the last output frame): no step can be "
                "taken (the model gives no finite motion there: a load, an input or a body's property "
                "out of range?)")
