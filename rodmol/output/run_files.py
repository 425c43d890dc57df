"""The files a run directory holds: the one list, and replacing an earlier run.

A run directory (``rodmol run --out DIR``, ``simulate(..., out=DIR)``,
:func:`rodmol.write_series`) holds the index ``result.h5`` with its chunks
and views, or ``result.npz`` with its ``.pvd``/``.vtp`` series, and the
pictures of ``rodmol render`` and ``rodmol plot``. :data:`TOP` and
:data:`NUMBERED` name them all; :func:`clear` removes exactly those (and
their half-written temporaries), never another file, so a replaced run leaves
nothing of itself behind. :func:`refuse_replacing` keeps an earlier run from
being replaced by accident (:func:`claim`: both, before a writer's first file).
"""

import contextlib
import json
import re
from pathlib import Path

from .._files import OVERWRITE, kept, leftover_temporaries, refuse_directories
from ..errors import ParameterError
from . import h5result, xdmf
from .parts import PARTS

#: ``result.npz``: the whole Result (``--format vtp``, :meth:`rodmol.Result.save`).
NPZ = "result.npz"
#: The folder of the per-frame ``.vtp`` files of the series format.
SERIES = "vtk"
#: ``rodmol render``'s pictures.
RENDERED = ("last_frame.png", "animation.gif")
#: ``rodmol plot``'s pictures.
PLOTTED = ("tip_path.png", "markers.png", "tensions.png")
#: A system's run (:mod:`rodmol.output.system_files`): its index and the bodies' view
#: (each rod's files in a folder of its own, a run directory as a single rod's).
SYSTEM = ("system.h5", "bodies.xdmf")
#: The files a run writes directly into its directory.
TOP = (h5result.INDEX, NPZ, *(f"{view}.xdmf" for view in xdmf.VIEWS), *(f"{part}.pvd" for part in PARTS),
       *RENDERED, *PLOTTED, *SYSTEM)
#: The numbered files in its folders: folder -> the names' pattern (a regular expression).
NUMBERED = {h5result.FRAMES: r"chunk_\d{6}\.(h5|xmf)", SERIES: rf"({'|'.join(PARTS)})_\d+\.vtp"}
#: Name patterns (glob) of the numbered files, for their temporaries.
_GLOBS = {h5result.FRAMES: "chunk_*", SERIES: "*.vtp"}


def numbered(directory, folder):
    """The numbered files of ``folder`` (a key of :data:`NUMBERED`) in ``directory``, sorted."""
    path = Path(directory) / folder
    if not path.is_dir():
        return []
    return sorted(f for f in path.iterdir() if f.is_file() and re.fullmatch(NUMBERED[folder], f.name))


def temporaries(directory):
    """The half-written files a killed writer left (hidden ``.part`` files of the run's files)."""
    directory = Path(directory)
    patterns = [directory / name for name in TOP] + [directory / f / g for f, g in _GLOBS.items()]
    return [file for pattern in patterns for file in leftover_temporaries(pattern)]


def run_files(directory):
    """rodmol's files in ``directory``: an earlier run's outputs, its pictures, their temporaries."""
    directory = Path(directory)
    found = [directory / name for name in TOP if (directory / name).is_file()]
    for folder in NUMBERED:
        found += numbered(directory, folder)
    return found + temporaries(directory)


def clear(directory):
    """Remove every file of :func:`run_files` (and the run's folders, if that empties them),
    and a system's run's rod folders (:func:`system_rods`) so;
    first refuse a directory where the run writes a file, or a file where it writes a folder."""
    directory = Path(directory)
    refuse_directories([directory / name for name in TOP])
    for folder in NUMBERED:
        if (directory / folder).exists() and not (directory / folder).is_dir():
            raise ParameterError(f"{str(directory / folder)!r} is a file, where rodmol writes a folder of its "
                                 "output; remove it or choose another output directory")
    rods = [folder for folder in system_rods(directory) if (directory / folder).is_dir()]
    for folder in rods:  # before the index that names them
        clear(directory / folder)
    for file in run_files(directory):
        file.unlink(missing_ok=True)
    for folder in [*NUMBERED, *rods]:
        with contextlib.suppress(OSError):  # absent, or holds files not rodmol's
            (directory / folder).rmdir()


