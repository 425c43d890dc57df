"""What every backend returns: the states at the output times reached, with
progress reports and step statistics, so a failed or interrupted run keeps
what it computed."""

import time
from dataclasses import dataclass, field

import numpy as np

from ..errors import RodmolError


@dataclass
class RawSolution:
    t: np.ndarray
    y: np.ndarray
    success: bool
    message: str
    stats: dict = field(default_factory=dict)
    #: The exception that ended the run (a user callback's, with its traceback), or None.
    error: BaseException = None


class Outputs:
    """Collects states at the output times (in one preallocated array) and reports progress.

    The states handed back have unit quaternions (``layout.project_quaternions``,
    once over all frames, when the solution is made); the integration itself
    is not touched.
    """

    def __init__(self, t_out, y0, progress, layout):
        self.t_out, self.progress, self.layout = t_out, progress, layout
        self.start = time.perf_counter()
        self.ys = np.empty((len(t_out), len(y0)))
        self.ys[0] = y0
        self.next_index = 1
        if progress is not None:  # the start, so a display measures from here
            progress(t_out[0], t_out[-1])

    @property
    def done(self):
        return self.next_index == len(self.t_out)

    def add(self, y):
        k = self.next_index
        self.ys[k] = y
        self.next_index = k + 1
        if self.progress is not None:
            self.progress(self.t_out[k], self.t_out[-1])

    def stopped(self, backend, watch, reason, error=None, **stats):
        """The frames so far, for a run that ended early: the message says the
        last frame's time, how far ``backend`` got (``watch.summary()``) and why."""
        reached = self.t_out[self.next_index - 1]
        return self.solution(False, f"{backend} stopped after t = {reached:.6g} s (last output frame; "
                             f"{watch.summary()}): {reason}", error=error, **stats)

    def solution(self, success, message, error=None, **stats):
        stats["wall_time_s"] = time.perf_counter() - self.start
        n = self.next_index
        self.layout.project_quaternions(self.ys[:n])
        return RawSolution(self.t_out[:n].copy(), self.ys[:n], success, message, stats, error)


def run_steps(steps, stop, out, stats, now=None):
    """A backend's step loop with the endings every backend shares.

    ``steps()`` returns a RawSolution to end early (``stop(reason)``), or
    None once every output is done. Ctrl-C and exceptions (a user callback's
    too) stop the run with the frames so far; ``now()`` [s] says when, for
    exceptions that do not say it themselves.
    """
    try:
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
