"""The forward run of an adjoint: CVODE's steps kept as checkpoints, the state between
them by cubic Hermite interpolation (:class:`Trajectory`).

:class:`ForwardRun` drives the one CVODE stepper (:class:`rodmol.solve.stepping.Stepper`,
as :func:`rodmol.solve.cvode.cvode` does: towards the next frame the loss reads, stopping at
the inputs' knots) and keeps each internal step's (t, y, f(t, y)). Kept whole, the memory
grows with the steps; with ``every = K`` only every K-th step is kept, and a segment between
two kept steps is integrated again (CVODE restarted at its first state, ending exactly at its
last) when the backward integration reaches it, so that memory is one segment's: the
recomputed steps differ from the first run's only within the tolerances.
"""

import numpy as np

from ..errors import IntegrationError
from .stepping import Stepper
from .watch import Watch


class Trajectory:
    """y(t) on [t[0], t[-1]] from states ``y`` (k, n) and rates ``f`` (k, n) at times ``t``
    (k,) increasing: cubic Hermite on each interval (the state and its rate at both ends)."""

    def __init__(self, t, y, f):
        self.t, self.y, self.f = np.asarray(t, dtype=float), np.asarray(y), np.asarray(f)

    def covers(self, t):
        return self.t[0] <= t <= self.t[-1]

    def __call__(self, t):
        i = int(np.clip(np.searchsorted(self.t, t, side="right") - 1, 0, len(self.t) - 2))
        t0, t1 = self.t[i], self.t[i + 1]
        h = t1 - t0
        s = (t - t0) / h
        h00, h10 = (1 + 2 * s) * (1 - s) ** 2, s * (1 - s) ** 2
        h01, h11 = s * s * (3 - 2 * s), s * s * (s - 1)
        return h00 * self.y[i] + h10 * h * self.f[i] + h01 * self.y[i + 1] + h11 * h * self.f[i + 1]


class ForwardRun:
    """CVODE over ``system`` from ``y0`` at ``t0`` [s] to ``t_end`` [s], keeping every
    ``every``-th step (None: every step); ``frames_at`` [s] are the times whose
    (projected) states the loss reads. ``options``: the CVODE backend's."""

    def __init__(self, system, t0, y0, t_end, frames_at, *, rtol, atol, every=None, max_wall_time=None,
                 progress=None, **options):
        self.system, self.t0, self.t_end = system, float(t0), float(t_end)
        self.every = every
        self._options = dict(rtol=rtol, atol=atol, **options)
        self._limits = (max_wall_time, progress)
        self.stepper = Stepper(system, t0, y0, **self._options)
        self.frames_at = np.asarray(frames_at, dtype=float)
        self.steps = 0
        kept, frames = self._run(self.t0, y0, self.t_end, self.frames_at, keep_every=every or 1)
        self.kept_t, self.kept_y, self.kept_f = kept
        self.frames = frames
        self._segment = None if every else Trajectory(*kept)

    def _run(self, t_start, y_start, t_stop, frames_at, keep_every):
        """Steps from (t_start, y_start) to t_stop: ((t, y, f) of the kept steps, frames at ``frames_at``)."""
        stepper, system = self.stepper, self.system
        if t_start != stepper.t or stepper.reached != t_start:
            stepper.restart(t_start, y_start)
        watch = Watch(system, (t_start, t_stop), *self._limits)
        ts, ys, fs = [t_start], [np.array(y_start, dtype=float)], [system(t_start, np.array(y_start, dtype=float))]
        frames, i, count = np.empty((len(frames_at), system.size)), 0, 0
        while i < len(frames_at) and frames_at[i] <= t_start:
            frames[i] = y_start
            i += 1
        reached = t_start
        while reached < t_stop:
            target = frames_at[i] if i < len(frames_at) else t_stop
            stop = stepper.stop_time(t_stop)
            r, problem = stepper.step(float(target), stop, watch)
            if problem:
                raise IntegrationError(f"the forward run of the gradient failed: {problem}")
            if r.t <= reached:  # CVODE handing the same step back after an interpolation
                continue
            while i < len(frames_at) and frames_at[i] <= r.t:
                frames[i] = r.y if frames_at[i] == r.t else stepper.interpolate(frames_at[i])
                i += 1
            reached = r.t
            count += 1
            if count % keep_every == 0 or reached >= t_stop:
                y = np.array(r.y, dtype=float)
                ts.append(reached)
                ys.append(y)
                fs.append(system(reached, y))
        self.steps += count
        system.project_quaternions(frames)
        return (np.array(ts), np.array(ys), np.array(fs)), frames

    def state(self, t):
        """y(t) [the state] at ``t`` [s]: the kept steps' interpolant, a segment integrated
        again in the bounded mode."""
        if self._segment is None or not self._segment.covers(t):
            k = int(np.clip(np.searchsorted(self.kept_t, t, side="right") - 1, 0, len(self.kept_t) - 2))
            start, stop = self.kept_t[k], self.kept_t[k + 1]
            (ts, ys, fs), _ = self._run(start, self.kept_y[k], stop, np.empty(0), keep_every=1)
            ys[-1], fs[-1] = self.kept_y[k + 1], self.kept_f[k + 1]  # the first run's: segments join
            self._segment = Trajectory(ts, ys, fs)
        return self._segment(t)

    def boundaries(self):
        """The times [s] where the backward integration must not step across: the kept
        steps in the bounded mode (a segment is integrated again at a time), else none."""
        return self.kept_t[1:-1] if self.every else np.empty(0)
