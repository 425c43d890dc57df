"""The ``[[load]]`` tables of a scenario file: external loads (:mod:`rodmol.loads`).

Each table has a ``type`` (see :data:`~rodmol.scenario.schema.LOADS`) and
the keys of the Python class it builds. Point-load values are a 3-vector,
``[t, x, y, z]`` knots or a CSV file relative to the scenario file;
distributed loads take a constant 3-vector.
"""

from functools import partial

from .. import loads as rodmol_loads
from ..holds import HOLD_KINDS
from . import readers as read
from .arm import entries
from .problems import FAILED, failed
from .schema import LOAD_UNITS, LOADS

#: Readers of the keys every type shares the meaning of.
_READERS = {
    "s": read.number("non-negative", "m"),
    "frame": read.choice(rodmol_loads.FRAMES),
    "name": read.string,
    "point": read.vector(3, "m"),
    "normal": read.vector(3, "-"),
    "centre": read.vector(3, "m"),
    "start": read.vector(3, "m"),
    "end": read.vector(3, "m"),
    "radius": read.number("positive", "m"),
    "stiffness": read.number("positive", "N/m^2"),
    "damping": read.number("non-negative", "N s/m^2"),
    "friction": read.number("non-negative"),
    "slip_speed": read.number("positive", "m/s"),
    "smoothing_depth": read.number("positive", "m"),
    "kind": read.choice(HOLD_KINDS),
    "position": read.vector(3, "m"),
    "rotation": read.matrix3,
}


def load_kind(entry):
    """The valid ``type`` of a [[load]] table, or None."""
    kind = entry.get("type") if isinstance(entry, dict) else None
    return kind if isinstance(kind, str) and kind in LOADS else None


def loads(data, ctx):
    """The loads of the ``[[load]]`` tables, in order; FAILED if any has a problem."""
    tables = entries(data, ctx, "load")
    if tables is FAILED:
        return FAILED
    built = [_load(ctx, ("load", i), entry) for i, entry in enumerate(tables)]
    return FAILED if failed(*built) else built


def _load(ctx, path, entry):
    if not isinstance(entry, dict):
        ctx.add(path[:1], f"`load` must be an array of tables `[[load]]`, got {entry!r}")
        return FAILED
    if "type" not in entry:
        ctx.add(path, f"missing required key `type`; valid types: {', '.join(LOADS)}")
        return FAILED
    kind = ctx.read(entry, path, "type", read.choice(tuple(LOADS)))
    if kind is FAILED:
        return FAILED  # its keys depend on the type: they cannot be checked
    keys, required = LOADS[kind]
    build, units = rodmol_loads.SCENARIO_TYPES[kind][0], LOAD_UNITS[kind]
    what = "moment" if "moment" in keys else "force"
    point = getattr(build, "spread", None) == "point"
    table = ctx.table(entry, path, ("type",) + keys, required=required, units=units,
                      hint=f" (for `type = {kind!r}`)")
    readers = dict(_READERS)
    # A contact's law is per length of rod, a hold's at its node: the units come from the type.
    for key, condition in (("stiffness", "positive"), ("damping", "non-negative")):
        if key in keys:
            readers[key] = read.number(condition, units[key])
    if point:
        readers[what] = read.vector_input(ctx.base_dir, what, units[what])
    elif what in keys:
        readers[what] = read.constant_vector(units[what])
    values = {key: ctx.read(table, path, key, readers[key]) for key in keys if key in table}
    if failed(*values.values()) or any(key not in table for key in required):
        return FAILED
    return ctx.construct(path, table, partial(build, **values))
