"""The arm's tables of a scenario file: ``[rod]``, ``[material]``, ``[medium]``,
``[[cable]]``, ``[[marker]]`` and ``[base]``.

Each reader returns the rodmol object (or the value) a table describes, or
:data:`~rodmol.scenario.problems.FAILED` once its problems are recorded.
"""

from functools import partial

import numpy as np

from .. import scenarios
from ..arm import CABLE_OFFSETS
from ..base_motion import BaseMotion
from ..cables import Cable
from ..inputs import Constant
from ..markers import Marker
from ..model import DRAG_LAWS
from ..parameters import MEDIA, Material, Medium
from ..rod import Rod
from . import readers as read
from .problems import FAILED, failed
from .schema import (
    BASE,
    CABLE,
    COEFFICIENTS,
    MARKER,
    MATERIAL,
    MATERIAL_REQUIRED,
    MEDIUM,
    PAPER_CABLE,
    ROD,
    SWITCHES,
)


def missing_table(data, ctx, key):
    """True (and a problem recorded) if the required table ``key`` is absent."""
    if key in data:
        return False
    ctx.add((), f"missing table `[{key}]` (or use the paper's arm: `arm = \"paper\"`)")
    return True


#: Stand-ins for the other values when a [material] value is checked alone.
_PLACEHOLDER = {"E": 1.0, "nu": 0.0, "mu": 0.0, "rho": 1.0}


def material(data, ctx):
    """``[material]``: E, mu, rho and exactly one of nu and G."""
    if missing_table(data, ctx, "material"):
        return FAILED
    path = ("material",)
    table = ctx.table(data["material"], path, MATERIAL, required=MATERIAL_REQUIRED)
    values = {k: ctx.read(table, path, k, read.component_viscosity if k == "viscosity" else read.number())
              for k in MATERIAL if k in table}
    elastic = [k for k in ("nu", "G") if k in table]
    if not isinstance(data["material"], dict):
        return FAILED  # recorded by ctx.table
    if not elastic:
        ctx.add(path, "missing required key `nu` (Poisson ratio [-]), or give the shear modulus `G` [Pa]")
    elif len(elastic) == 2:
        ctx.add(path + ("G",), "give either `nu` (Poisson ratio) or `G` (shear modulus [Pa]), not both")
    complete = all(k in values for k in MATERIAL_REQUIRED) and len(elastic) == 1
    if not complete or failed(*values.values()):
        # Check each given value alone (the others set to placeholders) to report them all.
        for key, value in values.items():
            if value is not FAILED:
                others = {k: v for k, v in _PLACEHOLDER.items() if not (key == "G" and k == "nu")}
                ctx.construct(path, {key: value}, partial(Material, **{**others, key: value}))
        return FAILED
    return ctx.construct(path, table, lambda: Material(**values))


def rod(data, ctx):
    """``[rod]`` with its ``[material]``."""
    body = material(data, ctx)
    path = ("rod",)
    if missing_table(data, ctx, "rod"):
        return FAILED
    table = ctx.table(data["rod"], path, ROD, required=ROD)
    length = ctx.read(table, path, "length", read.number("positive", "m"))
    radius = ctx.read(table, path, "radius", read.radius(length))
    if failed(body, length, radius) or length is None or radius is None:
        return FAILED
    return ctx.construct(path, table, lambda: Rod(length, radius, body))


def medium(data, ctx, default):
    """``medium = "water"`` or a ``[medium]`` table; returns (medium, Model switches)."""
    value = data.get("medium", default)
    path = ("medium",)
    if isinstance(value, str):
        return ctx.read({"medium": value}, (), "medium", lambda v: read.choice(tuple(MEDIA))(v)), {}
    table = ctx.table(value, path, MEDIUM)
    preset = ctx.read(table, path, "preset", read.choice(tuple(MEDIA)), "air")
    coefficients = {k: ctx.read(table, path, k, read.number("non-negative"))
                    for k in COEFFICIENTS if k in table}
    switches = {k: ctx.read(table, path, k, read.boolean) for k in SWITCHES if k in table}
    if "drag_law" in table:
        switches["drag_law"] = ctx.read(table, path, "drag_law", read.choice(DRAG_LAWS))
    if "drag_coefficients" in table:
        switches["drag_coefficients"] = ctx.read(table, path, "drag_coefficients", read.vector(3, "kg/m^2"))
    if failed(preset, *coefficients.values(), *switches.values()) or not isinstance(value, dict):
        return FAILED, {}
    start = {k: getattr(MEDIA[preset], k) for k in COEFFICIENTS}
    fluid = ctx.construct(path, table, lambda: Medium(**{**start, **coefficients}))
    return fluid, switches


def entries(data, ctx, kind):
    """The list of ``[[kind]]`` tables, or FAILED (recorded) if ``kind`` is not one."""
    found = data.get(kind, [])
    if not isinstance(found, list):
        ctx.add((kind,), f"`{kind}` must be an array of tables `[[{kind}]]`, got {found!r}")
        return FAILED
    return found


