"""What :func:`rodmol.simulate` does differently for each kind of model, in one table: one
rod (:class:`rodmol.Model`) and a system of rods and rigid bodies (:class:`rodmol.System`).

Everything else about a run (the checks, resuming, the output times, the tolerances, the
initial state, the backends of :data:`rodmol.solve.backends.BACKENDS`, the chunked run into a
sink, the report of a failure) is one path for both, in :mod:`rodmol.simulate`. A new kind of
model is one more :class:`RunKind` in :data:`KINDS`; its discretised system is a
:class:`rodmol.discretise.protocol.Discretised` (what that path and every backend read), and
:func:`rodmol.solve.equilibrium.equilibrium` takes it.
"""

from dataclasses import dataclass

from . import run_sinks
from .discretise.assembly import Assembly
from .discretise.system import SemiDiscrete
from .errors import ParameterError
from .model import Model
from .result import Result, from_states
from .solve import kernels
from .solve.scales import check_scales
from .system_result import SystemResult
from .systems import System


@dataclass(frozen=True)
class RunKind:
    """How a run of one kind of model differs from the others'."""

    #: The user's model (the problem floor's noun).
    model: type
    #: ``(model, scheme)`` -> its discretised system (a ``Discretised``), built once per run.
    discretise: object
    #: ``initial=None``: "equilibrium" (the paper's choice) or "straight" (from rest).
    default_initial: str
    #: ``(system, t, states, success, message, stats)`` -> the run's result.
    result: object
    #: An earlier run's result, taken as ``initial`` (its last state).
    results: type
    #: ``(directory, resume=, overwrite=)`` -> the sink of ``out=DIR`` (:mod:`rodmol.run_sinks`).
    directory_sink: object
    #: ``(system, t, y, run, rtol, atol, options)``: the compiled kernels made ready before the
    #: run, by a run of a microsecond (:mod:`rodmol.solve.kernels`); None: in the first step.
    prepare: object = None


def _prepare_rod(system, t, y, run, rtol, atol, options):
    check_scales(system, t, atol)  # before the kernels' first run, which would fail on them
    kernels.prepare(system, t, y, run, rtol, atol, options)


KINDS = (
    RunKind(Model, SemiDiscrete, "equilibrium", from_states, Result, run_sinks.directory_sink, _prepare_rod),
    RunKind(System, Assembly, "straight", SystemResult, SystemResult, run_sinks.system_writer),
)


def run_kind(model):
    """The :class:`RunKind` of ``model``; anything else is refused naming the kinds."""
    for kind in KINDS:
        if isinstance(model, kind.model):
            return kind
    names = " or ".join(f"rodmol.{kind.model.__name__}" for kind in KINDS)
    raise ParameterError(f"`model` must be a {names}, got {model!r}")
