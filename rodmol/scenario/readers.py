"""Field readers of scenario files: each turns one TOML value into a checked
Python value, or raises :class:`~rodmol.scenario.problems.Bad` (or a
:class:`~rodmol.errors.ParameterError`) with a message that names no place;
:meth:`Context.read <rodmol.scenario.problems.Context.read>` adds the line
and table.
"""

import difflib
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .._checks import short
from ..cables import as_tension, read_tension_csv
from ..inputs import as_time_input
from .problems import Bad


def _is_number(x):
    return isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x)


def number(condition=None, unit=""):
    """A finite number; ``condition`` "positive" or "non-negative"."""
    def read(value):
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
            raise Bad(f"must be a number{f' [{unit}]' if unit else ''}, got {short(value)}")
        if condition == "positive" and value <= 0:
            raise Bad(f"must be > 0{f' {unit}' if unit else ''}, got {short(value)}")
        if condition == "non-negative" and value < 0:
            raise Bad(f"must be >= 0{f' {unit}' if unit else ''}, got {short(value)}")
        return float(value)
    return read


def integer(minimum, maximum=None):
    def read(value):
        if isinstance(value, bool) or not isinstance(value, int):
            raise Bad(f"must be an integer, got {short(value)}")
        if value < minimum:
            raise Bad(f"must be >= {minimum}, got {short(value)}")
        if maximum is not None and value > maximum:
            raise Bad(f"must be <= {maximum}, got {short(value)}")
        return value
    return read


def boolean(value):
    if not isinstance(value, bool):
        raise Bad(f"must be true or false, got {short(value)}")
    return value


def string(value):
    if not isinstance(value, str):
        raise Bad(f"must be a string, got {short(value)}")
    return value


def path(value):
    """A file or directory name."""
    string(value)
    if "\0" in value:
        raise Bad(f"must be a path without NUL characters, got {short(value)}")
    return value


def choice(options):
    """One of ``options``, with a suggestion for a near miss."""
    def read(value):
        if value not in options:
            close = difflib.get_close_matches(str(value), options, n=1, cutoff=0.6)
            tip = f"did you mean {close[0]!r}? " if close else ""
            raise Bad(f"is {short(value)}: {tip}valid values are {', '.join(map(repr, options))}")
        return value
    return read


def vector(length, unit):
    def read(value):
        if not isinstance(value, list) or len(value) != length or not all(map(_is_number, value)):
            raise Bad(f"must be {length} numbers [{unit}], got {short(value)}")
        return tuple(float(x) for x in value)
    return read


def matrix3(value):
    rows = value if isinstance(value, list) and len(value) == 3 else None
    try:
        return tuple(vector(3, "-")(row) for row in rows)
    except (Bad, TypeError):
        raise Bad(f"must be a 3x3 rotation matrix (three rows of three numbers), got {short(value)}") from None


def pairs(what, unit):
    def read(value):
        ok = isinstance(value, list) and len(value) >= 1 and all(
            isinstance(p, list) and len(p) == 2 and all(map(_is_number, p)) for p in value)
        if not ok:
            raise Bad(f"must be a list of {what} pairs [{unit}], got {short(value)}")
        return [(float(a), float(b)) for a, b in value]
    return read


def offset(value):
    """A cable routing: [p_y, p_z] or [[s, p_y, p_z], ...] knots [m]."""
    if isinstance(value, list) and value and all(isinstance(row, list) for row in value):
        if len(value) >= 2 and all(len(row) == 3 and all(map(_is_number, row)) for row in value):
            return [tuple(float(x) for x in row) for row in value]
        raise Bad(f"must be [p_y, p_z] or at least two [s, p_y, p_z] knots [m], got {short(value)}")
    return vector(2, "m")(value)


def displacement(base_dir, name):
    """An actuator position z(t): a number [m], [t, z] knots or a CSV file relative to ``base_dir``."""
    def read(value):
        if isinstance(value, str):
            return str(_resolve(base_dir, value))
        if isinstance(value, list):
            return pairs("(t, z)", "s, m")(value)
        if _is_number(value):
            return float(value)
        raise Bad(f"must be a number [m], a list of [t, z] knots [s, m] or a CSV file name, got {short(value)}")
    return read


