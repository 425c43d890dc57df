"""The ``[[load]]`` tables of a scenario file: external loads (:mod:`rodmol.loads`),
a rigid body's ``[[body.contact]]`` tables, its obstacles, and a system file's
``[[contact]]`` tables, rods touching a body (:class:`rodmol.Contact`).

Each table has a ``type`` (a key of :data:`rodmol.loads.SCENARIO_TYPES`) and
the arguments of the Python class it builds, checked by that class. Point-load
values are a 3-vector, ``[t, x, y, z]`` knots or a CSV file relative to the
scenario file; distributed loads take a constant 3-vector.
"""

import inspect

from .. import _checks
from ..contacts import Contact
from .arm import build_table, entries
from .problems import FAILED, failed
from .tables import BODY_CONTACTS, CONTACTS, LOADS, ROD_CONTACT_TYPE


def loads(data, ctx, at=()):
    """The loads of the ``[[load]]`` tables (in the table at path ``at``), in
    order; FAILED if any has a problem."""
    return _typed(data, ctx, at, "load", LOADS)


def contacts(data, ctx, at=()):
    """The obstacles of the ``[[contact]]`` tables of a body (the table at path
    ``at``): contact [[load]] types, their law per contact point; FAILED if any has a problem."""
    return _typed(data, ctx, at, "contact", BODY_CONTACTS)


def rod_contacts(data, ctx):
    """The :class:`rodmol.Contact` of a system file's ``[[contact]]`` tables: a
    ``body``, its ``rods`` and a contact [[load]] type's shape in the body frame;
    or, ``type = "rods"``, a :class:`rodmol.RodContact` (``a``, ``b`` and its
    law); FAILED if any has a problem."""
    return _typed(data, ctx, (), "contact", CONTACTS, _contact)


def _contact(table):
    """The builder of a [[contact]] table ``table``: its shape's keyword
    arguments (``table.sources[0]``) made the shape of a Contact; of rods touching
    rods, the :class:`rodmol.RodContact` itself."""
    if table is CONTACTS[ROD_CONTACT_TYPE]:
        return table.sources[0].build
    shape = table.sources[0].build

    def build(body, rods, **keys):
        return Contact(body, rods, shape(**keys))

    build.__signature__ = inspect.Signature([p.replace(kind=p.KEYWORD_ONLY) for p in table.parameters().values()])
    return build


def _typed(data, ctx, at, kind, types, builder=None):
    tables = entries(data, ctx, kind, at)
    if tables is FAILED:
        return FAILED
    built = [_load(ctx, at + (kind, i), entry, types, builder) for i, entry in enumerate(tables)]
    return FAILED if failed(*built) else built


def _load(ctx, path, entry, types, builder=None):
    kind = path[-2]
    if not isinstance(entry, dict):
        ctx.add(path[:-1], f"`{kind}` must be an array of tables `[[{kind}]]`, got {entry!r}")
        return FAILED
    if "type" not in entry:
        ctx.add(path, f"missing required key `type`; valid types: {', '.join(types)}")
        return FAILED
    name = ctx.read(entry, path, "type", lambda v: _checks.choice("type", v, tuple(types)))
    if name is FAILED:
        return FAILED  # its keys depend on the type: they cannot be checked
    table = types[name]
    build = table.sources[0].build if builder is None else builder(table)
    return build_table(entry, ctx, path, table, build, hint=f" (for `type = {name!r}`)")
