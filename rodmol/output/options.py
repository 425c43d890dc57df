"""What a run writes: :class:`OutputOptions`."""

from dataclasses import dataclass

from .formats import DEFAULT
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
