"""What every backend returns: the states at the output times reached, with
progress reports and step statistics, so a failed or interrupted run keeps
what it computed."""

import time
from dataclasses import dataclass, field

import numpy as np

from ..errors import RodmolError, UserFunctionError


@dataclass
class RawSolution:
    t: np.ndarray
    y: np.ndarray
    success: bool
    message: str
    stats: dict = field(default_factory=dict)
    #: The exception that ended the run (a user callback's, with its traceback), or None.
    error: BaseException = None
    #: (backend, why it stopped or "", time reached [s], steps, last step [s]).
    ending: tuple = None


class Outputs:
    """Collects states at the output times (in one preallocated array) and reports progress.

    The states handed back after the first (the start, as given) have unit
    quaternions (``system.project_quaternions``, once over the frames, when
    the solution is made); the integration itself is not touched.
    ``backend`` names the backend in messages; ``watch`` (a
    :class:`rodmol.solve.watch.Watch`) says how far it got.
    """

    def __init__(self, t_out, y0, progress, system, backend, watch):
        self.t_out, self.progress, self.system = t_out, progress, system
        self.backend, self.watch = backend, watch
        self.start = time.perf_counter()
        self.ys = np.empty((len(t_out), len(y0)))
        self.ys[0] = y0
        self.next_index = 1

    def report_start(self):
        """The start, so a display measures from here."""
        if self.progress is not None:
            self.progress(self.t_out[0], self.t_out[-1])

    @property
    def done(self):
        return self.next_index == len(self.t_out)

    def add(self, y):
        k = self.next_index
        self.ys[k] = y
        self.next_index = k + 1
        if self.progress is not None:
            self.progress(self.t_out[k], self.t_out[-1])

    def stopped(self, reason, error=None, **stats):
        """The frames so far, for a run that ended early: the message says the
        last frame's time, how far the backend got and why (:func:`stop_message`)."""
        message = stop_message(self.t_out[self.next_index - 1], *self._ending(reason))
        return self.solution(False, message, error=error, reason=reason, **stats)

    def _ending(self, reason):
        return self.backend, reason, self.watch.t, self.watch.steps, self.watch.h_last

    def solution(self, success, message, error=None, reason="", **stats):
        stats["wall_time_s"] = time.perf_counter() - self.start
        n = self.next_index
        self.system.project_quaternions(self.ys[1:n])
        return RawSolution(self.t_out[:n].copy(), self.ys[:n], success, message, stats, error,
                           self._ending(reason))


def stop_message(frame, backend, reason, reached, steps, last_step):
    """The message of a run that stopped: the last output frame's time [s], how far
    ``backend`` got (time reached [s], steps, last step [s]) and why."""
    return (f"{backend} stopped after t = {frame:.6g} s (last output frame; the solver reached "
            f"t = {reached:.6g} s in {steps} steps, last step {last_step:.3g} s): {reason}")


def run_steps(steps, stop, out, stats, now=None):
    """A backend's step loop with the endings every backend shares.

    ``steps()`` returns a RawSolution to end early (``stop(reason)``), or
    None once every output is done. Ctrl-C and exceptions (a user callback's
    too) stop the run with the frames so far; ``now()`` [s] says when, for
    exceptions that do not say it themselves.
    """
    try:
        out.report_start()
        ended = steps()
    except KeyboardInterrupt:
        return stop("interrupted")
    except Exception as exc:  # noqa: BLE001 (the frames so far are kept, the exception too)
        return stop(cause(exc, None if now is None else now()), exc)
    return ended if ended is not None else out.solution(True, "The solver reached the end time.", **stats())


def step_size_stats(sizes):
    """Smallest, median and largest step [s] (0 if none), for the run's stats."""
    if not sizes:
        return dict(h_min=0.0, h_median=0.0, h_max=0.0)
    h = np.asarray(sizes)
    return dict(h_min=float(h.min()), h_median=float(np.median(h)), h_max=float(h.max()))




