"""``result.npz``: the whole Result in one file (:meth:`rodmol.Result.save`, the ``"vtp"``
format's result file), read back by :func:`read_npz`."""

import json

import numpy as np

from ..result import ARRAYS, Result
from .h5result import damaged


def read_npz(path):
    """The :class:`rodmol.Result` saved in the ``.npz`` file ``path``; a damaged or truncated
    file is a :class:`rodmol.ParameterError` naming it and what is wrong with it."""
    try:
        with np.load(path, allow_pickle=False) as data:
            info = json.loads(str(data["info"]))
            # Files written before a key existed load without it.
            arrays = {k: data[k] for k in ARRAYS if k in data}
        return Result(arrays, info["success"], info["message"], info["stats"], info.get("meta"))
    except Exception as exc:  # noqa: BLE001 (zip, zlib, JSON and numpy each raise their own)
        raise damaged(path, exc) from exc
