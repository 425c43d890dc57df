"""Streamed output of a run: the frame sink of :func:`rodmol.simulate`.

:class:`RunWriter` receives the states at the output times in chunks while
the run goes (``simulate(..., out=DIR)``; the sink protocol is
``begin(system, t_out)``, ``frames(t, y)``, ``end(success, message, stats)``
returning the :class:`rodmol.Result`, and ``chunk_frames``), derives the
Result's arrays for each chunk, and writes

* the chunk's HDF5 file and the index ``result.h5`` (:mod:`rodmol.io.h5result`),
* the ParaView views ``rod.xdmf``, ``cables.xdmf``, ``markers.xdmf``
  (:mod:`rodmol.io.xdmf`; only every ``every``-th frame and the last).

Memory stays bounded by one chunk. Every file appears complete under its
real name or not at all, so a run killed at any moment leaves a directory
that ParaView and :func:`rodmol.load_result` read up to the last complete
chunk, and whose last frame is the restart point of ``resume=True``.
"""

import time
from pathlib import Path

import numpy as np

from ..errors import ParameterError
from ..solve.chunked import merge_stats
from . import h5result, xdmf
from .h5result import INDEX, SERIES, STATIC
from .parts import cable_points

#: Number type of the arrays only the views use (the Result's own stay float64):
#: single precision halves the largest of them, the cables' points.
VIEW = np.float32
#: Output frames per chunk by default: bounded memory (about 50 kB a frame at
#: N = 100), fewer than 100 files for 600 s at 100 frames/s.
CHUNK_FRAMES = 2000


