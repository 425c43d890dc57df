"""A system file: several rods, rigid bodies and joints (:class:`rodmol.System`).

A file is a system file if it has ``[[rod]]`` (an array of tables) or one of
``[system]``, ``[[body]]``, ``[[joint]]``. Each ``[[rod]]`` holds a rod's
keys (``[rod]``'s), its ``name`` and ``n_elements`` (default
``[discretization]``'s) and its own tables nested: ``[rod.material]``,
``[[rod.cable]]``, ``[[rod.marker]]``, ``[[rod.load]]``, ``[rod.base]``, read
by the single-rod readers (:mod:`rodmol.scenario.arm`,
:mod:`rodmol.scenario.loads`) at the entry's path; ``[[contact]]`` tables
are rods touching a body (:class:`rodmol.Contact`, the shape as a contact
``[[load]]`` in the body frame). ``[system]`` gives the
medium (a preset name or a ``[system.medium]`` table, whose switches apply to
every rod) and gravity. The tables' keys come from the constructors
(:mod:`rodmol.scenario.tables`).
"""

import re

from .. import _checks
from ..base_motion import BaseMotion
from ..bodies import RigidBody
from ..errors import ParameterError
from ..model import Model
from ..parameters import Material
from ..rod import Rod
from ..systems import Joint, System
from . import arm as arm_tables
from . import tables
from .loads import contacts as contact_tables
from .loads import loads as load_tables
from .loads import rod_contacts
from .problems import FAILED, FOLLOWS, failed, unique_names

#: Top-level keys and tables of a single-rod file, and where a system file has them instead.
SINGLE_ROD_KEYS = {"arm": "a [[rod]] written out in full", "scenario": "Python (rodmol.scenarios)",
                   "material": "[rod.material]", "cable": "[[rod.cable]]", "marker": "[[rod.marker]]",
                   "load": "[[rod.load]]", "base": "[rod.base]", "medium": "[system] medium",
                   "gravity": "[system] gravity"}
#: Names no rod or body may take, and why.
RESERVED = {"world": "a joint's end `\"world\"` is the fixed frame"}


def is_system(data):
    """True if the parsed file ``data`` describes a system."""
    return isinstance(data.get("rod"), list) or any(key in data for key in tables.SYSTEM_TABLES)


def system(data, ctx, n_elements):
    """The :class:`rodmol.System` of the parsed file ``data``, or FAILED once
    its problems are recorded; ``n_elements``: ``[discretization]``'s, the
    default of every rod."""
    for key, place in SINGLE_ROD_KEYS.items():
        if key in data:
            ctx.add((key,), f"`{key}` belongs to a single-rod file: in a system file use {place}")
    settings = ctx.table(data.get("system", {}), ("system",), tables.SYSTEM)
    medium, switches = arm_tables.medium(settings, ctx, "air", at=("system",))
    gravity = arm_tables.values(tables.SYSTEM, ctx, ("system",), settings, keys=("gravity",))
    rods, bodies, refused = _parts(data, ctx, {"rod": lambda entry, path: _rod(entry, ctx, path, n_elements, switches),
                                      "body": lambda entry, path: _body(entry, ctx, path)})
    joints = arm_tables.numbered(data, ctx, "joint", tables.JOINT, _joint)
    contacts = rod_contacts(data, ctx)
    if "rod" not in data:
        ctx.add((), "missing `[[rod]]`: a system holds at least one rod")
    if failed(rods, bodies, joints, gravity):
        return FAILED
    # A part with problems stands in as a plain one of its name, so that the
    # joints, the medium and gravity are still checked by System.
    parts_failed = failed(medium, *rods, *rods.values(), *bodies, *bodies.values())
    rods = {name: STAND_IN_ROD() if failed(rod) else rod for name, rod in rods.items() if not failed(name)}
    bodies = {name: STAND_IN_BODY() if failed(body) else body for name, body in bodies.items()
              if not failed(name)}
    rods = rods or {"": STAND_IN_ROD()}
    built = ctx.construct(("system",), System, dict(rods=rods, bodies=bodies, joints=joints,
                                                    medium=None if failed(medium) else medium, **gravity,
                                                    contacts=() if failed(contacts) else contacts),
                          given=gravity, keys=("gravity",),
                          where=lambda key, message: _system_problem(key, message, refused))
    return FAILED if parts_failed or failed(contacts) else built


def _joint(name=None, **arguments):
    """A Joint from a [[joint]] table (``name``: the reader's numbering; a joint has none)."""
    return Joint(**arguments)


def _parts(data, ctx, read):
    """The rods and the bodies ({name: object} each) of the ``[[rod]]`` and ``[[body]]``
    tables, each read by ``read[kind](entry, path)``, and the (kind, name) of the tables
    whose name was refused as taken or reserved. A table whose name is missing, bad or
    refused stands under the key FAILED (its problem recorded). Rods and bodies share one
    set of names, as in a System: each unique, none 'world'."""
    found, named = {}, []
    for kind in ("rod", "body"):
        entries = arm_tables.entries(data, ctx, kind)
        if entries is not FAILED and not all(isinstance(entry, dict) for entry in entries):
            ctx.add((kind,), f"`{kind}` must be an array of tables `[[{kind}]]`, got {_checks.short(entries)}")
            entries = FAILED
        found[kind] = entries
        for i, entry in enumerate([] if entries is FAILED else entries):
            name = ctx.read(entry, (kind, i), "name", _name)
            if name is None:
                ctx.add((kind, i), "missing required key `name` (joints name the rods and bodies)")
            elif not failed(name):
                named.append(((kind, i), kind, name))
    kept = unique_names(ctx, named, RESERVED, "rods and bodies share one set of names, each unique")
    names = {path: name for path, _, name in named if path in kept}
    built = {}
    for kind, entries in found.items():
        if entries is FAILED:
            built[kind] = FAILED
            continue
        built[kind] = {}
        for i, entry in enumerate(entries):  # (every table is read, for its own problems)
            built[kind].setdefault(names.get((kind, i), FAILED), read[kind](entry, (kind, i)))
    return built["rod"], built["body"], {(kind, name) for path, kind, name in named if path not in kept}


