"""A system's variants: a :class:`rodmol.System` with dotted keys changed,
each routed to the part it names and the System rebuilt with the new part
(:meth:`rodmol.System.replace`).

* ``rods.<rod>.<key>``: a key of a single rod's (``material.E``,
  ``medium.drag``, ``discretization.n_elements``, ``tension.<cable>.scale``
  ...), applied to that rod's Model by :mod:`rodmol.model_variants`;
  the medium's numbers are the system's, not a rod's: ``medium.<number>``;
* ``bodies.<body>.<field>``: ``mass`` [kg], ``volume`` [m^3], ``inertia``
  [kg m^2], ``centre_of_mass`` [m], ``added_mass``, ``drag`` (each as
  :class:`rodmol.RigidBody` takes it), or one component of a vector field,
  ``bodies.<body>.<field>.<i>`` (i from 0: the principal inertia along a body
  axis, a drag coefficient, a diagonal entry of the added mass);
* ``medium.<number>`` (``medium.rho``, ``medium.Cy`` ...): the system's
  medium, around every rod and body;
* a rod's key without ``rods.<rod>.`` (``material.mu``, ``medium.drag``,
  ``discretization.n_elements``): every rod (a rod's own key wins over it);
  its value (:func:`value`) is the rods' common one.

On the problem floor, as :mod:`rodmol.model_variants`.
"""

import numpy as np

from . import _checks
from . import model_variants as rod_variants
from .bodies import RigidBody
from .errors import ParameterError
from .parameters import Medium

#: A body's numbers and its vector fields with their lengths (the fields worth fitting).
BODY_NUMBERS = ("mass", "volume")
BODY_VECTORS = {"inertia": 3, "centre_of_mass": 3, "added_mass": 6, "drag": 6}
#: Rod keys that apply to every rod when given without ``rods.<rod>.``.
EVERY_ROD = ("material.", "medium.", "discretization.n_elements")


def _medium_number(key):
    table, _, name = key.partition(".")
    return table == "medium" and name in rod_variants.MEDIUM


#: A rod's keys in a system (its medium's numbers are the system's).
ROD_KEYS = [k for k in rod_variants.MODEL_KEYS if not _medium_number(k)]
BODY_KEYS = list(BODY_NUMBERS) + [f"{f}[.<i>]" for f in BODY_VECTORS]
SYSTEM_MEDIUM = [f"medium.{k}" for k in rod_variants.MEDIUM]
#: The keys of a system, as templates.
KEYS = ([f"rods.<rod>.{k}" for k in ROD_KEYS] + [f"bodies.<body>.{k}" for k in BODY_KEYS] + SYSTEM_MEDIUM
        + [k for k in ROD_KEYS if k.startswith(EVERY_ROD)] + rod_variants.RUN_KEYS)


def variant(system, changes):
    """The System with ``changes`` ({key: value}, keys split) applied; every key
    and value checked first (a ParameterError names the key, the part and its keys)."""
    every, rods, bodies, medium = {}, {}, {}, {}
    for key, value in changes.items():
        kind, part, rest = _route(system, key)
        if kind == "medium":
            medium[rest] = rod_variants.number(key, value)
        elif kind == "every":
            every[rest] = value
        elif kind == "rod":
            rods.setdefault(part, {})[rest] = value
        else:
            bodies.setdefault(part, {})[rest] = value
    new_rods = {}
    for name, model in system.given_rods.items():
        own = {**every, **rods.get(name, {})}
        if own:
            new_rods[name] = rod_variants.variant(model, own, label=f"rods.{name}.")
    new_bodies = {name: _body(system.given_bodies[name], name, fields) for name, fields in bodies.items()}
    options = {}
    if medium:
        options["medium"] = rod_variants.guard("medium." + ",".join(medium), medium, lambda: Medium(
            **{**{k: getattr(system.medium, k) for k in rod_variants.MEDIUM}, **medium}))
    return rod_variants.guard("overrides", changes, lambda: system.replace(rods=new_rods, bodies=new_bodies,
                                                                           **options))


def value(system, key):
    """The value of the system's ``key`` (one field)."""
    kind, part, rest = _route(system, key)
    if kind == "medium":
        return getattr(system.medium, rest)
    if kind == "rod":
        return rod_variants.value(system.given_rods[part], rest, label=f"rods.{part}.")
    if kind == "body":
        field, index = rest
        current = getattr(system.given_bodies[part], field)
        if index is None:
            return current
        return float(current[index, index] if np.ndim(current) == 2 else current[index])
    values = {name: rod_variants.value(model, rest) for name, model in system.given_rods.items()}
    first = next(iter(values.values()))
    if any(v != first for v in values.values()):
        raise ParameterError(f"override {key!r}: the rods' values differ ({values}): name the rod, "
                             f"e.g. 'rods.{next(iter(values))}.{rest}'")
    return first


