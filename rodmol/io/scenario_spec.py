"""What a checked scenario file gives: a :class:`RunSpec` (the model, the
solver settings and the :class:`OutputOptions`), and :class:`Override`, a
command-line value that replaces the file's."""

from dataclasses import dataclass, field

from ..model import Model


@dataclass(frozen=True)
class OutputOptions:
    """What a run writes: ``directory`` (None: chosen by the caller), the VTK
    series (every ``every``-th output frame, and the last), and ``result.npz``."""

    directory: object = None
    vtk: bool = True
    npz: bool = True
    every: int = 1


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

    def simulate(self, progress=None):
        """Run it: :func:`rodmol.simulate` with this scenario's settings."""
        from ..simulate import simulate

        return simulate(self.model, self.t_end, progress=progress, **self.solver)


@dataclass(frozen=True)
class Override:
    """A value given on the command line, with the option's name for messages."""

    value: object
    label: str
