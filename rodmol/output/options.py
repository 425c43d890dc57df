"""What a run writes: :class:`OutputOptions`."""

import os
from dataclasses import dataclass

from .. import _checks
from ..errors import ParameterError
from .formats import DEFAULT, FORMATS
from .stream import CHUNK_FRAMES


@dataclass(frozen=True)
class OutputOptions:
    """What a run writes: ``directory`` (None: chosen by the caller), the
    ``format`` (a name from :data:`rodmol.output.formats.FORMATS`; ``"xdmf"``:
    streamed ``result.h5`` and XDMF views in chunks of ``chunk_frames``
    frames; ``"vtp"``: ``result.npz`` if ``npz`` and a .pvd series after the
    run), the ParaView views or series (``vtk``; every ``every``-th output
    frame, and the last; None: ``rodmol.output.parts.view_step``)."""

    directory: object = None
    format: str = DEFAULT
    vtk: bool = True
    npz: bool = True
    every: int = None
    chunk_frames: int = CHUNK_FRAMES

    def __post_init__(self):
        if self.directory is not None and not (isinstance(self.directory, (str, os.PathLike))
                                               and "\0" not in os.fspath(self.directory)):
            raise ParameterError(f"`directory` must be a path without NUL characters, got "
                                 f"{_checks.short(self.directory)}")
        _checks.choice("format", self.format, tuple(FORMATS))
        _checks.flag("vtk", self.vtk)
        _checks.flag("npz", self.npz)
        if self.every is not None:
            _checks.integer_at_least("every", self.every, 1)
        _checks.integer_at_least("chunk_frames", self.chunk_frames, 1)
