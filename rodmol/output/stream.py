"""Streamed output of a run: the frame sink of :func:`rodmol.simulate`.

:class:`RunWriter` receives the states at the output times in chunks while
the run goes (``simulate(..., out=DIR)``; the sink protocol is
:mod:`rodmol.solve.chunked`'s), derives the Result's arrays for each chunk,
and writes

* the chunk's HDF5 file and the index ``result.h5`` (:mod:`rodmol.output.h5result`),
* the ParaView views ``rod.xdmf``, ``cables.xdmf``, ``markers.xdmf``
  (:mod:`rodmol.output.xdmf`): every ``every``-th frame and the last of each
  chunk, in single precision; by default at most
  :data:`rodmol.output.parts.MAX_SHOWN` frames.

A background thread writes each chunk while the run goes on with the next,
so memory stays bounded by two chunks. Every file appears complete under its
real name or not at all, so a run killed at any moment leaves a directory
that ParaView and :func:`rodmol.load_result` read up to the last complete
chunk, and whose last frame is the restart point of ``resume=True``.
"""

import functools
import time
from concurrent.futures import Future, ThreadPoolExecutor
from contextlib import contextmanager
from functools import partial

import numpy as np

from .. import _settings, run_sinks
from .._files import output_directory
from ..errors import ParameterError
from ..result import STATIC
from . import h5result, run_files, xdmf
from .h5result import INDEX, VIEW
from .parts import cable_point_array, view_step
from .run_record import RunRecord, damaged

#: Output frames per chunk by default: bounded memory (about 45 kB a frame at
#: N = 100 with the views), fewer than 100 files for 600 s at 100 frames/s.
CHUNK_FRAMES = 2000


