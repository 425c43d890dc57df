"""Line numbers of the tables and keys of a TOML text, for error messages (tomllib gives none)."""

import re

_BARE = r"[A-Za-z0-9_-]+|\"[^\"]*\"|'[^']*'"
_KEY = rf"(?:{_BARE})(?:\s*\.\s*(?:{_BARE}))*"
_ARRAY_HEADER = re.compile(rf"^\s*\[\[\s*({_KEY})\s*\]\]")
_HEADER = re.compile(rf"^\s*\[\s*({_KEY})\s*\]")
_ASSIGN = re.compile(rf"^\s*({_KEY})\s*=(.*)$")


def _split_key(key):
    return tuple(part.strip("\"'") for part in re.findall(_BARE, key))


class KeyLines:
    """Line numbers of the tables and keys of a TOML text (tomllib gives none).

    Paths are tuples: ``("rod", "radius")``, ``("cable", 2, "anchor")`` for the
    third ``[[cable]]``, ``("rod", 1, "cable", 0)`` for the first ``[[rod.cable]]``
    of the second ``[[rod]]`` (a table under an array of tables belongs to its
    last entry, as in TOML). Lines inside multi-line arrays and strings are skipped.
    """

    def __init__(self, text):
        self.lines = {}
        table, counts, depth, in_string = (), {}, 0, None
        for number, line in enumerate(text.splitlines(), start=1):
            if depth or in_string:
                depth, in_string, _ = _scan(line, depth, in_string)
                continue
            if match := _ARRAY_HEADER.match(line):
                *parents, name = _split_key(match.group(1))
                array = _in_arrays(tuple(parents), counts) + (name,)
                counts[array] = counts.get(array, -1) + 1
                self.lines.setdefault(array, number)
                table = array + (counts[array],)
            elif match := _HEADER.match(line):
                table = _in_arrays(_split_key(match.group(1)), counts)
            elif match := _ASSIGN.match(line):
                self.lines.setdefault(table + _split_key(match.group(1)), number)
                depth, in_string, _ = _scan(match.group(2), 0, None)
                continue
            else:
                continue
            self.lines.setdefault(table, number)

    def find(self, path):
        """Line of ``path``, or of its closest enclosing table or key; None if unknown."""
        path = tuple(path)
        while path:
            if path in self.lines:
                return self.lines[path]
            path = path[:-1]
        return None


def _in_arrays(keys, counts):
    """The path of the dotted ``keys``, each array of tables met on the way
    followed by the index of its last entry so far (its count in ``counts``)."""
    path = ()
    for key in keys:
        path += (key,)
        if path in counts:
            path += (counts[path],)
    return path


def deepest_line(text):
    """The line where arrays and inline tables nest deepest (the first such), or None:
    where to point when a parser gives up on the nesting."""
    depth, in_string, deepest, where = 0, None, 0, None
    for number, line in enumerate(text.splitlines(), start=1):
        value = line if (depth or in_string) else (m.group(2) if (m := _ASSIGN.match(line)) else "")
        depth, in_string, peak = _scan(value, depth, in_string)
        if peak > deepest:
            deepest, where = peak, number
    return where


def _scan(fragment, depth, in_string):
    """Follow brackets and strings through a value fragment; return (depth, open string,
    deepest depth reached)."""
    i, peak = 0, depth
    while i < len(fragment):
        if in_string:
            end = fragment.find(in_string, i)
            if end < 0:
                return depth, in_string, peak
            i, in_string = end + 3, None
            continue
        c = fragment[i]
        if c == "#":
            break
        if fragment.startswith('"""', i) or fragment.startswith("'''", i):
            in_string, i = fragment[i:i + 3], i + 3
            continue
        if c in "\"'":
            i += 1
            while i < len(fragment) and fragment[i] != c:
                i += 2 if (c == '"' and fragment[i] == "\\") else 1
        elif c in "[{":
            depth += 1
            peak = max(peak, depth)
        elif c in "]}":
            depth = max(depth - 1, 0)
        i += 1
    return depth, in_string, peak
