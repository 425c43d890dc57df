"""The arm's tables of a scenario file: ``[rod]``, ``[material]``, ``[medium]``,
``[[cable]]``, ``[[marker]]`` and ``[base]``.

Each table's keys are its constructor's parameters (:mod:`rodmol.scenario.tables`),
and its values are checked by that constructor. Each reader returns the rodmol
object (or the value) a table describes, or
:data:`~rodmol.scenario.problems.FAILED` once its problems are recorded.
"""

from dataclasses import asdict

from .. import _checks, scenarios
from ..arm import CABLE_OFFSETS
from ..base_motion import BaseMotion
from ..cables import Cable
from ..errors import ParameterError
from ..markers import Marker
from ..parameters import MEDIA, Material, Medium
from ..rod import Rod
from . import tables
from .problems import FAILED, failed, unique_names


def missing_table(data, ctx, key):
    """True (and a problem recorded) if the required table ``key`` is absent."""
    if key in data:
        return False
    ctx.add((), f"missing table `[{key}]` (or use the paper's arm: `arm = \"paper\"`)")
    return True


def values(table, ctx, path, data, keys=None):
    """The values of ``data`` for the constructor keys of ``table`` (or ``keys``),
    as the constructors take them; FAILED if one cannot be converted."""
    keys = table.parameters() if keys is None else keys
    found = {k: ctx.read(data, path, k, lambda v, k=k: tables.convert(k, v, ctx.base_dir))
             for k in keys if k in data}
    return FAILED if failed(*found.values()) else found


def build_table(data, ctx, path, table, build, extra=None, hint=""):
    """The object ``build`` makes of the table ``data``: keys checked against
    ``table`` (``hint`` ends the message of an unknown key), values converted and
    checked by ``build``; ``extra``: arguments that do not come from the file."""
    if not isinstance(data, dict):
        ctx.table(data, path, table)  # records that it is not a table
        return FAILED
    ctx.table(data, path, table, hint=hint)
    given = values(table, ctx, path, data)
    if given is FAILED:
        return FAILED
    missing = [k for k in table.required() if k not in data]
    return ctx.construct(path, build, {**given, **(extra or {})}, given=data, missing=missing)


def rod(data, ctx):
    """``[rod]`` with its ``[material]``."""
    body = FAILED if missing_table(data, ctx, "material") else build_table(
        data["material"], ctx, ("material",), tables.MATERIAL, Material)
    if missing_table(data, ctx, "rod"):
        return FAILED
    # An unusable material still lets the rod's own values be checked.
    stand_in = body if body is not FAILED else Material(1.0, 0.0, rho=1.0)
    built = build_table(data["rod"], ctx, ("rod",), tables.ROD, Rod, extra={"material": stand_in})
    return FAILED if failed(body) else built


def medium(data, ctx, default, at=()):
    """``medium = "water"`` or a ``[medium]`` table (in the table at path ``at``);
    returns (medium, Model switches)."""
    value = data.get("medium", default)
    path = at + ("medium",)
    if isinstance(value, str):
        return ctx.read({"medium": value}, at, "medium", Medium.preset), {}
    table = ctx.table(value, path, tables.MEDIUM)
    preset = ctx.read(table, path, "preset", Medium.preset, MEDIA["air"])
    coefficients = values(tables.MEDIUM, ctx, path, table, keys=tables.Source(Medium).parameters())
    switches = values(tables.MEDIUM, ctx, path, table, keys=tables.MODEL_SWITCHES)
    if failed(preset, coefficients, switches) or not isinstance(value, dict):
        return FAILED, {}
    fluid = ctx.construct(path, Medium, {**asdict(preset), **coefficients}, given=table)
    return fluid, switches


def entries(data, ctx, kind, at=()):
    """The list of ``[[kind]]`` tables (in the table at path ``at``), or FAILED
    (recorded) if ``kind`` is not one."""
    found = data.get(kind, [])
    if not isinstance(found, list):
        ctx.add(at + (kind,), f"`{kind}` must be an array of tables `[[{kind}]]`, got {found!r}")
        return FAILED
    return found


