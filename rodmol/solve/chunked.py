"""Integration in chunks of output frames, handed to a frame sink as they are done.

The backend is restarted at every chunk boundary (frame indices that are
multiples of ``sink.chunk_frames``, counted from the first planned output),
so the boundaries are restart points: a run resumed from the last frame of a
chunk integrates exactly what the uninterrupted run did. Memory is bounded by
one chunk's states. Any sink with ``chunk_frames``, ``begin(system, t_out)``,
``frames(t, y)`` and ``end(success, message, stats)`` works (and ``flush()``,
if it has one, is called before ``end``: where a sink that writes behind the
run reports a failed write; ``account(stats)``, if it has one, gets the
solver's statistics of each chunk before its ``frames``; ``prepare(system)``
and ``record_settings(system, force, **run)``, if it has them, are called by
:func:`rodmol.simulate` before the run, the second recording the run's
settings and, resuming, refusing others unless ``force``). A sink that
resumes a run also has ``resume_point()`` -> (planned output times, restart
frame, its state) and ``check(system)``, which refuses another grid. rodmol
ships :class:`rodmol.output.stream.RunWriter` (a rod's) and
:class:`rodmol.output.system_stream.SystemRunWriter` (a System's).
"""

import time

import numpy as np

from .outputs import keep_before_failure, merge_stats


def run_chunked(run, system, y0, t_out, sink, first=0, *, progress=None, max_wall_time=None, **options):
    """Integrate from ``t_out[first]`` (state ``y0``) to ``t_out[-1]`` chunk by chunk.

    Returns (success, message, stats, error) of the whole run; the frames
    went to ``sink.frames`` (the first frame too, unless resuming).
    """
    size, t_end = int(sink.chunk_frames), float(t_out[-1])
    report = None if progress is None else (lambda t, _segment_end: progress(t, t_end))
    started, parts, k, y = time.perf_counter(), [], int(first), np.asarray(y0, dtype=float)
    sink.begin(system, t_out)
    try:
        return _chunks(run, system, y, t_out, sink, k, size, report, started, parts, max_wall_time,
                       options)
    except KeyboardInterrupt:  # landed while a chunk was being stored: the chunks before it are kept
        return False, "interrupted while storing the frames", merge_stats(parts), None


def _chunks(run, system, y, t_out, sink, k, size, report, started, parts, max_wall_time, options):
    while k < len(t_out) - 1:
        stop = min((k // size + 1) * size, len(t_out) - 1)
        budget = max_wall_time
        if max_wall_time is not None and parts:
            budget = max_wall_time - (time.perf_counter() - started)
            if budget <= 0:
                return False, (f"stopped after t = {t_out[k]:.6g} s: the wall-time budget "
                               f"max_wall_time = {max_wall_time:g} s is used up"), merge_stats(parts), None
        raw = keep_before_failure(run, system, y, t_out[k:stop + 1], progress=report,
                                  max_wall_time=budget, **options)
        parts.append(raw.stats)
        keep = 0 if k == 0 else 1  # a chunk's first frame is the previous chunk's last
        if len(raw.t) > keep:
            getattr(sink, "account", lambda stats: None)(raw.stats)
            failed = _store(parts, sink.frames, raw.t[keep:], raw.y[keep:])
            if failed:
                return failed
        if not raw.success:
            return False, raw.message, merge_stats(parts), raw.error
        k, y = stop, raw.y[-1]
    return _store(parts, getattr(sink, "flush", lambda: None)) or \
        (True, "The solver reached the end time.", merge_stats(parts), None)


def _store(parts, call, *args):
    """``call(*args)``, a sink's storing; on an ``OSError`` (a full disk: the chunks stored
    before stay valid) the run's outcome saying so, else None."""
    try:
        call(*args)
    except OSError as exc:
        return False, f"cannot store the frames: {exc}", merge_stats(parts), exc
    return None