def system_rods(directory):
    """The folders of the rods of a system's run in ``directory`` (each a run directory, named
    in its index ``system.h5``; :mod:`rodmol.output.system_files`), else none."""
    import h5py

    index = Path(directory) / SYSTEM[0]
    if not index.is_file():
        return []
    try:
        with h5py.File(index, "r") as handle:
            rods = json.loads(handle.attrs["info"])["rods"]
    except (OSError, KeyError, ValueError, TypeError):  # not rodmol's, or damaged: its folders unknown
        return []
    return [key for key in rods.values() if isinstance(key, str) and Path(key).name == key]


def earlier_run(directory):
    """What an earlier run left in ``directory``: None, or (finished, description)."""
    directory = Path(directory)
    index = directory / h5result.INDEX
    if index.is_file():
        try:
            info = h5result.read_index(index)
        except (OSError, KeyError, ValueError):
            return False, f"its {h5result.INDEX} cannot be read"
        t, t_out, meta = info["t"], info["t_out"], info["info"].get("meta") or {}
        grid = f", N = {meta['n_elements']}" if "n_elements" in meta else ""
        reached = float(t[-1]) if len(t) else float(t_out[0])
        if info["info"].get("complete", True) and info["info"].get("success"):
            return True, f"a finished run to t = {reached:g} s{grid}"
        return False, f"a run stopped at t = {reached:g} s of {float(t_out[-1]):g} s{grid}"
    if (directory / NPZ).is_file():
        return True, f"the run in {NPZ}"
    if run_files(directory):
        return True, "the outputs of an earlier run"
    return None


def refuse_replacing(directory, overwrite, resume_hint=None, overwrite_hint=OVERWRITE):
    """Unless ``overwrite``, raise a ParameterError if ``directory`` holds an earlier run; the
    message suggests ``resume_hint`` for an unfinished run (None: a writer that cannot resume),
    ``overwrite_hint`` for any (:func:`rodmol._files.kept`, the rule of every writer)."""
    found = None if overwrite else earlier_run(directory)
    if found is None:
        return
    finished, what = found
    if finished or resume_hint is None:
        raise ParameterError(kept(f"the output directory {str(directory)!r} holds {what}", overwrite_hint,
                                  "output directory"))
    raise ParameterError(f"the output directory {str(directory)!r} holds {what}: continue it with "
                         f"{resume_hint}, or replace it with {overwrite_hint}")


def claim(directory, overwrite, resume_hint=None, overwrite_hint=OVERWRITE):
    """Refuse to replace an earlier run in ``directory`` unless ``overwrite``
    (:func:`refuse_replacing`), then :func:`clear` it: what every writer of a run directory
    does before its first file."""
    refuse_replacing(directory, overwrite, resume_hint, overwrite_hint)
    clear(directory)


def refuse_resuming_nothing(directory, restart):
    """Refuse to resume with a writer made without ``resume=True`` (``restart`` None): it holds no run."""
    if restart is None:
        raise ParameterError(f"`resume=True`: this writer of {str(directory)!r} holds no run to resume "
                             "(make it with resume=True)")


def chunks_kept(chunks, point):
    """The chunks (name -> frames, in the run's order) that a run resumed from its restart frame
    ``point`` keeps: those ending at or before it. A first chunk cut short after its first frame
    ends at frame 0 but is not kept (none is, at ``point`` 0): the run is redone from the initial
    state it holds, that first frame included, which keeping it would store twice."""
    kept, frames = {}, 0
    for name, n in chunks.items():
        if frames + n - 1 > point or point == 0:
            break
        kept[name], frames = n, frames + n
    return kept


def cannot_write(path, exc):
    """The message of an output that could not be written (``exc``, an OSError, at ``path``)."""
    reason = exc.strerror or str(exc)
    where = exc.filename if isinstance(exc.filename, str) else str(path)
    return (f"cannot write {where!r}: {reason}; the outputs written before it are valid "
            "(free some space or choose another --out)")
