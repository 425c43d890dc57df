"""Inputs that vary in time: cable tensions, point loads, actuator commands.

Every time input is one of

* a constant (a number, or a vector for vector-valued inputs);
* knots ``[(t, x...), ...]``, interpolated linearly and held constant outside
  the first and last knot;
* a CSV table with a time column [s] and one column per component (an
  optional header line; ``#`` starts a comment), as logged by a rig;
* a callable ``f(t)``.

:func:`as_time_input` turns any of them into a :class:`TimeInput`, checked
once, with errors that name the input and the offending value or line.
"""

import csv
import math
import os
from bisect import bisect_right

import numpy as np

from ._checks import bad_return, floats, short, user_error
from .errors import ParameterError, RodmolError


class TimeInput:
    """A value of ``width`` components as a function of time t [s].

    ``value(t)`` returns a float if ``width == 1``, else a (width,) array.
    ``constant`` is True if the value never changes (it is then read once);
    ``held`` if it changes only between a stepping simulator's steps (it is
    then read when it changes, ``SemiDiscrete.read_held``).
    """

    width = 1
    constant = False
    held = False
    source = "function"

    def value(self, t):
        raise NotImplementedError


class Constant(TimeInput):
    constant = True
    source = "constant"

    def __init__(self, value, width):
        self.width = width
        self._value = float(value[0]) if width == 1 else np.array(value, dtype=float)

    def value(self, t):
        return self._value

    def __repr__(self):
        return f"Constant({self._value!r})"


class Knots(TimeInput):
    """Linear interpolation between knots, held constant outside them."""

    def __init__(self, times, values, source="knots"):
        values = np.asarray(values, dtype=float).reshape(len(times), -1)
        self.times, self.values, self.source = np.array(times, dtype=float), values, source
        self.width = values.shape[1]
        # Plain lists and bisect: called at every right-hand-side evaluation with a
        # scalar t, where np.interp's array overhead would dominate.
        self._t = [float(x) for x in self.times]
        self._v = [float(x) for x in values[:, 0]] if self.width == 1 else list(values)

    def value(self, t):
        times, values = self._t, self._v
        j = bisect_right(times, t)
        if j == 0:
            return values[0]
        if j == len(times):
            return values[-1]
        t0, v0 = times[j - 1], values[j - 1]
        return v0 + (values[j] - v0) * ((t - t0) / (times[j] - t0))

    def __repr__(self):
        return f"Knots({len(self._t)} knots from {self.source})"


class Function(TimeInput):
    """A callable ``f(t)``; its value is checked at every call (shape, finite)."""

    def __init__(self, function, width, name):
        self.function, self.width, self.name = function, width, name

    def value(self, t):
        try:
            raw = self.function(t)
        except RodmolError:
            raise
        except Exception as exc:  # noqa: BLE001 (the user's function: chained, never lost)
            raise user_error(f"the function of `{self.name}`", exc, t) from exc
        if self.width == 1 and isinstance(raw, (float, int, np.floating, np.integer)) and math.isfinite(raw):
            return float(raw)  # the usual answer, without numpy's overhead at every evaluation
        arr = floats(raw)
        if arr is not None and self.width == 1 and arr.size == 1:
            arr = arr.reshape(())
        if arr is None or arr.shape != ((self.width,) if self.width > 1 else ()) or not np.all(np.isfinite(arr)):
            many = f"{self.width} finite numbers" if self.width > 1 else "a finite number"
            raise bad_return(f"the function of `{self.name}`", raw, t, f"it must return {many}")
        return float(arr) if self.width == 1 else arr

    def __repr__(self):
        return f"Function({self.function!r})"


def knot_times(root):
    """The times [s] of the knots of every :class:`Knots` input reachable
    from ``root`` (a model: its cables, loads, base motion and their inputs),
    sorted and unique. An input has kinks there, so a time integrator with
    large steps must stop at them rather than stride over a short ramp.
    """
    times, seen, stack = [], set(), [root]
    while stack:
        obj = stack.pop()
        if id(obj) in seen:
            continue
        seen.add(id(obj))
        if isinstance(obj, Knots):
            times.append(obj.times)
        elif isinstance(obj, (list, tuple)):
            stack.extend(obj)
        elif isinstance(obj, dict):
            stack.extend(obj.values())
        elif type(obj).__module__.startswith("rodmol") and hasattr(obj, "__dict__"):
            stack.extend(vars(obj).values())
    return np.unique(np.concatenate(times)) if times else np.empty(0)