def component_viscosity(value):
    """``{shear_extension = [3 numbers], bending_torsion = [3 numbers]}`` [Pa s]."""
    keys = ("shear_extension", "bending_torsion")
    if not isinstance(value, dict) or not value or set(value) - set(keys):
        raise Bad(f"must be a table with keys {', '.join(keys)} (three viscosities [Pa s] each), got {short(value)}")
    return {k: vector(3, "Pa s")(v) for k, v in value.items()}


def _resolve(base_dir, value):
    path = Path(value)
    return path if path.is_absolute() else base_dir / path


@dataclass(frozen=True)
class RadiusProfile:
    """A radius r(s) [m] interpolated linearly between ``(s, r)`` points [m]."""

    s: tuple
    r: tuple

    def __call__(self, s):
        return np.interp(s, self.s, self.r)


def radius(length):
    """A section radius: a number, a [base, tip] pair or (s, r) points spanning the rod."""
    def read(value):
        if isinstance(value, list) and value and all(isinstance(p, list) for p in value):
            points = pairs("(s, r)", "m")(value)
            s, r = np.array(points).T
            if len(s) < 2:
                raise Bad(f"needs at least two (s, r) points, got {short(value)}")
            if np.any(np.diff(s) <= 0):
                raise Bad(f"points must have increasing s, got s = {s.tolist()}")
            if np.any(r <= 0):
                raise Bad(f"must be > 0 m, got r = {r.tolist()}")
            if isinstance(length, float) and not (s[0] == 0.0 and abs(s[-1] - length) <= 1e-9 * length):
                raise Bad(f"points must span s = 0 to the length {length!r} m, got s from "
                          f"{s[0].item()!r} to {s[-1].item()!r} m")
            return RadiusProfile(tuple(s), tuple(r))
        if isinstance(value, list):
            return vector(2, "m")(value) if len(value) == 2 else _bad_radius(value)
        if isinstance(value, (int, float)) and not isinstance(value, bool):
            return number("positive", "m")(value)
        return _bad_radius(value)
    return read


def _bad_radius(value):
    raise Bad("must be a number [m], a [base, tip] pair [m] or a list of [s, r] points [m], "
              f"got {short(value)}")


def tension(base_dir, name):
    """A cable tension: a number [N], [t, T] knots or a CSV file relative to ``base_dir``."""
    def read(value):
        if isinstance(value, str):
            return read_tension_csv(_resolve(base_dir, value))
        if isinstance(value, list):
            return as_tension(pairs("(t, T)", "s, N")(value), f"{name!r} tension")
        if isinstance(value, (int, float)) and not isinstance(value, bool):
            return number("non-negative", "N")(value)
        raise Bad(f"must be a number [N], a list of [t, T] knots [s, N] or a CSV file name, got {short(value)}")
    return read


def vector_input(base_dir, key, unit):
    """A 3-vector in time: 3 numbers [unit], a list of [t, x, y, z] knots or a
    CSV file (columns t, x, y, z) relative to ``base_dir``; returns a TimeInput."""
    def read(value):
        if isinstance(value, str):
            return as_time_input(key, _resolve(base_dir, value), 3, unit)
        if isinstance(value, list) and value and all(isinstance(row, list) for row in value):
            if not all(len(row) == 4 and all(map(_is_number, row)) for row in value):
                raise Bad(f"knots must be rows of 4 numbers [t, x, y, z] [s, {unit}], got {short(value)}")
            return as_time_input(key, [[float(x) for x in row] for row in value], 3, unit)
        if isinstance(value, list) and len(value) == 3 and all(map(_is_number, value)):
            return as_time_input(key, [float(x) for x in value], 3, unit)
        raise Bad(f"must be 3 numbers [{unit}], a list of [t, x, y, z] knots [s, {unit}] or a CSV "
                  f"file name, got {short(value)}")
    return read


def constant_vector(unit):
    """A constant 3-vector [unit] (f(s, t) needs Python)."""
    def read(value):
        if not isinstance(value, list) or len(value) != 3 or not all(map(_is_number, value)):
            raise Bad(f"must be 3 numbers [{unit}] (a constant; a load that varies along the rod "
                      f"or in time needs Python: rodmol.loads), got {short(value)}")
        return tuple(float(x) for x in value)
    return read
