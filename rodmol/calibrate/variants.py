"""Dotted overrides: one run's changes to a checked scenario (a RunSpec).

The keys are those of the scenario files (``docs/scenario-reference.md``),
and they apply to the built run, so they also change the paper's fixed arm:

* the numbers of ``[material]`` (``material.E``, ``material.nu``,
  ``material.G``, ``material.mu``, ``material.rho``; E keeps nu, so
  G = E / (2 (1 + nu)) follows it) and of ``[medium]`` (``medium.rho``,
  ``medium.Cx`` ...), the switches of ``[medium]`` (``medium.drag`` ...,
  true/false);
* ``discretization.n_elements``, ``discretization.scheme``; the keys of
  ``[solver]`` (``solver.t_end``, ``solver.rtol`` ...);
* ``tension.<cable>``: a tension input (number, knots, CSV path, TimeInput);
  ``tension.<cable>.scale`` [-] and ``tension.<cable>.offset`` [N]: the
  cable's tension becomes max(0, scale T(t) + offset). ``<cable>`` is the
  cable's name, or its number for the paper's arm (``tension.11.scale``).

A key may list several fields of one table, separated by commas, that take
one value: ``medium.Cy,Cz`` sets Cy = Cz (the paper's transverse drag).

A system's run (a :class:`rodmol.System`) names the part a key changes:
``rods.<rod>.material.E``, ``bodies.<body>.mass`` ...
(:mod:`rodmol.system_variants`); the run's keys (``[solver]``,
``discretization.scheme``) are as above. The Model's keys are
:mod:`rodmol.model_variants`'.
"""

import os
from dataclasses import replace

from .. import _checks, system_variants
from .. import model_variants as rod_variants
from ..discretise.schemes import DEFAULT_SCHEME, get_scheme
from ..errors import ParameterError
from ..model import Model
from ..model_variants import KEYS, RUN_KEYS, ScaledTension, expand, split_key  # noqa: F401 (also their home)
from ..run_spec import RunSpec
from ..systems import System


def as_spec(spec):
    """A RunSpec of one rod or of a system, or the RunSpec of a scenario file path."""
    if isinstance(spec, (str, os.PathLike)):
        from ..scenario.file import load_scenario

        spec = load_scenario(spec)
    if not isinstance(spec, RunSpec) or not isinstance(spec.model, (Model, System)):
        raise ParameterError(f"expected a scenario (rodmol.load_scenario(...), a RunSpec or a path), got {spec!r}")
    return spec


def spec_of(model, t_end, name="model", **solver):
    """A RunSpec for a model (a Model or a System) built in Python: run to
    ``t_end`` [s] with the options of :func:`rodmol.simulate` (``backend``,
    ``rtol``, ``output_dt`` ...)."""
    if not isinstance(model, (Model, System)):
        raise ParameterError(f"`model` must be a rodmol.Model or a rodmol.System, got {model!r}")
    return RunSpec(name, "", "<python>", model, _checks.positive("t_end", t_end, " s"), dict(solver))


def apply(spec, overrides):
    """The RunSpec with ``overrides`` ({dotted key: value}) applied; every key and
    value is checked first (a ParameterError names the key)."""
    spec = as_spec(spec)
    changes = expand(overrides)
    if not changes:
        return spec
    run = {k: v for k, v in changes.items() if k in RUN_KEYS}
    parts = {k: v for k, v in changes.items() if k not in RUN_KEYS}
    model = spec.model
    if parts:
        model = (system_variants.variant(model, parts) if isinstance(model, System)
                 else rod_variants.variant(model, parts))
    solver, t_end = dict(spec.solver), spec.t_end
    for key, value in run.items():
        name = key.partition(".")[2]
        if key == "discretization.scheme":
            solver["scheme"] = rod_variants.guard(key, value, lambda v=value: get_scheme(v).name)
        elif name == "t_end":
            t_end = rod_variants.guard(key, value, lambda v=value: _checks.positive("t_end", v, " s"))
        else:
            solver[name] = value if name in ("backend", "initial", "atol") else rod_variants.number(key, value)
    return replace(spec, model=model, t_end=t_end, solver=solver)


def current(spec, key):
    """The value the dotted ``key`` has in ``spec`` (the first field of a
    comma-joined key)."""
    spec = as_spec(spec)
    key = split_key(key)[0]
    if key == "discretization.scheme":
        return spec.solver.get("scheme", DEFAULT_SCHEME)
    if key == "solver.t_end":
        return spec.t_end
    if key in RUN_KEYS:
        return spec.solver.get(key.partition(".")[2])
    if isinstance(spec.model, System):
        return system_variants.value(spec.model, key)
    return rod_variants.value(spec.model, key)