def as_time_input(name, value, width=1, unit="", minimum=None):
    """Turn an accepted input (see the module docstring) into a :class:`TimeInput`.

    ``minimum`` (for example 0 for tensions) is checked on constants, knots
    and tables; a callable's values are checked where they are used.
    """
    if isinstance(value, TimeInput):
        return value
    if isinstance(value, (str, os.PathLike)):
        times, values = read_table(value, width, name, unit, minimum)
        return Knots(times, values, source=os.fspath(value))
    if callable(value):
        return Function(value, width, name)
    try:
        arr = np.asarray(value, dtype=float)
    except (TypeError, ValueError, OverflowError):
        raise ParameterError(f"`{name}` must be a number, {width} numbers, knots, a CSV path "
                             f"or a callable of t, got {short(value)}") from None
    if arr.shape == (width,) or (width == 1 and arr.ndim == 0):
        arr = arr.reshape(width)
        if not np.all(np.isfinite(arr)):
            raise ParameterError(f"`{name}` must be finite, got {short(value)}")
        _check_minimum(name, arr[None], minimum, unit, lambda i: "the value")
        return Constant(arr, width)
    times, values = knots(name, arr, width, value)
    _check_minimum(name, values, minimum, unit, lambda i: f"knot {i}")
    return Knots(times, values)


def knots(name, arr, width, raw=None):
    """Validated (times, values) of an array of knots (t, x_1..x_width)."""
    if arr.ndim != 2 or arr.shape[1] != 1 + width or len(arr) < 1:
        shape = "(t, value)" if width == 1 else f"(t, {width} values)"
        raise ParameterError(f"`{name}` knots must be a list of {shape} rows, got {short(raw)}")
    if not np.all(np.isfinite(arr)):
        raise ParameterError(f"`{name}` knots must be finite, got {short(raw)}")
    steps = np.diff(arr[:, 0])
    if np.any(steps <= 0.0):
        i = int(np.flatnonzero(steps <= 0.0)[0]) + 1
        raise ParameterError(f"`{name}` knot times must increase; knot {i} has t = {float(arr[i, 0])!r}")
    return arr[:, 0].copy(), arr[:, 1:].copy()


def _check_minimum(name, values, minimum, unit, where):
    if minimum is None:
        return
    bad = np.flatnonzero(np.any(values < minimum, axis=1))
    if len(bad):
        i = int(bad[0])
        raise ParameterError(f"`{name}` must be >= {minimum:g} {unit}; {where(i)} has "
                             f"{values[i].tolist() if values.shape[1] > 1 else float(values[i, 0])!r}")


def _number(cell):
    """The finite float in ``cell``, or None."""
    try:
        x = float(cell)
    except ValueError:
        return None
    return x if math.isfinite(x) else None


def read_table(path, width, what="value", unit="", minimum=None):
    """Read a CSV of a time column [s] and ``width`` value columns [``unit``].

    Returns (times (n,), values (n, width)). Errors name the file and the line;
    values below ``minimum`` are errors.
    """
    path = os.fspath(path)
    rows, header_seen = [], False
    try:
        handle = open(path, newline="", encoding="utf-8")  # noqa: SIM115 (closed by the with below)
    except (OSError, ValueError) as exc:
        reason = getattr(exc, "strerror", None) or str(exc)
        raise ParameterError(f"cannot read {what} table {path!r}: {reason}") from None
    with handle:
        try:
            lines = list(enumerate(csv.reader(handle), start=1))
        except UnicodeDecodeError as exc:
            raise ParameterError(f"{path}: not UTF-8 text ({exc})") from None
    for lineno, row in lines:
        cells = [c.strip() for c in row]
        if not any(cells) or cells[0].startswith("#"):
            continue
        values = [_number(c) for c in cells[:1 + width]]
        if not rows and not header_seen and any(v is None for v in values):
            header_seen = True  # the first row that is not all numbers is a header
            continue
        if not cells[0]:
            raise ParameterError(f"{path}:{lineno}: missing time in {row!r}")
        if len(cells) < 1 + width or not all(cells[1:1 + width]):
            raise ParameterError(f"{path}:{lineno}: missing {what} in {row!r} "
                                 f"(expected t and {width} value{'s' if width > 1 else ''})")
        if any(v is None for v in values):
            raise ParameterError(f"{path}:{lineno}: not a number in {row!r}")
        if rows and values[0] <= rows[-1][0]:
            raise ParameterError(f"{path}:{lineno}: time {values[0]!r} s does not increase "
                                 f"(previous {rows[-1][0]!r} s)")
        if minimum is not None and min(values[1:]) < minimum:
            raise ParameterError(f"{path}:{lineno}: negative {what} {min(values[1:])!r} {unit}")
        rows.append(values)
    if not rows:
        raise ParameterError(f"{path}: no (time, {what}) rows found")
    arr = np.array(rows)
    return arr[:, 0], arr[:, 1:]
