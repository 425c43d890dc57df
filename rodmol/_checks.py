"""Small validators shared by the parameter classes (never ``assert``)."""

import math

import numpy as np

from .errors import ParameterError


def finite(name, value):
    """Return ``value`` as a float, or raise if it is not a finite number."""
    if isinstance(value, (bool, np.bool_)):
        raise ParameterError(f"`{name}` must be a number, got {value!r}")
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise ParameterError(f"`{name}` must be a number, got {value!r}") from None
    if not math.isfinite(x):
        raise ParameterError(f"`{name}` must be finite, got {value!r}")
    return x


def positive(name, value, unit=""):
    x = finite(name, value)
    if x <= 0.0:
        raise ParameterError(f"`{name}` must be > 0{unit}, got {value!r}")
    return x


def non_negative(name, value, unit=""):
    x = finite(name, value)
    if x < 0.0:
        raise ParameterError(f"`{name}` must be >= 0{unit}, got {value!r}")
    return x


def vector3(name, value):
    """Return ``value`` as a finite float array of shape (3,)."""
    try:
        arr = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise ParameterError(f"`{name}` must be three numbers, got {value!r}") from None
    if arr.shape != (3,):
        raise ParameterError(f"`{name}` must have three components, got {value!r}")
    if not np.all(np.isfinite(arr)):
        raise ParameterError(f"`{name}` must be finite, got {value!r}")
    return arr


def integer_at_least(name, value, minimum):
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
        raise ParameterError(f"`{name}` must be an integer, got {value!r}")
    if value < minimum:
        raise ParameterError(f"`{name}` must be >= {minimum}, got {value!r}")
    return int(value)
