"""Streamed output of a system's run: the frame sink of ``simulate(system, ..., out=DIR)``.

:class:`SystemRunWriter` receives the assembled states in chunks from
:func:`rodmol.solve.chunked.run_chunked` (the sink protocol of a single
rod's run) and, for each chunk,

* hands each rod's frames to that rod's :class:`rodmol.output.stream.RunWriter`
  (``DIR/NAME/``, a single rod's run directory, streamed as one), waits until
  they are on disk,
* then writes the chunk's own file (``frames/chunk_NNNNNN.h5``: the assembled
  states and the bodies' frames), its bodies' grids and ``bodies.xdmf``, and
  last replaces the small index ``system.h5`` listing it
  (:mod:`rodmol.output.system_files`).

Each file appears complete under its real name or not at all, and
``system.h5`` is written last, so it never lists a frame a rod's files or
its chunk files lack: it is what a resumed run (``resume=True``) restarts
from, at its last restart point (a frame index that is a multiple of
``chunk_frames``), rolling every rod's directory back to that frame. A run
killed at any moment leaves a directory that :func:`rodmol.load_result`
reads up to the last chunk its ``system.h5`` lists (a rod's own files may
hold one chunk more). Writing a chunk costs the same at any length of the
run, and the writer keeps no frames of the chunks before (only their times).
"""

import numpy as np

from .. import _settings, run_sinks
from .._files import kept, output_directory
from ..errors import ParameterError
from ..system_result import SystemResult
from . import h5result, run_files, stream
from .parts import view_step
from .run_record import damaged
from .stream import CHUNK_FRAMES, RunWriter
from .system_files import (
    INDEX,
    _keys,
    _plain,
    chunk_batch,
    read_info,
    read_series,
    read_system,
    surface_of,
    write_bodies_view,
    write_index,
    write_views,
)


