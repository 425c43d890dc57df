"""The output formats: one table, :data:`FORMATS`, that every writer and reader looks up.

:func:`write_series` (``rodmol.write_series``), the command line's ``--format``,
the scenario file's ``[output] format`` and :func:`load_result` all read it.
A format is one :class:`Format` entry pointing into its own module:

* ``"xdmf"`` (:mod:`rodmol.output.stream`): ``result.h5`` and the XDMF views,
  streamed while the run goes;
* ``"vtp"`` (:mod:`rodmol.output.writers`, :mod:`rodmol.output.npz`):
  ``result.npz`` and the ``.pvd``/``.vtp`` series, written after the run.

Adding a format is its module and its entry here (and its files in
:data:`rodmol.output.run_files.TOP`, so that a replaced run leaves none behind).
"""

import os
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from .._checks import did_you_mean
from .._files import output_directory
from ..errors import ParameterError
from ..system_result import SystemResult
from . import (
    h5result,
    npz,
    run_files,
    stream,
    system_files,
    system_stream,  # (also registers the sink of a System's out=DIR)
    writers,
)


@dataclass(frozen=True)
class Format:
    """One output format.

    name : str
        Its name (``--format``, ``[output] format``, ``write_series(format=...)``).
    summary : str
        What it writes, for the command line's help.
    result_file : str
        The file in a run directory that holds the whole Result.
    read : callable
        ``read(path)``: the :class:`rodmol.Result` of that file.
    write : callable
        ``write(result, directory, every)``: write a finished Result into ``directory``,
        which :func:`write_series` has cleared (or found free); returns the path to open
        in ParaView.
    sink : callable or None
        Streams while the run goes: ``sink(directory, views=, every=, chunk_frames=,
        resume=, meta=)`` gives the frame sink of :func:`rodmol.simulate` (its
        ``directory`` and ``seconds`` the time spent writing). None: written after the run by
        ``write_run(result, options, directory, stopped)`` (``options``:
        :class:`rodmol.output.options.OutputOptions`; ``stopped()`` True ends the writing
        between frames; returns what :func:`rodmol.cli.commands.summary` lists), once
        ``before_run(directory, options)`` refused what would be in the way.
    """

    name: str
    summary: str
    result_file: str
    read: Callable
    write: Callable
    sink: Callable = None
    write_run: Callable = None
    before_run: Callable = None


FORMATS = {f.name: f for f in (
    Format("xdmf", "streamed result.h5 and XDMF views", h5result.INDEX, h5result.read_result,
           stream.write_xdmf, sink=stream.RunWriter),
    Format("vtp", "result.npz and a .pvd/.vtp series after the run", run_files.NPZ, npz.read_npz,
           writers.write_vtp, write_run=writers.write_run, before_run=writers.before_run),
)}
#: The format of a run unless another is asked for.
DEFAULT = "xdmf"


def get_format(name, what="format"):
    """The :class:`Format` called ``name``; a ParameterError names the known ones."""
    if not (isinstance(name, str) and name in FORMATS):
        raise ParameterError(f"unknown `{what}` {name!r}{did_you_mean(name, FORMATS)}; use "
                             + " or ".join(repr(n) for n in FORMATS))
    return FORMATS[name]


def write_series(result, directory, every=None, format=DEFAULT, overwrite=False):
    """Write a finished :class:`rodmol.Result` (or a system's ``SystemResult``:
    :func:`rodmol.output.system_stream.write_system`) for ParaView into ``directory``.

    ``format="xdmf"`` (default): ``result.h5`` and the XDMF views
    (:class:`rodmol.output.stream.RunWriter`), returns the path of ``rod.xdmf``;
    ``"vtp"``: ``result.npz`` and the ``.pvd``/``.vtp`` series, returns the
    path of ``rod.pvd`` (:data:`FORMATS`). Either directory is read back by
    :func:`rodmol.load_result`, ``rodmol render`` and ``rodmol plot``.
    ``every``: show every n-th output frame (and the last); by default all
    of them up to :data:`rodmol.output.parts.MAX_SHOWN` frames.
    An earlier run in ``directory`` (a rod's or a system's, any format) is kept: refused
    with a ParameterError unless ``overwrite=True``, which removes all of its files first
    (:func:`rodmol.output.run_files.claim`).
    """
    entry = get_format(format)
    system = isinstance(result, SystemResult)
    if system and entry.name != "xdmf":
        raise ParameterError(f"a system's result is written as 'xdmf' only, got `format` {format!r}")
    directory = output_directory(directory, "directory")
    run_files.claim(directory, overwrite)
    if system:  # each rod's files as a single rod's, the bodies', the index
        return system_stream.write_system(result, directory, every)
    return entry.write(result, directory, every)


def result_file(path):
    """The result file of ``path``: itself, or for a run directory or one of its
    views the directory's result file (``result.h5``, else ``result.npz``: :data:`FORMATS`' order)."""
    path = Path(path)
    if path.is_dir() or path.suffix == ".xdmf":
        folder = path if path.is_dir() else path.parent
        if system_files.is_system(folder):
            return folder / system_files.INDEX
        names = [f.result_file for f in FORMATS.values()]
        found = [folder / name for name in names if (folder / name).is_file()]
        if not found:
            raise FileNotFoundError(f"no {' or '.join(names)} in {str(folder)!r}")
        return found[0]
    return path


def load_result(path):
    """Read a :class:`Result`, or a :class:`SystemResult` from a system's run directory
    (:mod:`rodmol.output.system_files`): a run directory (its ``result.h5``, else ``result.npz``), a
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
    if system_files.is_system(path):
        return system_files.read_system(path.parent)
    by_suffix = {Path(f.result_file).suffix: f for f in FORMATS.values()}
    # Any other name is a file of Result.save, which writes the vtp format's result.npz.
    return by_suffix.get(path.suffix, FORMATS["vtp"]).read(path)
