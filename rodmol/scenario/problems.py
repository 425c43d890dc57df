"""Problems of a scenario file: each with its line and table, all collected at once.

A :class:`Context` walks the parsed file and hands its values to the rodmol
constructors, which check them; every problem it meets is recorded (with
the line number :class:`rodmol.scenario.toml_lines.KeyLines` finds) rather than
raised, and :class:`ScenarioError` reports them all together.
"""

import difflib
import inspect
import os
import re
from dataclasses import dataclass

from .._checks import short
from ..errors import ParameterError


class ScenarioError(ParameterError):
    """A scenario file has problems; ``problems`` lists them all (:class:`Problem`)."""

    def __init__(self, source, problems):
        self.source, self.problems = source, list(problems)
        count = f"{len(self.problems)} problem" + ("s" if len(self.problems) != 1 else "")
        lines = [f"{source}: {count}:"] + [f"  {p}" for p in self.problems]
        super().__init__("\n".join(lines))


@dataclass(frozen=True)
class Problem:
    """One problem: where (file, line, table) and what."""

    source: str
    line: object  # int, None, or a command-line option name
    table: str
    message: str

    def __str__(self):
        where = (f"{self.source}:{self.line}" if isinstance(self.line, int)
                 else f"command line {self.line}" if self.line else self.source)
        return f"{where}: {self.table} {self.message}" if self.table else f"{where}: {self.message}"


#: A value that could not be read; its problem is already recorded.
FAILED = object()
#: Where a problem that follows from one already recorded goes: nowhere.
FOLLOWS = object()


def failed(*values):
    """True if any of ``values`` could not be read."""
    return any(v is FAILED for v in values)


@dataclass(frozen=True)
class Override:
    """A value given on the command line, with the option's name for messages."""

    value: object
    label: str


def table_label(path):
    """How a table is named in messages: ``[rod]``, ``[[cable]] #2``,
    ``[[rod]] #1 [[cable]] #2``."""
    if not path:
        return ""
    if len(path) >= 2 and isinstance(path[1], int):
        entry = f"[[{path[0]}]] #{path[1] + 1}"
        return entry + (" " + table_label(path[2:]) if len(path) > 2 else "")
    return "[" + ".".join(map(str, path)) + "]"


def unique_names(ctx, named, reserved=None, rule="names must be unique"):
    """The paths of the tables of ``named`` — (path, kind, name) each: the ``[[kind]]`` table
    at ``path`` and its name — whose name no table before it in the file took. Each later
    use is a problem at that table's ``name`` key naming the table that took it first (and
    ``rule``); a ``reserved`` name ({name: why}) is one wherever it is."""
    reserved = reserved or {}

    def line(path):
        return ctx.lines.find(path + ("name",))

    taken, kept = {}, set()
    for path, kind, name in sorted(named, key=lambda entry: line(entry[0]) or 0):  # ties keep their order
        if name in reserved:
            ctx.add(path + ("name",), f"the {kind} name {name!r} is reserved: {reserved[name]}")
        elif name in taken:
            first = taken[name]
            at = f" (line {line(first)})" if line(first) else ""
            ctx.add(path + ("name",), f"the {kind} name {name!r} is used twice: {table_label(first)}{at} has it "
                                      f"too; {rule}")
        else:
            taken[name] = path
            kept.add(path)
    return kept