def numbered(data, ctx, kind, table, build, at=(), unique=False):
    """The objects of the ``[[kind]]`` tables (in the table at path ``at``); a
    nameless one is ``"kind K"``. ``unique``: names may not repeat (a repeat is
    a problem at the later table's name, naming the earlier)."""
    found = entries(data, ctx, kind, at)
    if found is FAILED:
        return FAILED
    built, named = [], []
    for i, entry in enumerate(found):
        name = {} if isinstance(entry, dict) and "name" in entry else {"name": f"{kind} {i + 1}"}
        built.append(build_table(entry, ctx, at + (kind, i), table, build, extra=name))
        name = entry.get("name") if isinstance(entry, dict) and "name" in entry else name["name"]
        if unique and isinstance(name, str):
            named.append((at + (kind, i), kind, name))
    kept = unique_names(ctx, named, rule=f"{kind} names must be unique (one without `name` is '{kind} K', "
                                         f"the K-th [[{kind}]])")
    return FAILED if failed(*built) or len(kept) < len(named) else built


def cables(data, ctx, at=()):
    """The ``[[cable]]`` tables of an arm written out in full."""
    return numbered(data, ctx, "cable", tables.CABLE, Cable, at, unique=True)


def markers(data, ctx, at=()):
    """The ``[[marker]]`` tables."""
    return numbered(data, ctx, "marker", tables.MARKER, Marker, at)


def paper_cables(data, ctx, scenario):
    """Tensions by cable number: the scenario's, replaced by the ``[[cable]]`` entries."""
    tensions = dict(scenarios.get(scenario).tensions) if scenario not in (None, FAILED) else {}
    found = entries(data, ctx, "cable")
    if found is FAILED:
        return FAILED
    hint = " (with `arm = \"paper\"`, a [[cable]] only sets the `tension` of cable `number` 1-12)"
    ok = True
    for i, entry in enumerate(found):
        path = ("cable", i)
        table = ctx.table(entry, path, tables.PAPER_CABLE, required=("number", "tension"), hint=hint)
        number = ctx.read(table, path, "number", _cable_number)
        tension = values(tables.PAPER_CABLE, ctx, path, table)
        if failed(number, tension) or "tension" not in table or number is None:
            ok = False
            continue
        cable = ctx.construct(path, lambda tension, number=number: Cable(
            CABLE_OFFSETS[number], 1.0, tension, name=f"cable {number}"), tension, given=table, keys=("tension",))
        ok = ok and not failed(cable)
        tensions[number] = getattr(cable, "tension", None)
    return tensions if ok else FAILED


def _cable_number(value):
    _checks.integer_at_least("number", value, 1)
    if value > len(CABLE_OFFSETS):
        raise ParameterError(f"`number` must be <= {len(CABLE_OFFSETS)}, got {value!r}")
    return value


def base(data, ctx, at=()):
    """``[base]``: a clamp, fixed or moving."""
    path, table = at + ("base",), data.get("base", {})
    fixed = ctx.read(table, path, "fixed", lambda v: _checks.flag("fixed", v), False) \
        if isinstance(table, dict) else False
    if fixed is True and ("velocity" in table or "angular_velocity" in table):
        ctx.add(path + ("fixed",), "`fixed = true` cannot be combined with `velocity` or "
                                   "`angular_velocity`")
    built = build_table(table, ctx, path, tables.BASE, BaseMotion)
    return FAILED if failed(fixed, built) or (fixed is True and not built.fixed) else built


def check_lengths(ctx, length, cables, markers, loads, at=()):
    """Anchors, markers and point loads beyond the tip, all of them (Model
    would stop at the first); ``at``: the path of the arm's table."""
    points = [(i, load) for i, load in enumerate(loads) if hasattr(load, "s")]
    for kind, items, key, value in (("cable", enumerate(cables), "anchor", lambda c: c.anchor),
                                    ("marker", enumerate(markers), "s", lambda m: m.s),
                                    ("load", points, "s", lambda p: p.s)):
        for i, item in items:
            if value(item) > length * (1 + 1e-12):
                ctx.add(at + (kind, i, key), f"`{key}` must lie within the rod, <= L = {length!r} m, "
                                             f"got {value(item)!r}")