def cause(exc, t=None):
    """An exception as the cause in a run's message (rodmol's own errors say where already)."""
    if isinstance(exc, RodmolError):
        return str(exc)
    return f"{type(exc).__name__}: {exc}" + (f" (at t = {t:.6g} s)" if t is not None else "")


#: Statistics that add up over parts of a run (the others: smallest, largest, median of medians, last).
_SUMMED = ("steps", "rhs_evals", "jac_evals", "prec_setups", "prec_solves", "wall_time_s")


def merge_stats(parts):
    """One run's statistics from those of its parts (chunks, or integrations again)."""
    parts = [p for p in parts if p]
    merged = dict(parts[-1]) if parts else {}
    for key in _SUMMED:
        if any(key in p for p in parts):
            merged[key] = sum(p.get(key, 0) for p in parts)
    for key, pick in (("h_min", min), ("h_max", max), ("h_median", np.median)):
        values = [p[key] for p in parts if key in p and p.get("steps", 1)]
        if values:
            merged[key] = float(pick(values))
    return merged


def keep_before_failure(run, system, y0, t_out, *, progress=None, **options):
    """``run(system, y0, t_out, ...)`` (a backend) keeping every frame before a user's function fails.

    A solver's trial step reaches past the next outputs, so a function that
    fails at t (:class:`UserFunctionError` with its ``t``) stops it with
    output times before t not done yet; those are integrated again from the
    last frame, ending at the last output before t, and so on while a
    function fails earlier. A failing function is not a numerical failure:
    no step is retried in the hope that a shorter one passes.
    """
    t_out = np.asarray(t_out, dtype=float)
    t_end = float(t_out[-1])
    report = None if progress is None else (lambda t, _segment_end: progress(t, t_end))
    parts = [run(system, y0, t_out, progress=report, **options)]
    failure = parts[0]  # the stop that ends the run
    while _user_failure(failure):
        last = parts[-1]
        missing = t_out[(t_out > last.t[-1]) & (t_out < failure.error.t)]
        if not len(missing):
            break
        parts.append(run(system, last.y[-1], np.concatenate([last.t[-1:], missing]), progress=report,
                         **options))
        if not parts[-1].success:  # a function failed earlier still, or another stop
            failure = parts[-1]
    raw = parts[0] if len(parts) == 1 else _joined(parts, failure)
    return _inputs_hold(system, raw)


def _inputs_hold(system, raw):
    """``raw`` without its last frames if the inputs fail at their times, ending there.

    A step that ends on an output time may do so within round-off of it, so
    a function failing from exactly that time on was never called there;
    the Result, which evaluates the inputs at every frame, would then fail.
    """
    if not system.inputs_vary:  # read once, before the run
        return raw
    k, error = len(raw.t), None
    while k > 1:
        try:
            system.update_inputs(raw.t[k - 1], raw.y[k - 1])
        except UserFunctionError as exc:
            k, error = k - 1, exc
            continue
        break
    if error is None:
        return raw
    backend, _, reached, steps, last_step = raw.ending
    ending = (backend, str(error), reached, steps, last_step)
    return RawSolution(raw.t[:k], raw.y[:k], False, stop_message(raw.t[k - 1], *ending), raw.stats, error,
                       ending)


def _user_failure(raw):
    """True if ``raw`` stopped because a function of the user's failed at a known time."""
    error = raw.error
    return not raw.success and raw.ending is not None and isinstance(error, UserFunctionError) \
        and error.t is not None


def _joined(parts, failed):
    """One RawSolution of a run integrated in ``parts`` that ended with ``failed``'s stop."""
    t = np.concatenate([parts[0].t] + [p.t[1:] for p in parts[1:]])
    y = np.concatenate([parts[0].y] + [p.y[1:] for p in parts[1:]])
    stats = merge_stats([p.stats for p in parts])
    backend, reason = failed.ending[:2]
    furthest = max(parts, key=lambda p: p.ending[2]).ending
    ending = (backend, reason, furthest[2], stats.get("steps", 0), furthest[4])
    return RawSolution(t, y, False, stop_message(t[-1], *ending), stats, failed.error, ending)