def _route(system, key):
    """(kind, part, rest) of ``key``: ("rod", name, rod key), ("body", name, (field, index or None)),
    ("medium", None, number) or ("every", None, rod key); a ParameterError for any other."""
    table, _, rest = key.partition(".")
    if table == "rods":
        name = _part(key, rest, system.given_rods, "rod")
        rod_key = rest[len(name) + 1:]
        if _medium_number(rod_key):
            raise ParameterError(f"override {key!r}: the medium is the system's, around every rod and body: "
                                 f"use 'medium.{rod_key.partition('.')[2]}'")
        if not rod_variants.is_key(rod_key):
            raise rod_variants.unknown(key, [f"rods.{name}.{k}" for k in ROD_KEYS], f" (rod {name!r})")
        return "rod", name, rod_key
    if table == "bodies":
        name = _part(key, rest, system.given_bodies, "body")
        return "body", name, _body_field(key, name, rest[len(name) + 1:])
    if _medium_number(key):
        return "medium", None, rest
    if rod_variants.is_key(key) and key.startswith(EVERY_ROD):
        return "every", None, key
    if table == "tension":
        raise ParameterError(f"override {key!r}: name the rod whose cable it is, "
                             f"'rods.<rod>.{key}' (rods: {', '.join(system.given_rods)})")
    raise _unknown(system, key)


def _unknown(system, key):
    """The ParameterError of a key that is no system's: a near miss among the
    system's keys, and the keys by group, one line each."""
    rods, bodies = list(system.given_rods), list(system.given_bodies)
    every = [k for k in ROD_KEYS if k.startswith(EVERY_ROD)]
    concrete = ([f"rods.{r}.{k}" for r in rods for k in ROD_KEYS] + [f"bodies.{b}.{k}" for b in bodies
                for k in BODY_NUMBERS + tuple(BODY_VECTORS)] + SYSTEM_MEDIUM + every + rod_variants.RUN_KEYS)
    return ParameterError("\n".join([
        f"unknown override {key!r} for a system{_checks.did_you_mean(key, concrete)}; valid keys:",
        f"  rods.<rod>.<key>, rods {', '.join(rods)}, keys {', '.join(ROD_KEYS)}",
        f"  bodies.<body>.<field>, bodies {', '.join(bodies) or '(none)'}, fields {', '.join(BODY_KEYS)}",
        f"  the system's medium: {', '.join(SYSTEM_MEDIUM)}",
        f"  every rod's: {', '.join(every)}",
        f"  the run's: {', '.join(rod_variants.RUN_KEYS)}"]))


def _part(key, rest, parts, kind):
    """The name of the part (a rod or a body, ``kind``) that ``rest`` starts with (the longest, for dotted names)."""
    for name in sorted(parts, key=len, reverse=True):
        if rest.startswith(name + "."):
            return name
    given = rest.split(".", 1)[0]
    raise ParameterError(f"override {key!r}: the system has no {kind} named {given!r}"
                         f"{_checks.did_you_mean(given, parts)} ({'rods' if kind == 'rod' else 'bodies'}: "
                         f"{', '.join(parts) or 'none'})")


def _body_field(key, name, rest):
    """(field, index or None) of a body's key ``rest``."""
    field, _, index = rest.partition(".")
    if rest in BODY_NUMBERS or (field in BODY_VECTORS and not index):
        return rest, None
    if field in BODY_VECTORS and index.isdigit() and int(index) < BODY_VECTORS[field]:
        return field, int(index)
    if field in BODY_VECTORS:
        raise ParameterError(f"override {key!r}: `{field}` of body {name!r} has components 0 to "
                             f"{BODY_VECTORS[field] - 1}, got {index!r}")
    raise rod_variants.unknown(key, [f"bodies.{name}.{k}" for k in BODY_KEYS], f" (body {name!r})")


def _body(body, name, changes):
    """The RigidBody ``body`` with ``changes`` ({(field, index or None): value}) applied."""
    fields = {f: getattr(body, f) for f in BODY_NUMBERS + tuple(BODY_VECTORS)}
    whole = {field for field, index in changes if index is None}
    for (field, index), given in changes.items():
        key = f"bodies.{name}.{field}" + ("" if index is None else f".{index}")
        if index is None:
            fields[field] = given
        elif field in whole:
            raise ParameterError(f"override {key!r}: `{field}` of body {name!r} is given whole too: "
                                 "give it whole or by its components, not both")
        else:  # a component of the stored array: a 3x3 or 6x6 matrix's diagonal entry
            arr = np.array(fields[field], dtype=float)
            arr[(index, index) if arr.ndim == 2 else index] = rod_variants.number(key, given)
            fields[field] = arr
    keys = ",".join(dict.fromkeys(f"bodies.{name}.{f}" for f, _ in changes))
    pose = {} if body.driven else dict(position=body.position, rotation=body.rotation)
    return rod_variants.guard(keys, {}, lambda: RigidBody(
        **fields, mesh=body.mesh, motion=body.motion, contacts=body.contacts,
        contact_points=body.contact_points, contact_radius=body.contact_radius, **pose))