def cables(data, ctx):
    """The ``[[cable]]`` tables of an arm written out in full."""
    tables = entries(data, ctx, "cable")
    if tables is FAILED:
        return FAILED
    built, names = [], {}
    for i, entry in enumerate(tables):
        path = ("cable", i)
        table = ctx.table(entry, path, CABLE, required=("offset", "anchor"))
        name = ctx.read(table, path, "name", read.string, f"cable {i + 1}")
        if name in names:
            ctx.add(path + ("name",), f"`name` {name!r} is already used by [[cable]] #{names[name] + 1}")
        names.setdefault(name, i)
        offset = ctx.read(table, path, "offset", read.offset)
        anchor = ctx.read(table, path, "anchor", read.number("positive", "m"))
        tension = ctx.read(table, path, "tension", read.tension(ctx.base_dir, name))
        options = {k: ctx.read(table, path, k, reader) for k, reader in _cable_options(ctx, name).items()
                   if k in table}
        if failed(name, offset, anchor, tension, *options.values()) or offset is None or anchor is None:
            built.append(FAILED)
            continue
        built.append(ctx.construct(path, table, partial(Cable, offset, anchor, tension, name=name, **options)))
    return FAILED if failed(*built) else built


def _cable_options(ctx, name):
    """Readers of the optional [[cable]] keys (routing on spacer disks,
    displacement control, friction)."""
    return {"outside_body": read.boolean, "displacement": read.displacement(ctx.base_dir, name),
            "compliance": read.number("positive", "1/N"), "base_to_actuator": read.number("non-negative", "m"),
            "rest_length": read.number("positive", "m"), "friction": read.number("non-negative"),
            "slip_speed": read.number("positive", "m/s")}


def paper_cables(data, ctx, scenario):
    """Tensions by cable number: the scenario's, replaced by the ``[[cable]]`` entries."""
    tensions = dict(scenarios.get(scenario).tensions) if scenario not in (None, FAILED) else {}
    tables = entries(data, ctx, "cable")
    if tables is FAILED:
        return FAILED
    hint = " (with `arm = \"paper\"`, a [[cable]] only sets the `tension` of cable `number` 1-12)"
    ok = True
    for i, entry in enumerate(tables):
        path = ("cable", i)
        table = ctx.table(entry, path, PAPER_CABLE, required=PAPER_CABLE, hint=hint)
        number = ctx.read(table, path, "number", read.integer(1, maximum=len(CABLE_OFFSETS)))
        tension = ctx.read(table, path, "tension", read.tension(ctx.base_dir, f"cable {number}"))
        if failed(number, tension) or number is None or tension is None:
            ok = False
        else:
            tensions[number] = tension
    return tensions if ok else FAILED


def markers(data, ctx):
    """The ``[[marker]]`` tables."""
    tables = entries(data, ctx, "marker")
    if tables is FAILED:
        return FAILED
    built = []
    for i, entry in enumerate(tables):
        path = ("marker", i)
        table = ctx.table(entry, path, MARKER, required=("s",))
        name = ctx.read(table, path, "name", read.string, f"marker {i + 1}")
        s = ctx.read(table, path, "s", read.number("non-negative", "m"))
        offset = ctx.read(table, path, "offset", read.vector(2, "m"))
        if failed(name, s, offset) or s is None:
            built.append(FAILED)
            continue
        built.append(ctx.construct(path, table, partial(Marker, s, offset, name)))
    return FAILED if failed(*built) else built


def _constant(vector):
    # A bound method of a constant input, not a closure, so that the model pickles.
    return Constant(vector, 3).value


def base(data, ctx):
    """``[base]``: a clamp, fixed or moving at constant velocities."""
    path = ("base",)
    table = ctx.table(data.get("base", {}), path, BASE)
    fixed = ctx.read(table, path, "fixed", read.boolean, False)
    position = ctx.read(table, path, "position", read.vector(3, "m"), (0.0, 0.0, 0.0))
    rotation = ctx.read(table, path, "rotation", read.matrix3, tuple(map(tuple, np.eye(3))))
    velocity = ctx.read(table, path, "velocity", read.vector(3, "m/s"))
    angular = ctx.read(table, path, "angular_velocity", read.vector(3, "rad/s"))
    if fixed is True and (velocity is not None or angular is not None):
        ctx.add(path + ("fixed",), "`fixed = true` cannot be combined with `velocity` or "
                                   "`angular_velocity`")
        return FAILED
    if failed(fixed, position, rotation, velocity, angular):
        return FAILED
    return ctx.construct(path, table, lambda: BaseMotion(
        None if velocity is None else _constant(np.array(velocity)),
        None if angular is None else _constant(np.array(angular)), position, rotation))
