"""The streamed result file: an HDF5 index (``result.h5``) and chunk files.

A run directory holds

* ``result.h5``: the index, small, replaced atomically after every chunk:
  the static arrays (``s``, ``radius``, ``node_length``), the planned output
  times ``t_out`` (so a resumed run keeps the same grid), the times reached
  ``t``, the chunk files in order and, as JSON in the attribute ``info``,
  ``success``, ``message``, ``stats``, ``meta`` and ``complete`` (False while
  the run goes or after it was killed), and for a run of ``simulate`` its
  ``settings``, each chunk's solver statistics and its ``sessions``
  (:mod:`rodmol.output.run_record`);
* ``frames/chunk_NNNNNN.h5``: the frames of one chunk: the arrays of
  :data:`rodmol.result.STORED` (``states`` included, so each chunk's last
  frame is a restart point; the Result's other arrays are derived from them
  on reading, exactly as in memory; the stresses and loads in single
  precision, :data:`SINGLE`) and, in the group ``view``, the arrays
  the ParaView views reference (:mod:`rodmol.output.xdmf`). Each is written under
  a temporary name and renamed when complete, and never changed after.

HDF5 files are not crash-safe while open for writing; here no file is ever
open for writing under its real name, so a killed run leaves an index that
lists only complete chunks. :func:`read_result` reads the arrays lazily (on
first access) and concatenates the chunks.
"""

import json
import os
from pathlib import Path

import numpy as np

from .._files import atomic_path
from ..discretise.layout import StateLayout
from ..errors import ParameterError
from ..result import ARRAYS, FORCES, STATIC, STORED, Result

INDEX = "result.h5"
FRAMES = "frames"
FORMAT = "rodmol-result"
#: The group of a chunk holding the views' arrays.
VIEW_GROUP = "view"
#: Stored in single precision (7 digits), read back as float64: the stresses and
#: loads, which only the model could recompute. The states stay double, so the
#: kinematics derived from them and a restart are exact.
SINGLE = FORCES
#: Number type of the views' floating arrays (the result's own keep theirs): what a
#: picture needs, at half the bytes.
VIEW = np.float32
#: HDF5 format versions readable by the HDF5 1.10 of ParaView 5.11 (Debian).
LIBVER = ("earliest", "v110")


def atomic_h5(path, fill):
    """Write an HDF5 file with ``fill(h5py.File)`` under a temporary name, then rename it to ``path``."""
    import h5py

    with atomic_path(path) as tmp, h5py.File(tmp, "x", libver=LIBVER) as handle:
        fill(handle)


def chunk_name(index):
    return f"{FRAMES}/chunk_{index:06d}.h5"


def write_chunk(directory, name, batches):
    """Write the chunk ``name`` (:func:`chunk_name`): ``batches`` in order, each a dict (dataset
    path -> time-first array; the views' arrays under ``view/``, :func:`views`) or a function
    returning one, called once the batches before it are written (so it may still be computed
    meanwhile). The views' floating arrays are written as :data:`VIEW`, and a view of every
    frame of a stored single-precision array is a link to it, not a copy. (HDF5 converts
    number types while writing, through a small buffer of its own: no copies.)"""
    (Path(directory) / FRAMES).mkdir(parents=True, exist_ok=True)

    def fill(handle):
        for batch in batches:
            for path, value in (batch() if callable(batch) else batch).items():
                group, _, key = path.rpartition("/")
                value = np.asarray(value)
                if group == VIEW_GROUP and key in SINGLE and key in handle and len(value) == len(handle[key]):
                    handle[path] = handle[key]  # an HDF5 hard link: the same numbers
                elif group == VIEW_GROUP:
                    handle.create_dataset(path, data=value, dtype=VIEW if value.dtype.kind == "f" else None)
                else:
                    handle.create_dataset(path, data=value, dtype=np.float32 if key in SINGLE else None)

    atomic_h5(Path(directory) / name, fill)


def views(arrays):
    """The views' ``arrays`` (name -> array) as a batch of :func:`write_chunk`."""
    return {f"{VIEW_GROUP}/{key}": value for key, value in arrays.items()}


def write_index(directory, static, t_out, t, chunks, info):
    """Replace ``result.h5``: static arrays, planned and reached times, chunk list, ``info`` (JSON)."""
    import h5py

    def fill(handle):
        handle.attrs["format"] = FORMAT
        handle.attrs["info"] = json.dumps(dict(info, units=ARRAYS))
        for key in STATIC:
            handle.create_dataset(key, data=np.asarray(static[key]))
        handle.create_dataset("t_out", data=np.asarray(t_out, dtype=float))
        handle.create_dataset("t", data=np.asarray(t, dtype=float))
        handle.create_dataset("chunks", data=[c.encode() for c in chunks], dtype=h5py.string_dtype())
        handle.create_dataset("chunk_frames", data=np.asarray(list(chunks.values()), dtype=np.int64))

    atomic_h5(Path(directory) / INDEX, fill)


