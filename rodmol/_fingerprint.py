"""A stable fingerprint of a model's parameters: what a resumed run compares.

:func:`fingerprint` hashes (SHA-256) a canonical text of a value walked
recursively: numbers by their exact binary value (``float.hex``), arrays by
dtype, shape and bytes, dataclasses and other objects by their class's
qualified name and their fields, containers item by item. Functions are
named by module and qualified name, with the values they close over and
their defaults (so a ramp built by a factory changes with its slope); their
code is not read, so editing a function's body keeps the fingerprint. No
``id`` or memory address enters, so the fingerprint is the same in every
process, and any changed number changes it.
"""

import dataclasses
import enum
import functools
import hashlib
import inspect

import numpy as np


def fingerprint(value):
    """The SHA-256 (hex) of the canonical text of ``value``."""
    digest = hashlib.sha256()
    _walk(value, digest.update, set())
    return digest.hexdigest()


def model_fingerprint(model):
    """The fingerprint of a :class:`rodmol.Model`'s physics: its rod and every constructor
    argument but the number of elements (the grid is compared on its own)."""
    return fingerprint((type(model), model.rod, model.options()))


def system_fingerprints(system):
    """The fingerprints of a :class:`rodmol.System`'s parts, by name (``"rod 'NAME'"``,
    ``"body 'NAME'"``, ``"joints"``, ``"medium"``, ``"gravity"``): each rod's
    :func:`model_fingerprint` (its grid compared apart; its Model carries the system's
    gravity, medium and penalty joints' holds), each body's and the system-wide ones, so that a
    resumed run can say which part changed."""
    parts = {f"rod {name!r}": model_fingerprint(model) for name, model in system.rods.items()}
    parts.update({f"body {name!r}": fingerprint(body) for name, body in system.bodies.items()})
    parts.update(joints=fingerprint(tuple(system.joints)), medium=fingerprint(system.medium),
                 gravity=fingerprint(system.gravity))
    return parts


def _name(obj):
    return f"{getattr(obj, '__module__', '?')}.{getattr(obj, '__qualname__', type(obj).__qualname__)}"


def _walk(value, put, seen):
    if value is None or isinstance(value, (bool, str, bytes, int, enum.Enum)):
        put(f"{type(value).__name__}:{value!r};".encode())
        return
    if isinstance(value, (float, np.floating)):
        put(f"f:{float(value).hex()};".encode())
        return
    if isinstance(value, (complex, np.complexfloating)):
        put(f"c:{value.real.hex()},{value.imag.hex()};".encode())
        return
    if isinstance(value, np.generic):
        value = np.asarray(value)
    if isinstance(value, np.ndarray):
        data = np.ascontiguousarray(value)
        put(f"a:{data.dtype.str}{data.shape}:".encode())
        put(data.tobytes() if data.dtype != object else repr(data.tolist()).encode())
        put(b";")
        return
    if id(value) in seen:  # a cycle: named, not walked again
        put(f"cycle:{type(value).__qualname__};".encode())
        return
    seen.add(id(value))
    try:
        _walk_compound(value, put, seen)
    finally:
        seen.discard(id(value))


def _walk_compound(value, put, seen):
    if isinstance(value, (list, tuple)):
        put(f"{type(value).__name__}[".encode())
        for item in value:
            _walk(item, put, seen)
        put(b"]")
    elif isinstance(value, dict):
        put(b"{")
        for key in sorted(value, key=repr):
            _walk(key, put, seen)
            _walk(value[key], put, seen)
        put(b"}")
    elif isinstance(value, (set, frozenset)):
        _walk(sorted(value, key=repr), put, seen)
    elif isinstance(value, functools.partial):
        _walk(("partial", value.func, value.args, value.keywords), put, seen)
    elif inspect.isclass(value) or inspect.isroutine(value):
        put(f"fn:{_name(value)};".encode())
        closure = getattr(value, "__closure__", None) or ()
        cells = []
        for cell in closure:
            try:
                cells.append(cell.cell_contents)
            except ValueError:  # an empty cell
                cells.append(None)
        if cells or getattr(value, "__defaults__", None) or getattr(value, "__kwdefaults__", None):
            _walk((cells, getattr(value, "__defaults__", None), getattr(value, "__kwdefaults__", None)),
                  put, seen)
        bound = getattr(value, "__self__", None)
        if inspect.ismethod(value) and bound is not None:
            _walk(bound, put, seen)
    elif dataclasses.is_dataclass(value):
        put(f"dc:{_name(type(value))}".encode())
        _walk({f.name: getattr(value, f.name) for f in dataclasses.fields(value)}, put, seen)
    else:
        put(f"obj:{_name(type(value))}".encode())
        fields = dict(getattr(value, "__dict__", {}))
        for slot in getattr(type(value), "__slots__", ()):
            if hasattr(value, slot):
                fields[slot] = getattr(value, slot)
        _walk(fields, put, seen)
