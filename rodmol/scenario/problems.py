"""Problems of a scenario file: each with its line and table, all collected at once.

A :class:`Context` walks the parsed file with the field readers of
:mod:`rodmol.scenario.readers`; every problem it meets is recorded (with
the line number :class:`rodmol.scenario.toml_lines.KeyLines` finds) rather than
raised, and :class:`ScenarioError` reports them all together.
"""

import difflib
import re
from dataclasses import dataclass

from .._checks import short
from ..errors import ParameterError
from .schema import UNITS


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


class Bad(Exception):
    """A value problem found by a field reader (message without location)."""


#: A value that could not be read; its problem is already recorded.
FAILED = object()


def failed(*values):
    """True if any of ``values`` could not be read."""
    return any(v is FAILED for v in values)



@dataclass(frozen=True)
class Override:
    """A value given on the command line, with the option's name for messages."""

    value: object
    label: str

def table_label(path):
    """How a table is named in messages: ``[rod]``, ``[[cable]] #2``."""
    if not path:
        return ""
    if len(path) >= 2 and isinstance(path[1], int):
        return f"[[{path[0]}]] #{path[1] + 1}"
    return "[" + ".".join(map(str, path)) + "]"


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

    def table(self, data, path, allowed, required=(), hint="", units=UNITS):
        """Check a table's keys; return it (an empty dict if it is not a table)."""
        if not isinstance(data, dict):
            self.add(path, f"`{path[-1]}` must be a table, got {short(data)}")
            return {}
        for key in data:
            if key not in allowed:
                close = difflib.get_close_matches(key, allowed, n=1, cutoff=0.6)
                tip = f"; did you mean `{close[0]}`?" if close else f"; valid keys: {', '.join(allowed)}"
                self.add(path + (key,), f"unknown key `{key}`{tip}{hint}", table=path)
        for key in required:
            if key not in data:
                unit = f" [{units[key]}]" if key in units else ""
                self.add(path, f"missing required key `{key}`{unit}")
        return data

    def read(self, table, path, key, reader, default=None):
        """``reader(value)`` of ``table[key]`` (``default`` if absent); on a problem, record it."""
        if key not in table:
            return default
        try:
            return reader(table[key])
        except Bad as exc:
            self.add(path + (key,), f"`{key}` {exc}")
        except ParameterError as exc:
            self.add(path + (key,), str(exc))
        return FAILED

    def construct(self, path, table, build):
        """Call a rodmol constructor; a ParameterError is recorded at the key it names."""
        try:
            return build()
        except ParameterError as exc:
            message = str(exc)
            named = [w for quoted in re.findall(r"`([^`]+)`", message)
                     for w in re.findall(r"[A-Za-z_]+", quoted) if w in table]
            self.add(path + ((named[0],) if named else ()), message)
            return FAILED
