"""Watching a time integration step by step, so a run that blows up, stalls or
overruns its budget ends at once with ``success=False`` and a message that
says where and why, instead of creeping on for hours.

Every accepted step (not only the output times) goes through
:meth:`Watch.state` and :meth:`Watch.pace`:

* the state is scanned by :func:`scan` (compiled, one pass, about a
  microsecond): non-finite entries, elements inverted or collapsed
  (axial stretch q1 <= :data:`MIN_STRETCH`), stretched beyond
  :data:`MAX_STRETCH`, or turning by more than :data:`MAX_TURN` rad over one
  element (the grid no longer resolves the curvature: the schemes and
  the chord formula break down near half a turn per element), and
  orientations whose quaternion norm left 1 (the solution blew up);
* every :data:`STALL_WINDOW` steps, the time covered by the window is
  compared with the run's span: a mean step below :data:`STALL_STEP` times
  the span means the run would need more than 1e7 steps (an hour or more at
  N = 100; the paper's tests take about 1e3): a stall;
* the wall-time budget ``max_wall_time`` (optional);
* ``progress(t, t_end)`` is called when :data:`PROGRESS_INTERVAL` seconds of
  wall time passed since the last report, so a stall is seen and can be
  stopped (Ctrl-C) between output times too;
* a stop asked by a signal (:func:`rodmol.solve.interrupts.stop_reason`,
  the command line's Ctrl-C and SIGTERM): the step is where the run stops
  safely.

The same scan checks the static equilibrium and a user's initial state
(:func:`state_problem`; a system's, each rod's part: :func:`assembly_state_problem`).
"""

import copy
import math
import time

import numba
import numpy as np

from ..discretise.layout import BLOCK, HEADER, QUAT, K, Q
from .interrupts import stop_reason

#: Axial stretch q1 at or below which an element counts as inverted or collapsed.
MIN_STRETCH = 0.05
#: Axial stretch q1 above which an element counts as torn apart (a linear
#: elastic law means nothing there).
MAX_STRETCH = 10.0
#: Largest rotation [rad] of the cross-section over one element, |k| ds.
MAX_TURN = 0.5 * math.pi
#: Largest departure of a quaternion's norm from 1 inside the integration
#: (which keeps it within about its tolerance; the stored states are projected
#: back to |Q| = 1, see ``StateLayout.project_quaternions``).
MAX_QUATERNION_DRIFT = 0.1
#: Steps per stall check, and the mean step [fraction of the run's span]
#: below which the window counts as a stall (1e8 steps or more to go).
STALL_WINDOW = 1000
STALL_STEP = 1e-7
#: Wall time [s] between progress reports on internal steps.
PROGRESS_INTERVAL = 0.5

#: Codes returned by :func:`scan`.
OK, NON_FINITE, INVERTED, STRETCHED, TURNED, QUATERNION = range(6)


@numba.njit(cache=True, nogil=True)
def scan(y, n, ds, min_stretch, max_stretch, max_turn, max_drift):
    """(code, element or entry index, value) of the first problem in state ``y``.

    Also returns the extremes for a diagnosis when all is well: the code is
    then OK and (index, value) are the element with the smallest q1 and q1.
    """
    for i in range(y.size):
        if not np.isfinite(y[i]):
            return NON_FINITE, i, y[i]
    worst, worst_q1 = 0, np.inf
    for b in range(n):
        o = HEADER + b * BLOCK
        q1 = y[o + Q]
        if q1 <= min_stretch:
            return INVERTED, b, q1
        if q1 > max_stretch:
            return STRETCHED, b, q1
        if q1 < worst_q1:
            worst, worst_q1 = b, q1
        turn = ds * math.sqrt(y[o + K] ** 2 + y[o + K + 1] ** 2 + y[o + K + 2] ** 2)
        if turn > max_turn:
            return TURNED, b, turn
        norm = math.sqrt(y[o + QUAT] ** 2 + y[o + QUAT + 1] ** 2 + y[o + QUAT + 2] ** 2
                         + y[o + QUAT + 3] ** 2)
        if abs(norm - 1.0) > max_drift:
            return QUATERNION, b, norm
    return OK, worst, worst_q1


def state_problem(layout, ds, t, y):
    """A sentence naming what is wrong with state ``y`` at time ``t`` [s], or None."""
    y = np.ascontiguousarray(y, dtype=float)
    code, i, value = scan(y, layout.n_elements, ds, MIN_STRETCH, MAX_STRETCH, MAX_TURN,
                          MAX_QUATERNION_DRIFT)
    return _describe(layout, ds, t, code, i, value)


def rod_state_problem(system, t, y):
    """:func:`state_problem` of a rod's system (a ``SemiDiscrete``)."""
    return state_problem(system.layout, system.model.ds, t, y)


def assembly_state_problem(assembly, t, y):
    """What is wrong with the state ``y`` at ``t`` [s] of a system of rods and bodies (an
    ``Assembly``: each rod's part as a single rod's state, the bodies' for finiteness), or None."""
    for name, sd in assembly.rods.items():
        problem = rod_state_problem(sd, t, y[assembly.parts[name]])
        if problem:
            return f"rod {name!r}: {problem}"
    if not np.all(np.isfinite(y)):
        return f"the state of a body became non-finite at t = {t:.6g} s: the solution blew up"
    return None


