"""What a checked scenario file gives: a :class:`RunSpec` (the model, the
solver settings and the :class:`OutputOptions`), and :class:`Override`, a
command-line value that replaces the file's."""

from dataclasses import dataclass, field

from ..model import Model
from .stream import CHUNK_FRAMES

#: Output formats of a run: streamed XDMF3 + HDF5 (result.h5), or the VTK
#: .pvd/.vtp series and result.npz written after the run.
FORMATS = ("xdmf", "vtp")


@dataclass(frozen=True)
class OutputOptions:
    """What a run writes: ``directory`` (None: chosen by the caller), the
    ``format`` (``"xdmf"``: streamed ``result.h5`` and XDMF views in chunks
    of ``chunk_frames`` frames; ``"vtp"``: ``result.npz`` if ``npz`` and a
    .pvd series after the run), the ParaView views or series (``vtk``; every
    ``every``-th output frame, and the last; None: ``rodmol.io.parts.view_step``)."""

    directory: object = None
    format: str = "xdmf"
    vtk: bool = True
    npz: bool = True
    every: int = None
    chunk_frames: int = CHUNK_FRAMES


@dataclass(frozen=True)
class RunSpec:
    """A checked scenario: the model, ``t_end`` [s], the options of
    :func:`rodmol.simulate` (``solver``) and the outputs."""

    name: str
    description: str
    source: str
    model: Model
    t_end: float
    solver: dict = field(default_factory=dict)
    output: OutputOptions = OutputOptions()

    def simulate(self, progress=None, **options):
        """Run it: :func:`rodmol.simulate` with this scenario's settings (and ``options``, e.g. ``out``)."""
        from ..simulate import simulate

        return simulate(self.model, self.t_end, progress=progress, **self.solver, **options)


@dataclass(frozen=True)
class Override:
    """A value given on the command line, with the option's name for messages."""

    value: object
    label: str
