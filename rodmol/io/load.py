"""Reading results back: :func:`load_result` for every file a run or
:meth:`rodmol.Result.save` writes."""

import json
import os
from pathlib import Path

import numpy as np

from ..errors import ParameterError
from ..result import ARRAYS, Result
from .h5result import damaged, read_result


def result_file(path):
    """The result file of ``path``: itself, or for a run directory or one of its
    views the directory's ``result.h5``, else its ``result.npz``."""
    path = Path(path)
    if path.is_dir() or path.suffix == ".xdmf":
        folder = path if path.is_dir() else path.parent
        found = [folder / name for name in ("result.h5", "result.npz") if (folder / name).is_file()]
        if not found:
            raise FileNotFoundError(f"no result.h5 or result.npz in {str(folder)!r}")
        return found[0]
    return path


def load_result(path):
    """Read a :class:`Result`: a run directory (its ``result.h5``, else ``result.npz``), a
    streamed run's ``result.h5`` or one of its views (``rod.xdmf``, ...; arrays read on first
    access), or a ``.npz`` written by :meth:`Result.save`.

    A path that holds no result, or a damaged or truncated file, is a
    :class:`rodmol.ParameterError` naming the file and what is wrong with it.
    """
    if not isinstance(path, (str, os.PathLike)) or "\0" in str(path):
        raise ParameterError(f"`path` must be a file or directory name, got {path!r}")
    try:
        path = result_file(path)
    except FileNotFoundError as exc:
        raise ParameterError(f"`path`: {exc}") from None
    if not path.is_file():
        raise ParameterError(f"`path`: no such result file or run directory: {str(path)!r}")
    if path.suffix == ".h5":
        return read_result(path)
    try:
        with np.load(path, allow_pickle=False) as data:
            info = json.loads(str(data["info"]))
            # Files written before a key existed load without it.
            arrays = {k: data[k] for k in ARRAYS if k in data}
        return Result(arrays, info["success"], info["message"], info["stats"], info.get("meta"))
    except Exception as exc:  # noqa: BLE001 (zip, zlib, JSON and numpy each raise their own)
        raise damaged(path, exc) from exc
