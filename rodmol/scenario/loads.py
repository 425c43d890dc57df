"""The ``[[load]]`` tables of a scenario file: external loads (:mod:`rodmol.loads`).

Each table has a ``type`` (a key of :data:`rodmol.loads.SCENARIO_TYPES`) and
the arguments of the Python class it builds, checked by that class. Point-load
values are a 3-vector, ``[t, x, y, z]`` knots or a CSV file relative to the
scenario file; distributed loads take a constant 3-vector.
"""

from .. import _checks
from .arm import build_table, entries
from .problems import FAILED, failed
from .tables import LOADS


def loads(data, ctx, at=()):
    """The loads of the ``[[load]]`` tables (in the table at path ``at``), in
    order; FAILED if any has a problem."""
    tables = entries(data, ctx, "load", at)
    if tables is FAILED:
        return FAILED
    built = [_load(ctx, at + ("load", i), entry) for i, entry in enumerate(tables)]
    return FAILED if failed(*built) else built


def _load(ctx, path, entry):
    if not isinstance(entry, dict):
        ctx.add(path[:-1], f"`load` must be an array of tables `[[load]]`, got {entry!r}")
        return FAILED
    if "type" not in entry:
        ctx.add(path, f"missing required key `type`; valid types: {', '.join(LOADS)}")
        return FAILED
    kind = ctx.read(entry, path, "type", lambda v: _checks.choice("type", v, tuple(LOADS)))
    if kind is FAILED:
        return FAILED  # its keys depend on the type: they cannot be checked
    table = LOADS[kind]
    return build_table(entry, ctx, path, table, table.sources[0].build, hint=f" (for `type = {kind!r}`)")