class RunWriter:
    """Streams frames into ``directory`` (created if needed).

    Parameters
    ----------
    directory : path
    views : bool
        Write the XDMF views for ParaView (False: only ``result.h5`` and the chunks).
    every : int, optional
        The views show every ``every``-th output frame (and the last of each
        chunk); the result file keeps all. Default: all of them up to
        :data:`rodmol.output.parts.MAX_SHOWN` frames (:func:`rodmol.output.parts.view_step`).
    chunk_frames : int
        Output frames per chunk file. With ``simulate(..., out=...)`` the
        solver also restarts at every chunk boundary (the restart points),
        so a resumed run repeats the uninterrupted one exactly.
    resume : bool
        Continue the unfinished run in ``directory`` (see :meth:`resume_point`),
        with its own ``chunk_frames`` and ``every``.
    overwrite : bool
        Without ``resume``: replace an earlier run in ``directory`` (all of its
        files, :mod:`rodmol.output.run_files`); False refuses with a ParameterError
        if there is one (the default; ``simulate(..., out=DIR)`` passes its ``overwrite``).
    meta : dict, optional
        Added to the Result's ``meta`` (e.g. the scenario's name).
    """

    def __init__(self, directory, *, views=True, every=None, chunk_frames=CHUNK_FRAMES, resume=False,
                 overwrite=False, meta=None):
        if (every is not None and int(every) < 1) or int(chunk_frames) < 1:
            raise ParameterError(f"`every` and `chunk_frames` must be >= 1, got {every!r}, {chunk_frames!r}")
        self.directory = output_directory(directory, "out")
        self.views, self.chunk_frames = bool(views), int(chunk_frames)
        self.every = None if every is None else int(every)
        self.extra_meta = dict(meta or {})
        self.chunks, self.t, self.t_out, self.seconds = {}, [], None, 0.0
        self.static, self.meta, self.system = None, None, None
        self._pool, self._pending = None, None  # the writer's thread, and the chunk it writes
        self._depth = 0  # of nested _timed blocks
        self._fixed_views = None  # the views' static arrays, made once
        self.record, self.restart, self._dropped = RunRecord(), None, []
        if resume:
            self._reopen()
            for file in run_files.temporaries(self.directory):
                file.unlink(missing_ok=True)
        else:
            run_files.claim(self.directory, overwrite, "resume=True")

    # ----------------------------------------------------------------- the sink protocol

    def prepare(self, system):
        """Load what writing needs, once per process, before the run (``simulate`` books it
        with the compiled kernels' preparation): loaded by the first chunk in the writer's
        thread, it would hold the GIL against the run."""
        _load_once()

    def begin(self, system, t_out):
        """Start (or, resuming, continue) a run of ``system`` with output times ``t_out``
        (None: a run without a planned end, as a stepping simulator's; the views then show
        every ``every``-th frame, default all)."""
        from ..result import run_meta, static_arrays

        self.system = system
        if self.t_out is None and t_out is not None:
            self.t_out = np.asarray(t_out, dtype=float)
        if self.static is None:
            self.static, self.meta = static_arrays(system), dict(run_meta(system), **self.extra_meta)
        self.every = view_step(0 if self.t_out is None else len(self.t_out), self.every)
        first = self.t[-1] if self.t else None if self.t_out is None else self.t_out[0]
        self.record.t_start = None if first is None else float(first)
        if self._dropped:  # list the chunks kept before a chunk of the same name replaces a dropped one
            self._write(None, None, None, list(self.chunks), self._index(dict(success=True, message="running",
                                                                             complete=False)))
            self._dropped = []

    def frames(self, t, y):
        """Store the states ``y`` (n, size) at output times ``t`` (n,) as one chunk."""
        from ..result import from_states

        with self._timed():
            self.store(from_states(self.system, np.asarray(t, dtype=float), np.asarray(y), True, "", {}))

    def account(self, stats):
        """The solver's statistics of the frames stored next (:func:`rodmol.solve.chunked.run_chunked`
        calls it before :meth:`frames`): the index records the work of each chunk kept."""
        self.record.account(stats)

    def record_settings(self, system, force=False, **run):
        """Record the settings of this run of ``system`` in the index (:func:`rodmol._settings.record`;
        ``run``: its backend, rtol, atol, backend options and initial state); resuming, refuse other
        settings than the run's, naming each, unless ``force`` (then recorded as what it changed)."""
        settings, recorded = _settings.record(system, **run), self.record.settings
        settings, forced = _settings.settle(recorded, settings, force, repr(str(self.directory)))
        self.record.settings, self.record.forced = settings, forced

    @property
    def settings(self):
        """The settings of the run in the directory (None: not recorded, an older rodmol's)."""
        return self.record.settings

    def flush(self):
        """Wait until the chunks stored so far are on disk; raises the ``OSError`` of one that
        could not be written."""
        self._settle(True)

    def _settle(self, report):
        """Wait for the chunk being written; if it failed, unlist it (it is not on disk) and,
        if ``report``, raise why."""
        pending, self._pending = self._pending, None
        if pending is None:
            return
        job, name = pending
        with self._timed():
            try:
                job.result()
            except BaseException:
                self._unlist(name)
                if report:
                    raise

    def _unlist(self, name):
        """Forget the chunk ``name`` (the last listed), which is not on disk."""
        del self.t[len(self.t) - self.chunks.pop(name):]
        self.record.drop([name])

    def end(self, success, message, stats):
        """Finish: the final index; returns the Result (read lazily)."""
        with self._timed():
            try:
                self.flush()
            finally:
                if self._pool is not None:
                    self._pool.shutdown()
                    self._pool = None
            h5result.write_index(*self._index(dict(success=bool(success), message=str(message),
                                                    complete=True), dict(stats)))
        return self.result()

    # ----------------------------------------------------------------- other uses

    def store(self, chunk):
        """Write the :class:`rodmol.Result` ``chunk`` (the next frames of the run) as one chunk."""
        from ..result import LOADS, STORED

        if self.static is None:
            self.static = {key: getattr(chunk, key) for key in STATIC}
            self.meta = dict(chunk.meta, **self.extra_meta)
        n, start = len(chunk.t), len(self.t)
        frames = self._shown(start, n)
        shown = chunk if len(frames) == n else chunk.select(frames)
        name = h5result.chunk_name(len(self.chunks))
        self.chunks[name] = n
        self.record.stored(name)
        self.t.extend(np.asarray(chunk.t, dtype=float).tolist())
        handed = []
        try:  # from here on, an interrupt (or a failed write before) drops the chunk: it is listed above
            # The chunk that ends the planned run leaves the index to end() (a kill before it: resumed there).
            final = self.t_out is not None and len(self.t) == len(self.t_out)
            index = None if final else self._index(dict(success=True, message="running", complete=False))
            # The thread writes each batch of arrays while this one computes the next, then the views' text.
            posed, moving = self._view_batches(shown) if self.views else ([], [])
            batches = [*posed, lambda: {key: getattr(chunk, key) for key in LOADS}, *moving]
            fragment = [partial(self._fragment, shown.t, name)] if self.views else []
            handed = [Future() for _ in batches + fragment]
            made = [future.result for future in handed]
            at_hand = {key: getattr(chunk, key) for key in STORED if key not in LOADS}
            self._write_behind(name, partial(self._write, name, [at_hand, *made[:len(batches)]],
                                             made[-1] if fragment else None, list(self.chunks), index))
            for future, make in zip(handed, batches + fragment):
                future.set_result(make())
        except BaseException as exc:
            for future in handed:
                if not future.done():
                    future.set_exception(exc)
            if self._pending is not None and self._pending[1] == name:
                self._settle(False)  # handed to the writer's thread: it stops at the missing batch
            else:
                self._unlist(name)
            raise

    @contextmanager
    def _timed(self):
        """Add the time inside to ``seconds`` (the writer's share of the run's wall time),
        once when nested."""
        self._depth += 1
        started = time.perf_counter()
        try:
            yield
        finally:
            self._depth -= 1
            if self._depth == 0:
                self.seconds += time.perf_counter() - started

    def _write_behind(self, name, job):
        """Run ``job`` (the writing of a chunk) in the writer's thread while the run goes on;
        first wait for the chunk before (so at most two chunks are in memory, and they land
        in order)."""
        self.flush()
        if self._pool is None:
            self._pool = ThreadPoolExecutor(1, thread_name_prefix="rodmol-writer")
        self._pending = (self._pool.submit(job), name)

    def _write(self, name, batches, fragment, chunks, index):
        """Write a chunk file (see :func:`h5result.write_chunk`), its views (``fragment``: a
        function returning their XDMF text, or None without views) and the index that lists
        it (``index``: the arguments of :func:`h5result.write_index`, or None), in the writer's
        thread (h5py lets the solver run meanwhile)."""
        if name is not None:
            h5result.write_chunk(self.directory, name, batches)
        if fragment is not None or (name is None and self.views):
            if fragment is not None:
                xdmf.write_fragment(self.directory / (name[:-3] + ".xmf"), fragment())
            fragments = [c[:-3] + ".xmf" for c in chunks]
            for view in self.view_names():
                xdmf.write_view(self.directory / f"{view}.xdmf", view, fragments)
        if index is not None:
            h5result.write_index(*index)

    def write_result(self, result):
        """Write a finished in-memory :class:`rodmol.Result`, chunk by chunk; returns the path of ``rod.xdmf``."""
        self.t_out = np.asarray(result.t, dtype=float)
        self.every = view_step(len(self.t_out), self.every)
        self.record.t_start = float(result.t[0]) if len(result.t) else 0.0
        with self._timed():
            for k0 in range(0, len(result.t), self.chunk_frames):
                self.store(result.select(slice(k0, k0 + self.chunk_frames)))
        self.end(result.success, result.message, result.stats)
        return self.directory / "rod.xdmf"

    def result(self):
        return h5result.read_result(self.directory / INDEX)

    def resume_point(self):
        """(planned output times, restart frame, its state) of the run resumed (:meth:`_reopen`)."""
        run_files.refuse_resuming_nothing(self.directory, self.restart)
        return self.t_out, self.restart[0], self.restart[2]

    def check(self, system):
        """Resuming: refuse ``system`` (a ``SemiDiscrete``) on another grid than the run's, before
        anything is sized by it (:func:`rodmol._settings.check_grid`)."""
        _settings.check_grid(self.settings or {}, system, repr(str(self.directory)))

    # ----------------------------------------------------------------- internals

    def _reopen(self):
        """Read the run to resume; its restart point is the last frame of its last complete chunk
        (the frame the uninterrupted run restarted from): the frames after it, a chunk that
        Ctrl-C or a failure cut short, are dropped and redone."""
        path = self.directory / INDEX
        if not path.is_file():
            raise ParameterError(f"nothing to resume in {str(self.directory)!r}: no {INDEX}")
        with damaged(path):
            index = h5result.read_index(path)
            info = index["info"]
            finished = info.get("complete", True) and info.get("success")
            self.chunks, self.t, self.t_out = dict(index["chunks"]), index["t"].tolist(), index["t_out"]
            self.static = {key: index[key] for key in STATIC}
            # The restart points of the run being resumed, whatever this writer was given.
            self.chunk_frames = int(info.get("chunk_frames", self.chunk_frames))
            self.every = info.get("every") or self.every
            self.meta = dict(info.get("meta") or {}, **self.extra_meta)
            self.record = RunRecord(info)
        if finished:
            raise ParameterError(f"nothing to resume in {str(self.directory)!r}: the run there finished "
                                 f"({info['message']})")
        if not self.chunks:
            raise ParameterError(f"nothing to resume in {str(self.directory)!r}: no frames were kept")
        self._roll_back()

    def roll_back(self, point):
        """Resuming: restart from the earlier restart point ``point`` (a frame index, a multiple
        of ``chunk_frames``, at or before :meth:`resume_point`'s), dropping the chunks after it
        (a system's run restarts all its rods from the frame its own index reached)."""
        if point == self.restart[0]:  # there already: reopening rolled back to it (a first chunk cut short)
            return
        if point % self.chunk_frames or point > self.restart[0]:
            raise ParameterError(f"cannot restart {str(self.directory)!r} at frame {point}: its restart "
                                 f"points are multiples of {self.chunk_frames} up to {self.restart[0]}")
        self._roll_back(point)

    def _roll_back(self, point=None):
        """Keep the chunks up to the restart point ``point`` (a frame index that is a multiple of
        ``chunk_frames``; None: the last one); ``restart``: (its index, time, state)."""
        last = len(self.t) - 1
        point = last - last % self.chunk_frames if point is None else point
        kept = run_files.chunks_kept(self.chunks, point)
        # The first chunk cut short: its first frame, the run's initial state, is the restart point.
        chunk, row = (list(kept)[-1], -1) if kept else (list(self.chunks)[0], 0)
        with damaged(self.directory / chunk):
            t, state = h5result.frame_state(self.directory, chunk, row)
        dropped = [name for name in self.chunks if name not in kept]
        self._dropped += dropped
        self.record.drop(dropped)
        self.chunks, self.t = kept, self.t[:sum(kept.values())]
        self.restart = (point, t, state)

    def view_names(self):
        """The views this run has: the rod, and the cables and markers if any."""
        names = ["rod"]
        if self.meta.get("cables"):
            names.append("cables")
        if self.meta.get("markers"):
            names.append("markers")
        return names

    def _shown(self, start, n):
        """Chunk frames shown in the views: global index a multiple of ``every``, and the chunk's
        last (so the run's last frame is always shown, and a chunk's views never change)."""
        return [k for k in range(n) if (start + k) % self.every == 0 or k == n - 1]

    def _fragment(self, t, name):
        """The XDMF text of the chunk ``name``'s views (relative to them: they sit in the run
        directory), showing times ``t``."""
        return xdmf.rod_fragment(name, t, self._static_views())

    def _static_views(self):
        """The views' arrays that do not change in time (made once: every chunk file holds them)."""
        if self._fixed_views is None:
            self._fixed_views = xdmf.static_views(self.static, self.meta)
        return self._fixed_views

    def _view_batches(self, shown):
        """The views' arrays of the Result ``shown`` (:func:`xdmf.view_batches`)."""
        return xdmf.view_batches(self._static_views(), self.static["s"], self.meta, shown)

    def _index(self, info, stats=None):
        """The arguments of :func:`h5result.write_index` now (copies: the run goes on); ``stats``:
        the session's statistics once it ended (:class:`RunRecord`)."""
        t = np.array(self.t)
        reached = float(t[-1]) if len(t) else self.record.t_start
        info.update(self.record.info(list(self.chunks), reached, stats))
        info.update(meta=self.meta or {}, chunk_frames=self.chunk_frames, every=self.every)
        return self.directory, self.static, self.t_out if self.t_out is not None else t, t, dict(self.chunks), info


@functools.cache
def _load_once():
    import h5py  # noqa: F401  (imported, not used here)

    # The views' compiled kernel for their number type: a cable over a two-node rod.
    cable_point_array(np.array([0.0, 1.0]), np.zeros((1, 2, 3)), np.tile(np.eye(3), (1, 2, 1, 1)),
                      {"cables": [{"anchor": 1.0, "offset": [0.0, 0.0]}]}, VIEW)


def write_xdmf(result, directory, every=None, overwrite=False):
    """The ``"xdmf"`` format of :func:`rodmol.write_series`: ``result.h5`` and the XDMF
    views of a finished Result; an earlier run there is kept unless ``overwrite``
    (:func:`rodmol.output.run_files.claim`); returns the path of ``rod.xdmf``."""
    run_files.claim(output_directory(directory, "directory"), overwrite)
    return RunWriter(directory, every=every, overwrite=True).write_result(result)


run_sinks.register_directory(RunWriter)  # simulate(out=DIR) streams into a RunWriter
