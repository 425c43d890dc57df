"""Streamed output of a system's run: the frame sink of ``simulate(system, ..., out=DIR)``.

:class:`SystemRunWriter` receives the assembled states in chunks from
:func:`rodmol.solve.chunked.run_chunked` (the sink protocol of a single
rod's run) and, for each chunk,

* hands each rod's frames to that rod's :class:`rodmol.output.stream.RunWriter`
  (``DIR/NAME/``, a single rod's run directory, streamed as one), waits until
  they are on disk,
* then rewrites ``system.h5`` and ``bodies.xdmf`` (:func:`rodmol.output.system_files.write_index`)
  with every frame so far, the planned output times, ``chunk_frames`` and the run's settings.

``system.h5`` is written last, so it never lists a frame a rod's files lack:
it is what a resumed run (``resume=True``) restarts from, at its last restart
point (a frame index that is a multiple of ``chunk_frames``), rolling every
rod's directory back to that frame. A run killed at any moment leaves a
directory that :func:`rodmol.load_result` reads up to the last chunk its
``system.h5`` lists (a rod's own files may hold one chunk more).

Unlike a rod's chunks, ``system.h5`` holds every frame so far (the assembled
states and the bodies' frames): it is rewritten, atomically, at each chunk.
"""

import numpy as np

from .. import run_sinks
from .._files import output_directory
from ..errors import ParameterError
from ..system_result import SystemResult
from . import run_files
from .parts import view_step
from .stream import CHUNK_FRAMES, RunWriter
from .system_files import INDEX, _keys, read_info, read_system, write_index


class SystemRunWriter:
    """Streams a system's frames into ``directory`` (created if needed).

    Parameters
    ----------
    directory : path
    chunk_frames : int
        Output frames per chunk; the solver restarts at every chunk boundary
        (the restart points of ``resume``).
    every : int, optional
        The views show every ``every``-th output frame (and the last);
        default as for a single rod (:func:`rodmol.output.parts.view_step`).
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
        self.assembly, self.rods, self.t_out, self.settings = None, {}, None, None
        self.t, self.states = [], []  # the frames listed in system.h5, chunk by chunk
        self.restart, self._resumed = None, None
        if resume:
            self._reopen()
        else:
            self._refuse_replacing(overwrite)
            run_files.clear(self.directory)

    # ----------------------------------------------------------------- the sink protocol

    def begin(self, system, t_out):
        """Start (or continue) the run of the assembly ``system`` (``system.assembly`` if it
        carries one) through the output times ``t_out``."""
        assembly = getattr(system, "assembly", system)
        self.assembly = assembly
        if self.t_out is None:
            self.t_out = np.asarray(t_out, dtype=float)
        keys = _keys(assembly.rods, "rod")
        if self._resumed is not None:
            self.check(assembly)
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
        self.t.append(chunk.t)
        self.states.append(chunk.states)
        self._write_index(True, "running", {}, complete=False)

    def flush(self):
        """Wait until every rod's chunks stored so far are on disk (an ``OSError`` if one failed)."""
        for writer in self.rods.values():
            writer.flush()

    def end(self, success, message, stats):
        """Finish every rod's files and the index; returns the run's SystemResult (in memory)."""
        for writer in self.rods.values():
            writer.end(success, message, stats)
        return self._write_index(success, message, stats, complete=True)

    def check(self, assembly):
        """Resuming: refuse an assembly that is not the one of the run in the directory."""
        keys, size = _keys(assembly.rods, "rod"), self.states[0].shape[1]
        if self._resumed != keys or size != assembly.size:
            raise ParameterError(f"cannot resume the run in {str(self.directory)!r}: it is a run of the rods "
                                 f"{list(self._resumed)} with {size} states, this system has the rods "
                                 f"{list(keys)} with {assembly.size}")

    def record_settings(self, settings):
        """The run's settings (JSON values), recorded in the index for a resumed run."""
        self.settings = dict(settings)

    def result(self):
        """The SystemResult read from the directory."""
        return read_system(self.directory)

    # ----------------------------------------------------------------- internals

    def _write_index(self, success, message, stats, complete):
        if not self.t:  # stopped before its first frame was stored: nothing to list
            return SystemResult(self.assembly, np.empty(0), np.empty((0, self.assembly.size)), success, message,
                                dict(stats))
        result = SystemResult(self.assembly, np.concatenate(self.t), np.concatenate(self.states), success,
                              message, dict(stats))
        write_index(self.directory, result, view_step(len(self.t_out), self.every), complete=complete,
                    t_out=self.t_out.tolist(), chunk_frames=self.chunk_frames, every=self.every,
                    settings=self.settings)
        return result

    def _refuse_replacing(self, overwrite):
        if overwrite or not (self.directory / INDEX).is_file():
            run_files.refuse_replacing(self.directory, overwrite, "resume=True", "overwrite=True")
            return
        info = read_info(self.directory)[0]
        if info.get("complete", True) and info["success"]:
            raise ParameterError(f"the output directory {str(self.directory)!r} holds a finished system run: "
                                 "it is kept unless you pass overwrite=True (`--overwrite`) to replace it")
        raise ParameterError(f"the output directory {str(self.directory)!r} holds an unfinished system run: "
                             "continue it with resume=True (`--resume`), or replace it with overwrite=True")

    def _reopen(self):
        """Read the run to resume: its plan, settings and frames up to its last restart point."""
        if not (self.directory / INDEX).is_file():
            raise ParameterError(f"nothing to resume in {str(self.directory)!r}: no {INDEX}")
        info, t, states = read_info(self.directory)
        if info.get("complete", True) and info["success"]:
            raise ParameterError(f"nothing to resume in {str(self.directory)!r}: the run there finished "
                                 f"({info['message']})")
        if "t_out" not in info or not len(t):
            raise ParameterError(f"nothing to resume in {str(self.directory)!r}: no frames of a streamed "
                                 "run were kept")
        self.t_out, self.chunk_frames = np.asarray(info["t_out"], dtype=float), int(info["chunk_frames"])
        self.every, self.settings = info.get("every"), info.get("settings") or {}
        last = len(t) - 1
        point = last - last % self.chunk_frames
        self.t, self.states = [t[:point + 1]], [states[:point + 1]]
        self.restart, self._resumed = (point, states[point]), info["rods"]


run_sinks.register_system_writer(SystemRunWriter)  # simulate(system, out=DIR) streams into one