class Context:
    """Collects problems, each with its line and table.

    ``data`` is the parsed file (set once the overrides are applied),
    ``base_dir`` where its relative paths start.
    """

    def __init__(self, source, lines, base_dir):
        self.source, self.lines, self.base_dir = source, lines, base_dir
        self.problems, self.overridden, self.data = [], {}, {}

    def override(self, dotted, value, data):
        """Replace the value at the dotted key in ``data``; its problems name the option."""
        label = getattr(value, "label", None)
        value = getattr(value, "value", value)
        *tables, key = dotted.split(".")
        target = data
        for name in tables:
            target = target.setdefault(name, {})
            if not isinstance(target, dict):
                return  # the file's own problem, reported when its table is read
        target[key] = value
        self.overridden[tuple(dotted.split("."))] = label or f"({dotted})"

    def add(self, path, message, table=None):
        """Record a problem at ``path`` (a key or a table); ``table`` defaults to the
        innermost table on the path."""
        path = tuple(path)
        if table is None:
            node, table = self.data, ()
            for i, part in enumerate(path):
                try:
                    node = node[part]
                except (KeyError, IndexError, TypeError):
                    break
                if isinstance(node, dict):
                    table = path[:i + 1]
        line = self.overridden.get(path) or self.lines.find(path)
        self.problems.append(Problem(self.source, line, table_label(table), message))

    def table(self, data, path, table, required=None, hint=""):
        """Check a table's keys against ``table`` (a :class:`~rodmol.scenario.tables.Table`);
        return it (an empty dict if it is not a table)."""
        if not isinstance(data, dict):
            self.add(path, f"`{path[-1]}` must be a table, got {short(data)}")
            return {}
        allowed = table.names()
        for key in data:
            if key not in allowed:
                close = difflib.get_close_matches(key, allowed, n=1, cutoff=0.6)
                tip = f"; did you mean `{close[0]}`?" if close else f"; valid keys: {', '.join(allowed)}"
                self.add(path + (key,), f"unknown key `{key}`{tip}{hint}", table=path)
        for key in table.required() if required is None else required:
            if key not in data:
                unit = f" [{table.unit(key)}]" if table.unit(key) else ""
                self.add(path, f"missing required key `{key}`{unit}")
        return data

    def read(self, table, path, key, check, default=None):
        """``check(value)`` of ``table[key]`` (``default`` if absent); a ParameterError is
        recorded at the key."""
        if key not in table:
            return default
        try:
            return check(table[key])
        except ParameterError as exc:
            self.add(path + (key,), str(exc))
        return FAILED

    def construct(self, path, build, values, given=None, missing=(), where=None, keys=None):
        """``build(**values)``: the constructor checks the values. Each ParameterError is
        recorded at the key it names (or at the path ``where(key, message)`` gives; nowhere if
        that is :data:`FOLLOWS`); that key then takes a stand-in value (:data:`STAND_INS`, or its default) and ``build``
        is tried again, so that every bad value is reported at once. ``given``: the
        file's keys (those with a line); ``missing``: required keys already reported
        absent (they take stand-ins); ``keys``: those a message may name (default:
        ``build``'s parameters). Returns the object, or FAILED."""
        values, given = dict(values), set(values if given is None else given)
        keys = tuple(inspect.signature(build).parameters) if keys is None else keys
        reported, left = list(missing), {k: list(STAND_INS) for k in missing}
        values.update({k: left[k].pop(0) for k in missing})
        while True:
            try:
                built = build(**values)
                return FAILED if reported else built
            except TypeError:
                if not reported:
                    raise
                return FAILED  # a stand-in left out a required argument: no more to find
            except ParameterError as exc:
                message = str(exc)
                key = named_key(message, keys) or quoted_value(message, values, given)
                if key is None or key not in reported:
                    place = where(key, message) if where else None
                    if place is not FOLLOWS:
                        self.add(place or path + ((key,) if key in given else ()), message)
                if key is None:
                    return FAILED
                if key not in reported:
                    reported.append(key)
                    left[key] = list(STAND_INS) + ([DROP] if key in values else [])
                if not left[key]:
                    return FAILED
                stand_in = left[key].pop(0)
                if stand_in is DROP:
                    del values[key]
                else:
                    values[key] = stand_in


#: Values tried in place of a bad one, to find the table's other problems
#: (never built into a model): a number, a zero, a 3-vector, a 2-vector, a count.
STAND_INS = (1.0, 0.0, (1.0, 0.0, 0.0), (0.0, 0.0), 2)
#: Stand-in "leave it out": the constructor's default.
DROP = object()


def quoted_value(message, values, given):
    """The key of ``given`` whose text value the message quotes (a CSV file's name), or None."""
    return next((k for k in given if isinstance(values.get(k), (str, os.PathLike))
                 and os.fspath(values[k]) in message), None)


def named_key(message, keys):
    """The key of ``keys`` a constructor's message is about: the last word of
    its first back-quoted name that is a key (```cable 'a' anchor``` -> anchor)."""
    for quoted in re.findall(r"`([^`]+)`", message):
        words = [w for w in re.findall(r"[A-Za-z_]+", quoted) if w in keys]
        if words:
            return words[-1]
    return None
