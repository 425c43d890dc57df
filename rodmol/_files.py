"""Writing a file so that readers only ever see a complete one."""

import contextlib
import os
import tempfile
from pathlib import Path

from .errors import ParameterError


def _temporary_name(name):
    """(prefix, suffix) of the temporaries of a file called ``name``: hidden, ``.part``."""
    return f".{name}.", ".part"


@contextlib.contextmanager
def atomic_path(path):
    """Yield a temporary path beside ``path``, to be created exclusively (``open`` mode "x");
    moved to ``path`` when the block ends normally.

    The file is written under a unique temporary name in the same folder and
    renamed with :func:`os.replace`: a half-written file never sits under the
    real name (a full disk or an interrupt leave the previous version), and
    two writers never share a temporary. The temporary is removed on error.
    The name is reserved and freed again, so the writer creates the file: opened
    with truncation instead, ext4 writes a file out to the disk when it is
    closed (auto_da_alloc), which cost a run 10 ms a chunk.
    """
    path = os.fspath(path)
    folder, name = os.path.split(os.path.abspath(path))
    prefix, suffix = _temporary_name(name)
    fd, tmp = tempfile.mkstemp(prefix=prefix, suffix=suffix, dir=folder)
    os.close(fd)
    os.unlink(tmp)
    try:
        yield tmp
        os.replace(tmp, path)
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        raise


def output_directory(path, name="out"):
    """Create the output directory ``path`` (and its parents) and return it as a Path; a
    :class:`ParameterError` naming the parameter ``name`` says why it cannot be (a file
    in its place, no permission, a NUL in the name, an empty name), before anything is written."""
    if isinstance(path, str) and not path.strip():  # Path("") is the current directory: never meant
        raise ParameterError(f"`{name}` must name a directory, got {path!r}")
    try:
        path = Path(path)
        path.mkdir(parents=True, exist_ok=True)
    except (OSError, TypeError, ValueError) as exc:  # ValueError: a NUL in the path
        reason = getattr(exc, "strerror", None) or str(exc)
        if isinstance(exc, FileExistsError):
            reason = "a file of that name is in the way (give a directory)"
        raise ParameterError(f"cannot create the output directory `{name}` = {str(path)!r}: {reason}") from None
    return path


def refuse_directories(paths, name=None):
    """Raise a :class:`ParameterError` if one of ``paths``, where files are to be written,
    is a directory (renaming a finished file over it would fail only after the work);
    ``name``: the parameter that gave the path, if it was given whole."""
    for path in paths:
        if not isinstance(path, (str, os.PathLike)):
            raise ParameterError(f"`{name or 'path'}` must be a file name, got {path!r}")
        if os.path.isdir(path):
            given = f"`{name}` = " if name else ""
            raise ParameterError(f"{given}{str(path)!r} is a directory, where rodmol writes a file; "
                                 "remove it or choose another name")


#: How a call asks to replace an earlier output (the command line says ``--overwrite``).
OVERWRITE = "overwrite=True"


def kept(what, hint=OVERWRITE, other="name"):
    """The message of an earlier output kept: ``what`` (the output and what it holds) is kept
    unless the caller passes ``hint``."""
    return f"{what}: it is kept unless you pass {hint} to replace it (or choose another {other})"


def claim(paths, overwrite, hint=OVERWRITE, remove=True):
    """The one rule of every writer of files under names a user gave: unless ``overwrite``,
    refuse (a :class:`ParameterError` naming the first that exists, before any work is done)
    to replace any of ``paths``; with ``overwrite``, remove those that exist (unless not
    ``remove``: a single file written atomically replaces its old self), so that none of an
    earlier output is left beside the new one. A directory in the place of one is refused
    either way. Returns the paths (as Paths)."""
    refuse_directories(paths)
    paths = [Path(path) for path in paths]
    found = [path for path in paths if os.path.lexists(path)]
    if found and not overwrite:
        raise ParameterError(kept(f"{str(found[0])!r} exists", hint))
    for path in found if remove else ():
        path.unlink(missing_ok=True)
    return paths


def write_atomically(path, write, buffering=-1):
    """Call ``write(handle)`` on a binary file (``buffering`` as :func:`open`'s), then move it to
    ``path`` (see :func:`atomic_path`)."""
    with atomic_path(path) as tmp, open(tmp, "xb", buffering=buffering) as handle:
        write(handle)


def leftover_temporaries(pattern):
    """The temporaries :func:`atomic_path` made for the files matching ``pattern`` (a path
    whose name may hold glob wildcards) that were never moved to their names: what a
    killed writer leaves (they are leftovers only while no writer works in that folder)."""
    folder = Path(pattern).parent
    prefix, suffix = _temporary_name(Path(pattern).name)
    return sorted(folder.glob(f"{prefix}*{suffix}")) if folder.is_dir() else []