def _name(value):
    if not isinstance(value, str) or not value:
        raise ParameterError(f"`name` must be a non-empty string, got {_checks.short(value)}")
    return value


def _rod(entry, ctx, path, n_elements, switches):
    """The Model of one ``[[rod]]`` table."""
    required = tables.ROD.required()
    ctx.table(entry, path, tables.SYSTEM_ROD, required=required)
    material = FAILED if _missing(entry, ctx, path, "material") else arm_tables.build_table(
        entry["material"], ctx, path + ("material",), tables.MATERIAL, Material)
    given = arm_tables.values(tables.ROD, ctx, path, entry)
    stand_in = material if material is not FAILED else Material(1.0, 0.0, rho=1.0)
    rod = FAILED if given is FAILED else ctx.construct(
        path, Rod, {**given, "material": stand_in}, given=entry,
        missing=[k for k in required if k not in entry])
    cables = arm_tables.cables(entry, ctx, at=path)
    markers = arm_tables.markers(entry, ctx, at=path)
    loads = load_tables(entry, ctx, at=path)
    base = arm_tables.base(entry, ctx, at=path)
    if not failed(rod, cables, markers, loads):  # (rod: with a stand-in material if its own failed)
        arm_tables.check_lengths(ctx, rod.length, cables, markers, loads, at=path)
    if failed(material, rod, cables, markers, loads, base):
        return FAILED
    n = entry.get("n_elements", n_elements)
    return ctx.construct(path, Model, dict(rod=rod, n_elements=n, cables=cables, markers=markers, loads=loads,
                                           base=base, **switches),
                         given=entry, keys=("n_elements",) + tuple(switches),
                         where=lambda key, message: _rod_problem(entry, path, key, message))


def _missing(entry, ctx, path, key):
    if key in entry:
        return False
    ctx.add(path, f"missing table `[{path[0]}.{key}]`")
    return True


def _rod_problem(entry, path, key, message):
    """Where a rod's Model error belongs: its key (``n_elements`` here or in
    [discretization]; a medium switch in [system.medium]), or the nested
    entry whose name the message quotes, or the [[rod]] table."""
    if key == "n_elements":
        return path + (key,) if key in entry else ("discretization", key)
    if key is not None:
        return ("system", "medium", key)
    for kind in ("cable", "marker", "load"):
        for i, item in enumerate(entry.get(kind, []) if isinstance(entry.get(kind), list) else []):
            name = item.get("name") if isinstance(item, dict) else None
            if isinstance(name, str) and (repr(name) in message or message.startswith(f"{name}: ")):
                return path + (kind, i)
    return path


def _body(entry, ctx, path):
    """The RigidBody of one ``[[body]]`` table: ``mass`` and ``inertia``, or a
    ``mesh`` file and a ``density`` (:meth:`RigidBody.from_mesh`), and its
    ``[[body.contact]]`` obstacles."""
    meshed = "density" in entry
    required = ("mesh", "density") if meshed else ("mass", "inertia")
    ctx.table(entry, path, tables.BODY, required=required)
    if meshed:
        for key in ("mass", "inertia", "volume", "centre_of_mass"):
            if key in entry:
                ctx.add(path + (key,), f"`{key}` follows from the `mesh` and `density`: leave it out")
    given = arm_tables.values(tables.BODY, ctx, path, entry)
    contacts = contact_tables(entry, ctx, at=path)
    if failed(given, contacts):
        return FAILED
    if contacts:
        given["contacts"] = contacts
    motion = entry.get("motion")
    if isinstance(motion, dict):  # driven: velocities in the body frame, from the body's pose
        pose = {key: given.pop(key) for key in ("position", "rotation") if key in given}
        given["motion"] = arm_tables.build_table(motion, ctx, path + ("motion",), tables.BODY_MOTION,
                                                 BaseMotion, extra=pose)
        if failed(given["motion"]):
            return FAILED
    build = _meshed if meshed else RigidBody
    return ctx.construct(path, build, given, given=entry, missing=[k for k in required if k not in entry])


def _meshed(mesh, density, **options):
    """A body of uniform ``density`` filling the surface in the file ``mesh``."""
    return RigidBody.from_mesh(mesh, density, **options)


def _system_problem(key, message, refused):
    """Where a System error belongs: its key in [system], the [[joint]] or
    [[contact]] it numbers, else the top level; nowhere if it is about a part
    left out for its name, ``refused`` ((kind, name) each), whose problem is recorded."""
    if any(f"names the {kind} {name!r}, which is not in" in message for kind, name in refused):
        return FOLLOWS
    if key is not None:
        return ("system", key)
    found = re.search(r"(joint|contact)s\[(\d+)\]", message)
    return (found.group(1), int(found.group(2))) if found else ()


def STAND_IN_ROD():  # noqa: N802 (a constant made on demand)
    """A plain rod in place of one with problems (never run)."""
    return Model(Rod(1.0, 0.1, Material(1.0, 0.0, rho=1.0)), 2)


def STAND_IN_BODY():  # noqa: N802
    """A plain body in place of one with problems (never run)."""
    return RigidBody(1.0, (1.0, 1.0, 1.0))

