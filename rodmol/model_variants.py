"""A single rod's variants: its :class:`rodmol.Model` with dotted keys changed.

The keys are the scenario file's (:mod:`rodmol.scenario.tables`) that a
Model holds: the numbers of ``[material]`` and ``[medium]``, the switches of
``[medium]``, ``discretization.n_elements`` and ``tension.<cable>`` (with
``.scale`` and ``.offset``); the run's keys (``[solver]``, the scheme) are
applied by :mod:`rodmol.calibrate.variants`, and
:mod:`rodmol.system_variants` routes a system's ``rods.<name>.<key>`` here.
On the problem floor (it reads the Model's own classes, not the scenario
reader), so that :mod:`rodmol.named_parameters` and the runs below
calibration can rebuild a model at other parameter values.
"""

import inspect
import re
from dataclasses import fields, replace

from . import _checks
from .cables import Tension, as_tension
from .errors import ParameterError
from .inputs import TimeInput
from .model import Model
from .parameters import Material, Medium
from .rod import Rod

#: Model's keyword parameters set in the scenario's [medium] (the rest come from other tables).
MODEL_SWITCHES = ("drag", "added_mass", "munk_moment", "drag_law", "drag_coefficients")
#: simulate's keywords a scenario's [solver] table sets, in simulate's order.
SOLVER_KEYS = ("t_end", "initial", "backend", "rtol", "atol", "output_dt", "max_wall_time")
#: The numbers of [material] and [medium] (the dataclasses' float fields), the switches of [medium].
MATERIAL = tuple(f.name for f in fields(Material) if "float" in str(f.type))
MEDIUM = tuple(f.name for f in fields(Medium) if "float" in str(f.type))
SWITCHES = tuple(k for k, p in inspect.signature(Model).parameters.items()
                 if k in MODEL_SWITCHES and type(p.default) is bool)
#: The keys of a Model.
MODEL_KEYS = ([f"material.{k}" for k in MATERIAL] + [f"medium.{k}" for k in MEDIUM + SWITCHES]
              + ["discretization.n_elements", "tension.<cable>", "tension.<cable>.scale", "tension.<cable>.offset"])
#: The run's keys (a RunSpec's, of a rod or a system): the scheme and [solver]'s.
RUN_KEYS = ["discretization.scheme"] + [f"solver.{k}" for k in SOLVER_KEYS]
#: Every key of a single rod's run.
KEYS = MODEL_KEYS[:-3] + RUN_KEYS + MODEL_KEYS[-3:]


class ScaledTension(TimeInput):
    """``max(0, scale T(t) + offset)`` [N] of a tension input ``T``."""

    def __init__(self, signal, scale=1.0, offset=0.0):
        self.signal, self.scale, self.offset = signal, float(scale), float(offset)
        self.constant, self.source = signal.constant, f"scaled {signal.source}"

    def value(self, t):
        return max(0.0, self.scale * self.signal.value(t) + self.offset)

    def __repr__(self):
        return f"ScaledTension({self.signal!r}, scale={self.scale!r}, offset={self.offset!r})"


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


def is_key(key):
    """True if ``key`` (one field, split) names a Model's key (its cable unchecked)."""
    table, _, name = key.partition(".")
    return ((table == "material" and name in MATERIAL) or (table == "medium" and name in MEDIUM + SWITCHES)
            or key == "discretization.n_elements" or (table == "tension" and bool(name)))


def variant(model, changes, label=""):
    """The Model with ``changes`` ({key: value}, keys split) applied; each key
    and value checked first (a ParameterError names ``label`` + the key)."""
    groups = {"material": {}, "medium": {}, "switches": {}, "tension": {}}
    n_elements = model.n_elements
    for key, value in changes.items():
        table, _, name = key.partition(".")
        if table == "material" and name in MATERIAL:
            groups["material"][name] = number(label + key, value)
        elif table == "medium" and name in MEDIUM:
            groups["medium"][name] = number(label + key, value)
        elif table == "medium" and name in SWITCHES:
            groups["switches"][name] = boolean(label + key, value)
        elif key == "discretization.n_elements":
            n_elements = guard(label + key, value, lambda v=value: _checks.integer_at_least("n_elements", v, 2))
        elif table == "tension" and name:
            cable, what = _tension_key(model, label + key, name)
            groups["tension"].setdefault(cable, {})[what] = value
        else:
            raise unknown(label + key, [label + k for k in MODEL_KEYS] if label else KEYS)
    material = guard(label + "material." + ",".join(groups["material"]), groups["material"],
                     lambda: _material(model.rod.material, groups["material"]))
    medium = guard(label + "medium." + ",".join(groups["medium"]), groups["medium"],
                   lambda: Medium(**{**{k: getattr(model.medium, k) for k in MEDIUM}, **groups["medium"]}))
    cables = [_cable(c, groups["tension"].get(i), label) for i, c in enumerate(model.cables)]
    switches = {k: groups["switches"].get(k, getattr(model, k)) for k in SWITCHES}
    return guard(label.rstrip(".") or "overrides", changes, lambda: model.replace(
        rod=Rod(model.rod.length, model.rod.radius, material), n_elements=n_elements, medium=medium,
        cables=cables, **switches))


def value(model, key, label=""):
    """The value of the Model's ``key`` (one field)."""
    table, _, name = key.partition(".")
    if table == "material" and name in MATERIAL:
        return getattr(model.rod.material, name)
    if table == "medium" and name in MEDIUM:
        return getattr(model.medium, name)
    if table == "medium" and name in SWITCHES:
        return getattr(model, name)
    if key == "discretization.n_elements":
        return model.n_elements
    if table == "tension" and name:
        index, what = _tension_key(model, label + key, name)
        signal = getattr(model.cables[index].tension, "signal", None)
        if what in ("scale", "offset"):
            return getattr(signal, what, 1.0 if what == "scale" else 0.0)
        return model.cables[index].tension
    raise unknown(label + key, [label + k for k in MODEL_KEYS] if label else KEYS)


def unknown(key, valid, where=""):
    """The ParameterError of an unknown ``key``{``where``}: a near miss among ``valid``, and them all."""
    return ParameterError(f"unknown override {key!r}{where}{_checks.did_you_mean(key, valid)}; "
                          f"valid keys: {', '.join(valid)}")


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
    raise ParameterError(f"override {key!r}: no cable named {name!r}{_checks.did_you_mean(name, names)}; "
                         f"the cables are {names}")


def _cable(cable, change, label):
    if not change:
        return cable
    key = f"{label}tension.{cable.name}"
    tension = cable.tension
    if "input" in change:
        tension = guard(key, change["input"], lambda: as_tension(change["input"], key))
    if "scale" in change or "offset" in change:
        if not isinstance(tension, Tension) or tension.feedback:
            raise ParameterError(f"override {key}.scale/offset: the tension of cable {cable.name!r} is "
                                 "a feedback law, which cannot be scaled")
        scale = number(key + ".scale", change.get("scale", 1.0))
        offset = number(key + ".offset", change.get("offset", 0.0))
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


def number(key, value):
    """``value`` as a finite float; a ParameterError names the override ``key``."""
    return guard(key, value, lambda: _checks.finite(key, value))


def boolean(key, value):
    if not isinstance(value, bool):
        raise ParameterError(f"override {key!r} must be true or false, got {value!r}")
    return value


def guard(key, value, build):
    """``build()``, with a ParameterError prefixed by the override it came from."""
    try:
        return build()
    except ParameterError as exc:
        given = "" if isinstance(value, dict) else f" = {value!r}"
        raise ParameterError(f"override {key!r}{given}: {exc}") from None