def _describe(layout, ds, t, code, i, value):
    at = f"at t = {t:.6g} s"
    if code == NON_FINITE:
        return (f"the state became non-finite {at} ({layout.entry_name(i)} = {value!r}): the "
                "solution blew up; the load may be beyond what the rod can carry")
    if code == INVERTED:
        what = "inverted" if value <= 0.0 else "collapsed"
        return (f"element {i} {what} {at} (axial stretch q1 = {value:.3g}): the grid is too coarse "
                "for this curvature, or the load is beyond what the rod can carry")
    if code == STRETCHED:
        return (f"element {i} stretched to {value:.3g} times its length {at}: the load is beyond "
                "what the rod can carry (check E and the loads)")
    if code == TURNED:
        return (f"element {i} turns by {value:.3g} rad over its length ds = {ds:.3g} m {at} "
                f"(more than {MAX_TURN:.3g} rad): the grid is too coarse for this curvature (use "
                "more elements), or the load is beyond what the rod can carry")
    if code == QUATERNION:
        return (f"the orientation of node {i + 1} lost its unit norm (|Q| = {value:.3g}) {at}: "
                "the solution blew up")
    return None


def watch_for(system, t_span, max_wall_time=None, progress=None):
    """The :class:`Watch` of a backend's ``system``: its own if it has one
    (``system.watch``, a system of rods and bodies), else a rod's."""
    own = getattr(system, "watch", None)
    if own is not None:
        return own(t_span, max_wall_time, progress)
    return Watch(system, t_span, max_wall_time, progress)


class Watch:
    """The per-step checks of one integration (see the module docstring).

    ``t_span`` is (t0, t_end) [s]; ``max_wall_time`` [s] or None;
    ``progress(t, t_end)`` or None. :meth:`step` returns None while all is
    well, else the cause of the stop (a sentence).
    """

    def __init__(self, system, t_span, max_wall_time=None, progress=None):
        self.layout, self.ds = system.layout, system.model.ds
        self.n = self.layout.n_elements
        # The tip section carries the pull of the cables anchored there: a pull
        # near its axial stiffness EA crushes it (the Result's tip strain
        # 1 - T / EA turns negative) though no element of the state does.
        model = system.model
        self.system = system
        self.tip_cables = np.flatnonzero(system.routing.weights[:, -1] == 1.0)  # anchored at the tip
        self.tip_stiffness = float(model.rod.stiffness(model.rod.length)[0][0])
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
        self._window_start, self._checked, self._worst = self.t0, 0, (0, 1.0)

    def state(self, t, h, y):
        """Check the state ``y`` at the end ``t`` [s] of an accepted step of size ``h`` [s]."""
        self.steps += 1
        self.t, self.h_last = t, h
        code, i, value = scan(y, self.n, self.ds, MIN_STRETCH, MAX_STRETCH, MAX_TURN,
                              MAX_QUATERNION_DRIFT)
        if code != OK:
            return _describe(self.layout, self.ds, t, code, i, value)
        self._worst = (i, value)
        if len(self.tip_cables):
            return self._tip(t, y)
        return None

    def _tip(self, t, y):
        pull = float(np.sum(self.system.tensions(t, y)[self.tip_cables]))
        q1 = 1.0 - pull / self.tip_stiffness
        if q1 > MIN_STRETCH:
            return None
        return (f"the tip section is crushed at t = {t:.6g} s: the cables anchored at the tip pull "
                f"with {pull:.3g} N against its axial stiffness EA = {self.tip_stiffness:.3g} N "
                f"(tip strain q1 = {q1:.3g}): the load is beyond what the rod can carry")

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
                return self._stall(covered, *self._worst, y)
        now = time.perf_counter()
        if self.max_wall_time is not None and now - self.start > self.max_wall_time:
            return (f"the wall-time budget max_wall_time = {self.max_wall_time:g} s is used up "
                    f"at t = {t:.6g} s")
        if self.progress is not None and now - self.reported >= PROGRESS_INTERVAL:
            self.reported = now
            self.progress(t, self.t_end)
        return None

    def _stall(self, covered, worst, q1, y):
        mean = covered / STALL_WINDOW
        to_go = (self.t_end - self.t) / mean if mean > 0 else math.inf
        k = self.layout.field(y, "k")
        turns = self.ds * np.linalg.norm(k, axis=1)
        b = int(np.argmax(turns))
        return (f"stalled at t = {self.t:.6g} s: the last {STALL_WINDOW} steps covered only "
                f"{covered:.3g} s (mean step {mean:.3g} s, about {to_go:.3g} more steps to go). "
                f"Most compressed element {worst} (q1 = {q1:.3g}), largest turn {turns[b]:.3g} rad "
                f"over element {b}: the load may be beyond what the rod can carry (collapse, "
                "buckling, whirling), or the grid too coarse for the motion" + self._stiff_hint())

    def _stiff_hint(self):
        if not getattr(self.system, "lightly_damped", False):
            return ""
        return ("; or the rod is stiff and lightly damped (no mode of the grid is damped): try "
                "max_order=2 with CVODE or backend='galpha' (docs/troubleshooting.md)")