class RunWriter:
    """Streams frames into ``directory`` (created if needed).

    Parameters
    ----------
    directory : path
    views : bool
        Write the XDMF views for ParaView (False: only ``result.h5`` and the chunks).
    every : int
        The views show every ``every``-th output frame (and the last); the
        result file keeps all.
    chunk_frames : int
        Output frames per chunk file. With ``simulate(..., out=...)`` the
        solver also restarts at every chunk boundary (the restart points),
        so a resumed run repeats the uninterrupted one exactly.
    resume : bool
        Continue the unfinished run in ``directory`` (see :meth:`resume_point`),
        with its own ``chunk_frames`` and ``every``.
    meta : dict, optional
        Added to the Result's ``meta`` (e.g. the scenario's name).
    """

    def __init__(self, directory, *, views=True, every=1, chunk_frames=CHUNK_FRAMES, resume=False,
                 meta=None):
        if int(every) < 1 or int(chunk_frames) < 1:
            raise ParameterError(f"`every` and `chunk_frames` must be >= 1, got {every!r}, {chunk_frames!r}")
        self.directory = Path(directory)
        self.directory.mkdir(parents=True, exist_ok=True)
        self.views, self.every, self.chunk_frames = bool(views), int(every), int(chunk_frames)
        self.extra_meta = dict(meta or {})
        self.chunks, self.t, self.t_out, self.seconds = {}, [], None, 0.0
        self.static, self.meta, self.system, self.last = None, None, None, None
        self.previous = None
        if resume:
            self._reopen()
        else:
            self._clear()

    # ----------------------------------------------------------------- the sink protocol

    def begin(self, system, t_out):
        """Start (or, resuming, continue) a run of ``system`` with output times ``t_out``."""
        from ..result import run_meta, static_arrays

        self.system = system
        if self.t_out is None:
            self.t_out = np.asarray(t_out, dtype=float)
        if self.static is None:
            self.static, self.meta = static_arrays(system), dict(run_meta(system), **self.extra_meta)

    def frames(self, t, y):
        """Store the states ``y`` (n, size) at output times ``t`` (n,) as one chunk."""
        from ..result import from_states

        started = time.perf_counter()
        chunk = from_states(self.system, np.asarray(t, dtype=float), np.asarray(y), True, "", {})
        self.store({name: getattr(chunk, name) for name in SERIES})
        self.seconds += time.perf_counter() - started

    def end(self, success, message, stats):
        """Finish: the last frame in the views, the final index; returns the Result (read lazily)."""
        started = time.perf_counter()
        if self.last is not None and self.views:
            name, t, start = self.last
            frames = self._shown(start, len(t), last=True)
            if frames != self._shown(start, len(t)):  # the run's last frame was not shown yet
                self._fragment(name, t, frames, len(t))
        if self.previous is not None:  # a resumed run: the statistics of both parts
            stats = merge_stats([self.previous.get("stats", {}), stats])
        self._index(dict(success=bool(success), message=str(message), stats=dict(stats),
                         complete=True))
        self.seconds += time.perf_counter() - started
        return self.result()

    # ----------------------------------------------------------------- other uses

    def store(self, arrays, static=None, meta=None):
        """Write one chunk from the Result arrays of its frames (``SERIES`` names, time first);
        ``static`` arrays and ``meta`` of the Result, unless :meth:`begin` gave them."""
        if self.static is None:
            self.static, self.meta = static, dict(meta, **self.extra_meta)
        index = len(self.chunks)
        name = h5result.write_chunk(self.directory, index, arrays, self._extras(arrays) if self.views else None)
        n = len(arrays["t"])
        start = len(self.t)
        self.chunks[name] = n
        self.t.extend(np.asarray(arrays["t"], dtype=float).tolist())
        self.last = (name, np.asarray(arrays["t"]), start)
        if self.views:
            self._fragment(name, arrays["t"], self._shown(start, n), n)
            fragments = [c[:-3] + ".xmf" for c in self.chunks]
            for view in self.view_names():
                xdmf.write_view(self.directory / f"{view}.xdmf", view, fragments)
        self._index(dict(success=True, message="running", stats={}, complete=False))

    def write_result(self, result):
        """Write a finished in-memory :class:`rodmol.Result`, chunk by chunk; returns the path of ``rod.xdmf``."""
        started = time.perf_counter()
        self.t_out = np.asarray(result.t, dtype=float)
        static = {key: getattr(result, key) for key in STATIC}
        for k0 in range(0, len(result.t), self.chunk_frames):
            frames = slice(k0, k0 + self.chunk_frames)
            self.store({name: getattr(result, name)[frames] for name in SERIES}, static, result.meta)
        self.seconds += time.perf_counter() - started
        self.end(result.success, result.message, result.stats)
        return self.directory / "rod.xdmf"

    def result(self):
        return h5result.read_result(self.directory / INDEX)

    def resume_point(self):
        """(planned output times, index of the last frame kept, its state) of the run being resumed."""
        if not self.chunks:
            raise ParameterError(f"nothing to resume in {str(self.directory)!r}: no frames were kept")
        _, y = h5result.last_state(self.directory, self.chunks)
        return self.t_out, len(self.t) - 1, y

    # ----------------------------------------------------------------- internals

    def _reopen(self):
        path = self.directory / INDEX
        if not path.is_file():
            raise ParameterError(f"nothing to resume in {str(self.directory)!r}: no {INDEX}")
        index = h5result.read_index(path)
        if index["info"].get("complete", True) and index["info"].get("success"):
            raise ParameterError(f"nothing to resume in {str(self.directory)!r}: the run there finished "
                                 f"({index['info']['message']})")
        self.chunks, self.t, self.t_out = dict(index["chunks"]), index["t"].tolist(), index["t_out"]
        self.static = {key: index[key] for key in STATIC}
        self.meta = dict(index["info"].get("meta") or {}, **self.extra_meta)
        # The restart points of the run being resumed, whatever this writer was given.
        self.chunk_frames = int(index["info"].get("chunk_frames", self.chunk_frames))
        self.every = int(index["info"].get("every", self.every))
        self.previous = index["info"]

    def _clear(self):
        clear_outputs(self.directory)
        (self.directory / "result.npz").unlink(missing_ok=True)

    def view_names(self):
        """The views this run has: the rod, and the cables and markers if any."""
        names = ["rod"]
        if self.meta.get("cables"):
            names.append("cables")
        if self.meta.get("markers"):
            names.append("markers")
        return names

    def _shown(self, start, n, last=False):
        """Chunk frames shown in the views: global index a multiple of ``every``, and the run's last."""
        frames = [k for k in range(n) if (start + k) % self.every == 0]
        if last and (not frames or frames[-1] != n - 1):
            frames.append(n - 1)
        return frames

    def _fragment(self, name, t, frames, n):
        h5 = name  # relative to the views, which sit in the run directory
        n_nodes = len(self.static["s"])
        views = {"rod": xdmf.rod_grids(h5, t, frames, n_nodes, n)}
        if self.meta.get("cables"):
            n_points = sum(len(s) for s, _ in self._cable_layout())
            views["cables"] = xdmf.cable_grids(h5, t, frames, n_points, n_points - len(self.meta["cables"]), n)
        if self.meta.get("markers"):
            views["markers"] = xdmf.marker_grids(h5, t, frames, len(self.meta["markers"]), n)
        xdmf.write_fragment(self.directory / (name[:-3] + ".xmf"), views)

    def _cable_layout(self):
        one = np.zeros((1, len(self.static["s"]), 3))
        return cable_points(self.static["s"], one, np.broadcast_to(np.eye(3), one.shape[:2] + (3, 3)), self.meta)

    def _extras(self, arrays):
        """The arrays the views need besides the Result's: global velocity, cable and marker geometry."""
        n_nodes = len(self.static["s"])
        rotations = np.asarray(arrays["rotations"])
        extras = {"s": self.static["s"], "radius": self.static["radius"],
                  "rod_cells": np.arange(n_nodes, dtype=np.int64)[None],
                  "velocity_global": np.einsum("tnij,tnj->tni", rotations, arrays["velocity"]).astype(VIEW)}
        paths = cable_points(self.static["s"], np.asarray(arrays["positions"]), rotations, self.meta)
        if paths:
            sizes = [len(s) for s, _ in paths]
            starts = np.concatenate([[0], np.cumsum(sizes)])
            cells = np.concatenate([np.stack([np.arange(a, b - 1), np.arange(a + 1, b)], axis=1)
                                    for a, b in zip(starts[:-1], starts[1:])])
            tension = np.asarray(arrays["tensions"], dtype=VIEW).reshape(len(arrays["t"]), -1)
            cell_cable = np.concatenate([np.full(n - 1, i) for i, n in enumerate(sizes)])
            extras.update(cable_points=np.concatenate([p.astype(VIEW) for _, p in paths], axis=1),
                          cable_s=np.concatenate([s for s, _ in paths]),
                          cable_index=np.repeat(np.arange(len(paths)), sizes),
                          cable_cells=cells, cable_cell_index=cell_cable,
                          cable_point_tension=np.repeat(tension, sizes, axis=1),
                          cable_cell_tension=tension[:, cell_cable])
        markers = self.meta.get("markers", [])
        if markers:
            extras.update(marker_cells=np.arange(len(markers), dtype=np.int64)[:, None],
                          marker_s=np.array([float(m["s"]) for m in markers]),
                          marker_index=np.arange(len(markers), dtype=np.int64))
        return extras

    def _index(self, info):
        if self.previous is not None and not info.get("complete"):
            info["stats"] = self.previous.get("stats", {})
        info.update(meta=self.meta or {}, chunk_frames=self.chunk_frames, every=self.every)
        h5result.write_index(self.directory, self.static, self.t_out if self.t_out is not None else self.t,
                             self.t, self.chunks, info)


def clear_outputs(directory):
    """Remove the streamed outputs of an earlier run in ``directory``, so nothing stale is listed or read."""
    directory = Path(directory)
    for name in (INDEX, *(f"{v}.xdmf" for v in xdmf.VIEWS)):
        (directory / name).unlink(missing_ok=True)
    frames = directory / h5result.FRAMES
    if frames.is_dir():
        for file in frames.glob("chunk_*"):
            file.unlink()