def damaged(path, exc):
    """The :class:`ParameterError` for a result file ``path`` that cannot be read
    (``exc`` is what the reader raised), to be raised ``from exc``."""
    text = str(exc).strip() or type(exc).__name__
    try:
        with open(path, "rb") as handle:
            start = handle.read(8)
    except OSError:
        start = b""
    ours = start.startswith((b"PK\x03\x04", b"\x89HDF\r\n\x1a\n"))  # a zip (.npz) or an HDF5 file
    if not os.path.exists(path):
        what = "it is missing (the run's result.h5 lists it: a run directory copied in part?)"
    elif "truncated" in text or (ours and "not a zip file" in text):  # a zip's directory is at its end
        what = "it is truncated (it ends early: a copy or a write that did not finish?)"
    elif not ours:
        what = "it is not a file rodmol wrote (neither a .npz nor an HDF5 file)"
    else:
        what = "it is damaged or not a file rodmol wrote"
    if len(text) > 200:
        text = text[:200] + "..."
    return ParameterError(f"cannot read the result file {str(path)!r}: {what} ({type(exc).__name__}: {text})")


def read_index(path):
    """The index at ``path``: dict with the static arrays, ``t_out``, ``t``, ``chunks`` (name -> frames),
    ``info``; a file that is not a readable index is a :func:`damaged` error naming it."""
    import h5py

    try:
        with h5py.File(path, "r") as handle:
            if handle.attrs.get("format") != FORMAT:
                raise ValueError(f"no attribute format = {FORMAT!r}: not a rodmol result index")
            index = {key: handle[key][()] for key in (*STATIC, "t_out", "t")}
            names = [c.decode() if isinstance(c, bytes) else str(c) for c in handle["chunks"][()]]
            index["chunks"] = dict(zip(names, handle["chunk_frames"][()].tolist()))
            index["info"] = json.loads(handle.attrs["info"])
    except FileNotFoundError:
        raise
    except (OSError, KeyError, ValueError, TypeError) as exc:  # h5py reports damage as OSError
        raise damaged(path, exc) from exc
    return index


def read_series(directory, chunks, name):
    """Array ``name`` of all ``chunks`` of a run directory, concatenated in time."""
    import h5py

    parts = []
    for chunk in chunks:
        try:
            with h5py.File(Path(directory) / chunk, "r") as handle:
                parts.append(handle[name][()])
        except (OSError, KeyError, ValueError) as exc:  # a missing chunk too: the index lists it
            raise damaged(Path(directory) / chunk, exc) from exc
    return np.asarray(np.concatenate(parts), dtype=float) if parts else np.zeros((0,))


def last_state(directory, chunks):
    """(time [s], state) of the last frame of the last chunk: the restart point."""
    return frame_state(directory, list(chunks)[-1], -1)


def frame_state(directory, chunk, row):
    """(time [s], state) of frame ``row`` of the chunk file ``chunk``."""
    import h5py

    with h5py.File(Path(directory) / chunk, "r") as handle:
        return float(handle["t"][row]), handle["states"][row]


def read_result(path):
    """A :class:`rodmol.Result` from an index file, once the chunk files it lists are found; the
    time series load on first access."""
    path = Path(path)
    index = read_index(path)
    info, chunks, folder = index["info"], list(index["chunks"]), path.parent
    for chunk in chunks:  # all there now, not when an array is first read
        if not (folder / chunk).is_file():
            raise damaged(folder / chunk, FileNotFoundError(f"no file {chunk!r} in {str(folder)!r}"))
    arrays = {key: index[key] for key in STATIC}
    arrays["t"] = index["t"]

    def loader(name):
        if not chunks:  # nothing was written: empty arrays of the right rank
            return lambda result: {name: np.zeros((0,) + _empty_shape(name, len(arrays["s"]), info))}
        return lambda result: {name: read_series(folder, chunks, name)}

    # What the chunks hold is read from them (files of older versions held every array);
    # the Result derives the rest.
    deferred = {name: loader(name) for name in _stored(folder, chunks) if name != "t"}
    message = info["message"]
    if not info.get("complete", True):
        message = (f"the run was stopped before it finished (killed?): {len(arrays['t'])} frames up to "
                   f"t = {arrays['t'][-1] if len(arrays['t']) else 0.0:.6g} s were kept; resume it with "
                   "`rodmol run ... --resume` or simulate(..., out=DIR, resume=True)")
    return Result(arrays, info["success"] and info.get("complete", True), message, info["stats"],
                  info.get("meta"), deferred)


def _stored(folder, chunks):
    """The Result's arrays the chunks hold (all of :data:`STORED` when there are none)."""
    import h5py

    if not chunks:
        return STORED
    try:
        with h5py.File(folder / chunks[0], "r") as handle:
            return tuple(name for name in dict.fromkeys((*STORED, *ARRAYS)) if name in handle and name not in STATIC)
    except OSError as exc:
        raise damaged(folder / chunks[0], exc) from exc


def _empty_shape(name, n_nodes, info):
    meta = info.get("meta") or {}
    cables = (len(meta.get("cables", [])),)
    shapes = {"tensions": cables, "cable_lengths": cables, "actuator_positions": (len(meta.get("actuators", [])),),
              "states": (StateLayout(n_nodes - 1).size,), "boundary_rows": (12,)}
    return shapes.get(name, (n_nodes, 3))