class SystemRunWriter:
    """Streams a system's frames into ``directory`` (created if needed).

    Parameters
    ----------
    directory : path
    chunk_frames : int
        Output frames per chunk; the solver restarts at every chunk boundary
        (the restart points of ``resume``).
    every : int, optional
        The views show every ``every``-th output frame (and the last of each
        chunk); default as for a single rod (:func:`rodmol.output.parts.view_step`).
    resume : bool
        Continue the unfinished run in ``directory`` from its last restart
        point (:attr:`restart`), with its own ``chunk_frames`` and ``every``.
    overwrite : bool
        Without ``resume``: replace an earlier run in ``directory``; False
        refuses with a ParameterError if there is one.
    """

    def __init__(self, directory, *, chunk_frames=CHUNK_FRAMES, every=None, resume=False, overwrite=False):
        if int(chunk_frames) < 1 or (every is not None and int(every) < 1):
            raise ParameterError(f"`every` and `chunk_frames` must be >= 1, got {every!r}, {chunk_frames!r}")
        self.directory = output_directory(directory, "out")
        self.chunk_frames, self.every = int(chunk_frames), None if every is None else int(every)
        self.assembly, self.rods, self.t_out, self.settings, self.forced = None, {}, None, None, []
        self.t, self.chunks = [], {}  # the times listed in system.h5, and its chunk files (name -> frames)
        self.restart, self._resumed, self._layout = None, None, None
        self._parts = None  # (rod keys, body keys, body surfaces, the parts' slices) of the run
        self._cleared = bool(resume)  # an earlier run replaced (`overwrite`) when the run begins,
        if resume:                     # after the caller's checks and initial state (they may fail)
            self._reopen()
        else:
            self._refuse_replacing(overwrite)

    # ----------------------------------------------------------------- the sink protocol

    def begin(self, system, t_out):
        """Start (or continue) the run of the assembly ``system`` (``system.assembly`` if it
        carries one) through the output times ``t_out``."""
        self._clear()
        assembly = getattr(system, "assembly", system)
        self.assembly = assembly
        if self.t_out is None and t_out is not None:  # None: no planned end (a stepping simulator's run)
            self.t_out = np.asarray(t_out, dtype=float)
        keys = _keys(assembly.rods, "rod")
        if self._resumed is not None:
            self.check(assembly)
        self._plan(SystemResult(assembly, np.empty(0), np.empty((0, assembly.size)), True, "", {}),
                   0 if self.t_out is None else len(self.t_out))
        if self._resumed is not None:
            # First list only the chunks kept: the rods roll back to them next, and a new chunk may
            # replace a dropped one of the same name.
            write_bodies_view(self.directory, self._parts[1], list(self.chunks))
            self._write_index(True, "running", {}, complete=False)
            for name, key in keys.items():
                writer = RunWriter(self.directory / key, resume=True)
                writer.roll_back(self.restart[0])
                self.rods[name] = writer
        else:
            self.rods = {name: RunWriter(self.directory / key, chunk_frames=self.chunk_frames, every=self.every,
                                         overwrite=True) for name, key in keys.items()}
        for name, writer in self.rods.items():
            writer.prepare(assembly.rods[name])
            writer.begin(assembly.rods[name], self.t_out)

    def frames(self, t, y):
        """Store the assembled states ``y`` (n, size) at output times ``t`` (n,) as one chunk."""
        chunk = SystemResult(self.assembly, np.asarray(t, dtype=float), np.asarray(y), True, "", {})
        for name, writer in self.rods.items():
            writer.store(chunk[name])
        self.flush()  # the rods' frames on disk before system.h5 lists them
        self.store(chunk)

    def flush(self):
        """Wait until every rod's chunks stored so far are on disk (an ``OSError`` if one failed)."""
        for writer in self.rods.values():
            writer.flush()

    def end(self, success, message, stats):
        """Finish every rod's files and the index; returns the run's SystemResult (its states
        read back from the chunk files)."""
        for writer in self.rods.values():
            writer.end(success, message, stats)
        if not self.t:  # stopped before its first frame was stored: nothing to list
            return SystemResult(self.assembly, np.empty(0), np.empty((0, self.assembly.size)), success, message,
                                dict(stats))
        result = SystemResult(self.assembly, np.array(self.t), read_series(self.directory, dict(chunks=self.chunks),
                                                                           "states"), success, message, dict(stats))
        self._write_index(success, message, result.stats, complete=True)  # with what the result adds (rod contacts)
        return result

    def resume_point(self):
        """(planned output times, index of the restart frame, its state) of the run being resumed."""
        run_files.refuse_resuming_nothing(self.directory, self.restart)
        return self.t_out, self.restart[0], self.restart[1]

    def check(self, assembly):
        """Resuming: refuse an assembly that is not the one of the run in the directory (other
        rods, or another layout of the state: another grid, a body free or not)."""
        keys, size = _keys(assembly.rods, "rod"), assembly.size
        if self._resumed != keys or self._layout is not None and self._layout != _layout(assembly):
            raise ParameterError(f"cannot resume the run in {str(self.directory)!r}: it is a run of the rods "
                                 f"{list(self._resumed)} with the state's parts {self._layout}, this system has "
                                 f"the rods {list(keys)} with {_layout(assembly)} ({size} states): the states kept "
                                 "are the run's, so its rods' grids and bodies cannot change (start a new run)")

    def record_settings(self, assembly, force=False, **run):
        """Record the settings of this run of ``assembly`` in the index (:func:`rodmol._settings.record_system`;
        ``run``: its backend, rtol, atol, backend options and initial state); resuming, refuse other
        settings than the run's, naming each (a changed part of the system too), unless ``force``."""
        settings, recorded = _settings.record_system(assembly, **run), self.settings
        settings, forced = _settings.settle(recorded, settings, force, repr(str(self.directory)))
        self.settings = settings
        if forced:
            start = float(self.t_out[self.restart[0]]) if self.restart is not None else 0.0
            self.forced = [*self.forced, dict(t_start=start, changed=list(forced))]

    def result(self):
        """The SystemResult read from the directory."""
        return read_system(self.directory)

    # ----------------------------------------------------------------- other uses

    def store(self, result, frames=slice(None)):
        """Write the frames ``frames`` (a slice) of the SystemResult ``result`` (the next frames of
        the run) as one chunk file, its views and the index listing it (its rods' files are
        written by the caller)."""
        if self._parts is None:
            self._plan(result, len(result.t) if self.t_out is None else len(self.t_out))
        _, bodies, surfaces, _ = self._parts
        t, start = result.t[frames], len(self.t)
        shown = [k for k in range(len(t)) if (start + k) % self.every == 0 or k == len(t) - 1]
        name = h5result.chunk_name(len(self.chunks))
        h5result.write_chunk(self.directory, name, [chunk_batch(result, frames, shown, surfaces, bodies)])
        write_views(self.directory, name, t[shown], surfaces, bodies, [*self.chunks, name])
        self.t.extend(np.asarray(t, dtype=float).tolist())
        self.chunks[name] = len(t)
        self._write_index(True, "running", {}, complete=False)

    def write_result(self, result):
        """Write a finished SystemResult (each rod's files as a single rod's, then the system's
        chunks); returns the path of ``system.h5``."""
        self._clear()
        self.t_out = np.asarray(result.t, dtype=float)
        self._plan(result, len(result.t))
        for name, key in self._parts[0].items():
            stream.write_xdmf(result[name], self.directory / key, self.every)
        for k0 in range(0, len(result.t), self.chunk_frames):
            self.store(result, slice(k0, k0 + self.chunk_frames))
        self._write_index(result.success, result.message, result.stats, complete=True)
        return self.directory / INDEX

    # ----------------------------------------------------------------- internals

    def _clear(self):
        """Remove an earlier run's files (once, before the first file of this one)."""
        if not self._cleared:
            run_files.clear(self.directory)
            self._cleared = True

    def _plan(self, result, n_frames):
        """The run's parts (file keys, the bodies' surfaces, the state's layout) and the views' step."""
        if self._parts is None:
            bodies = _keys(result.bodies, "body")
            self._parts = (_keys(result.rods, "rod"), bodies, {name: surface_of(result, name) for name in bodies},
                           None if result.assembly is None else _layout(result.assembly))
        self.every = view_step(n_frames, self.every)

    def _write_index(self, success, message, stats, complete):
        rods, bodies, surfaces, layout = self._parts
        info = dict(success=bool(success), message=str(message), stats=_plain(stats), rods=rods, bodies=bodies,
                    complete=complete, chunk_frames=self.chunk_frames, every=self.every, settings=self.settings)
        if layout is not None:
            info["parts"] = layout
        if self.forced:
            info["forced"] = self.forced
        planned = self.t if self.t_out is None else self.t_out  # no planned end: the times reached
        write_index(self.directory, planned, self.t, dict(self.chunks), info, surfaces, bodies)

    def _refuse_replacing(self, overwrite):
        if overwrite or not (self.directory / INDEX).is_file():
            run_files.refuse_replacing(self.directory, overwrite, "resume=True", "overwrite=True")
            return
        info = read_info(self.directory)["info"]
        if info.get("complete", True) and info["success"]:
            where = f"the output directory {str(self.directory)!r}"
            raise ParameterError(kept(f"{where} holds a finished system run", "overwrite=True (`--overwrite`)",
                                      "output directory"))
        raise ParameterError(f"the output directory {str(self.directory)!r} holds an unfinished system run: "
                             "continue it with resume=True (`--resume`), or replace it with overwrite=True")

    def _reopen(self):
        """Read the run to resume: its plan, settings and chunks up to its last restart point
        (the chunks after it, cut short by Ctrl-C or a failure, are dropped and redone)."""
        path = self.directory / INDEX
        if not path.is_file():
            raise ParameterError(f"nothing to resume in {str(self.directory)!r}: no {INDEX}")
        index = read_info(self.directory)
        info, t = index["info"], index["t"]
        if info.get("complete", True) and info["success"]:
            raise ParameterError(f"nothing to resume in {str(self.directory)!r}: the run there finished "
                                 f"({info['message']})")
        if index["t_out"] is None or index["chunks"] is None or not len(t):
            raise ParameterError(f"nothing to resume in {str(self.directory)!r}: no frames of a streamed "
                                 "run were kept (or an older rodmol wrote them: start the run again)")
        self.t_out, self.chunk_frames = index["t_out"], int(info["chunk_frames"])
        self.every, self.settings = info.get("every"), info.get("settings") or {}
        self.forced, self._layout = list(info.get("forced") or []), info.get("parts")
        last = len(t) - 1
        point = last - last % self.chunk_frames
        kept = run_files.chunks_kept(index["chunks"], point)
        frames = sum(kept.values())
        # The first chunk cut short: its first frame, the run's initial state, is the restart point.
        chunk, row = (list(kept)[-1], -1) if kept else (list(index["chunks"])[0], 0)
        with damaged(self.directory / chunk):
            _, state = h5result.frame_state(self.directory, chunk, row)
        self.chunks, self.t = kept, t[:frames].tolist()
        self.restart, self._resumed = (point, state), info["rods"]
        for file in run_files.temporaries(self.directory):  # what a writer killed mid-file left
            file.unlink(missing_ok=True)


def _layout(assembly):
    """The state's layout of an assembly: each part's name and [start, stop) in the state, in order."""
    return [[name, part.start, part.stop] for name, part in assembly.parts.items()]


def write_system(result, directory, every=None, overwrite=False):
    """Write a finished :class:`SystemResult` into ``directory`` (see :mod:`rodmol.output.system_files`);
    an earlier run there is kept unless ``overwrite`` (:func:`rodmol.output.run_files.claim`);
    returns the path of ``system.h5``. ``every``: show every n-th frame in the views (and the last)."""
    run_files.claim(output_directory(directory, "directory"), overwrite)
    return SystemRunWriter(directory, every=every, overwrite=True).write_result(result)


run_sinks.register_system_writer(SystemRunWriter)  # simulate(system, out=DIR) streams into one
