"""A run's description, :class:`RunSpec`: the model, the end time, the options
of :func:`rodmol.simulate` and the outputs. A scenario file gives one
(:func:`rodmol.load_scenario`), and so does ``rodmol.calibrate.variants.spec_of``
for a model built in Python."""

from dataclasses import dataclass, field

from .model import Model
from .output.options import OutputOptions
from .simulate import simulate


@dataclass(frozen=True)
class RunSpec:
    """A checked run: the model (a :class:`Model`, or a :class:`rodmol.System`
    from a system file), ``t_end`` [s], the options of :func:`rodmol.simulate`
    (``solver``) and the outputs."""

    name: str
    description: str
    source: str
    model: Model
    t_end: float
    solver: dict = field(default_factory=dict)
    output: OutputOptions = OutputOptions()

    def simulate(self, progress=None, **options):
        """Run it: :func:`rodmol.simulate` with this run's settings (and ``options``, e.g. ``out``)."""
        return simulate(self.model, self.t_end, progress=progress, **self.solver, **options)
