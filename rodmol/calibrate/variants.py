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
"""

import os
import re
from dataclasses import replace

from .. import _checks
from ..cables import Tension, as_tension
from ..discretise.schemes import DEFAULT_SCHEME, get_scheme
from ..errors import NotSupportedYet, ParameterError
from ..inputs import TimeInput
from ..model import Model
from ..parameters import Material, Medium
from ..rod import Rod
from ..run_spec import RunSpec
from ..scenario import tables

# The keys are the scenario file's (rodmol.scenario.tables): the numbers of
# [material] and [medium], the switches of [medium], [discretization] and [solver].
MATERIAL = tables.MATERIAL.numbers()
MEDIUM = tables.MEDIUM.numbers()
SWITCHES = tables.MEDIUM.switches()
SOLVER = tables.SOLVER.names()
KEYS = ([f"material.{k}" for k in MATERIAL] + [f"medium.{k}" for k in MEDIUM + SWITCHES]
        + [f"discretization.{k}" for k in tables.DISCRETIZATION.names()] + [f"solver.{k}" for k in SOLVER]
        + ["tension.<cable>", "tension.<cable>.scale", "tension.<cable>.offset"])


class ScaledTension(TimeInput):
    """``max(0, scale T(t) + offset)`` [N] of a tension input ``T``."""

    def __init__(self, signal, scale=1.0, offset=0.0):
        self.signal, self.scale, self.offset = signal, float(scale), float(offset)
        self.constant, self.source = signal.constant, f"scaled {signal.source}"

    def value(self, t):
        return max(0.0, self.scale * self.signal.value(t) + self.offset)

    def __repr__(self):
        return f"ScaledTension({self.signal!r}, scale={self.scale!r}, offset={self.offset!r})"


def as_spec(spec):
    """A RunSpec of one rod, or the RunSpec of a scenario file path (a system's is
    refused: NotSupportedYet)."""
    if isinstance(spec, (str, os.PathLike)):
        from ..scenario.file import load_scenario

        spec = load_scenario(spec)
    if not isinstance(spec, RunSpec):
        raise ParameterError(f"expected a scenario (rodmol.load_scenario(...), a RunSpec or a path), got {spec!r}")
    if not isinstance(spec.model, Model):
        raise NotSupportedYet(f"{spec.source}: variants and calibration of a system (several rods and bodies) "
                              "are not supported yet: they take a single rod's scenario")
    return spec


def spec_of(model, t_end, name="model", **solver):
    """A RunSpec for a model built in Python: run to ``t_end`` [s] with the
    options of :func:`rodmol.simulate` (``backend``, ``rtol``, ``output_dt`` ...)."""
    if not isinstance(model, Model):
        raise ParameterError(f"`model` must be a rodmol.Model, got {model!r}")
    return RunSpec(name, "", "<python>", model, _checks.positive("t_end", t_end, " s"), dict(solver))


def expand(overrides):
    """{key: value} with comma-joined keys split: ``medium.Cy,Cz`` -> Cy and Cz."""
    out = {}
    for key, value in dict(overrides or {}).items():
        for one in split_key(key):
            out[one] = value
    return out


def split_key(key):
    """``"medium.Cy,Cz"`` -> ``["medium.Cy", "medium.Cz"]``."""
    if not isinstance(key, str) or not key:
        raise ParameterError(f"an override key must be a dotted name such as 'material.E', got {key!r}")
    first, *more = key.split(",")
    table = first.rsplit(".", 1)[0] if "." in first else ""
    return [first] + [k if "." in k else f"{table}.{k}" for k in (m.strip() for m in more)]


def apply(spec, overrides):
    """The RunSpec with ``overrides`` ({dotted key: value}) applied; every key and
    value is checked first (a ParameterError names the key)."""
    spec = as_spec(spec)
    changes = expand(overrides)
    if not changes:
        return spec
    model = spec.model
    groups = {"material": {}, "medium": {}, "switches": {}, "solver": {}, "tension": {}}
    n_elements = model.n_elements
    for key, value in changes.items():
        table, _, name = key.partition(".")
        if table == "material" and name in MATERIAL:
            groups["material"][name] = _number(key, value)
        elif table == "medium" and name in MEDIUM:
            groups["medium"][name] = _number(key, value)
        elif table == "medium" and name in SWITCHES:
            groups["switches"][name] = _boolean(key, value)
        elif key == "discretization.n_elements":
            n_elements = _guard(key, value, lambda v=value: _checks.integer_at_least("n_elements", v, 2))
        elif key == "discretization.scheme":
            groups["solver"]["scheme"] = _guard(key, value, lambda v=value: get_scheme(v).name)
        elif table == "solver" and name in SOLVER:
            groups["solver"][name] = value if name in ("backend", "initial", "atol") else _number(key, value)
        elif table == "tension" and name:
            cable, what = _tension_key(model, key, name)
            groups["tension"].setdefault(cable, {})[what] = value
        else:
            raise ParameterError(f"unknown override {key!r}; valid keys: {', '.join(KEYS)}")
    material = _guard("material." + ",".join(groups["material"]), groups["material"],
                      lambda: _material(model.rod.material, groups["material"]))
    medium = _guard("medium." + ",".join(groups["medium"]), groups["medium"],
                    lambda: Medium(**{**{k: getattr(model.medium, k) for k in MEDIUM}, **groups["medium"]}))
    cables = [_cable(c, groups["tension"].get(i)) for i, c in enumerate(model.cables)]
    switches = {k: groups["switches"].get(k, getattr(model, k)) for k in SWITCHES}
    new_model = _guard("overrides", changes, lambda: model.replace(
        rod=Rod(model.rod.length, model.rod.radius, material), n_elements=n_elements, medium=medium,
        cables=cables, **switches))
    solver = dict(spec.solver)
    t_end = spec.t_end
    for name, value in groups["solver"].items():
        if name == "t_end":
            t_end = _guard("solver.t_end", value, lambda v=value: _checks.positive("t_end", v, " s"))
        else:
            solver[name] = value
    return replace(spec, model=new_model, t_end=t_end, solver=solver)


def current(spec, key):
    """The value the dotted ``key`` has in ``spec`` (the first field of a
    comma-joined key)."""
    spec = as_spec(spec)
    key = split_key(key)[0]
    table, _, name = key.partition(".")
    model = spec.model
    if table == "material" and name in MATERIAL:
        return getattr(model.rod.material, name)
    if table == "medium" and name in MEDIUM:
        return getattr(model.medium, name)
    if table == "medium" and name in SWITCHES:
        return getattr(model, name)
    if key == "discretization.n_elements":
        return model.n_elements
    if key == "discretization.scheme":
        return spec.solver.get("scheme", DEFAULT_SCHEME)
    if key == "solver.t_end":
        return spec.t_end
    if table == "solver" and name in SOLVER:
        return spec.solver.get(name)
    if table == "tension" and name:
        index, what = _tension_key(model, key, name)
        signal = getattr(model.cables[index].tension, "signal", None)
        if what in ("scale", "offset"):
            return getattr(signal, what, 1.0 if what == "scale" else 0.0)
        return model.cables[index].tension
    raise ParameterError(f"unknown override {key!r}; valid keys: {', '.join(KEYS)}")


def _tension_key(model, key, name):
    """(cable index, "input" | "scale" | "offset") of a ``tension.`` key."""
    what = "input"
    for suffix in ("scale", "offset"):
        if name.endswith("." + suffix):
            name, what = name[: -len(suffix) - 1], suffix
    names = [c.name for c in model.cables]
    if name in names:
        return names.index(name), what
    number = re.fullmatch(r"[Tt]?(\d+)", name)
    if number and f"cable {number.group(1)}" in names:
        return names.index(f"cable {number.group(1)}"), what
    raise ParameterError(f"override {key!r}: no cable named {name!r}; the cables are {names}")


def _cable(cable, change):
    if not change:
        return cable
    label = f"tension.{cable.name}"
    tension = cable.tension
    if "input" in change:
        tension = _guard(label, change["input"], lambda: as_tension(change["input"], f"{label}"))
    if "scale" in change or "offset" in change:
        if not isinstance(tension, Tension) or tension.feedback:
            raise ParameterError(f"override {label}.scale/offset: the tension of cable {cable.name!r} is "
                                 "a feedback law, which cannot be scaled")
        scale = _number(label + ".scale", change.get("scale", 1.0))
        offset = _number(label + ".offset", change.get("offset", 0.0))
        signal = tension.signal
        if isinstance(signal, ScaledTension):  # scale the original, not a scaled copy
            signal = signal.signal
        tension = Tension(ScaledTension(signal, scale, offset))
    return replace(cable, tension=tension)


def _material(material, changes):
    values = {k: changes.get(k, getattr(material, k)) for k in ("E", "mu", "rho")}
    if "G" in changes and "nu" in changes:
        raise ParameterError("give either `material.nu` or `material.G`, not both")
    values["viscosity"] = material.viscosity
    if "G" in changes:
        return Material(**values, G=changes["G"])
    return Material(**values, nu=changes.get("nu", material.nu))


def _number(key, value):
    return _guard(key, value, lambda: _checks.finite(key, value))


def _boolean(key, value):
    if not isinstance(value, bool):
        raise ParameterError(f"override {key!r} must be true or false, got {value!r}")
    return value


def _guard(key, value, build):
    """``build()``, with a ParameterError prefixed by the override it came from."""
    try:
        return build()
    except ParameterError as exc:
        given = "" if isinstance(value, dict) else f" = {value!r}"
        raise ParameterError(f"override {key!r}{given}: {exc}") from None
