"""Small validators shared by the parameter classes (never ``assert``)."""

import difflib
import math

import numpy as np

from .errors import ParameterError, UserFunctionError

#: Longest representation of a value quoted in a message [characters].
SHORT = 200


def short(value, limit=SHORT):
    """``repr(value)``, cut to ``limit`` characters (a 100,000-entry list is not echoed whole)."""
    if isinstance(value, np.ndarray) and value.size > 64:
        return f"<array of shape {value.shape}, dtype {value.dtype}>"
    try:
        text = repr(value)
    except Exception as exc:  # noqa: BLE001 (a user object whose repr fails is still named)
        return f"<{type(value).__name__} object (repr failed: {type(exc).__name__})>"
    return text if len(text) <= limit else text[:limit] + f"... ({len(text)} characters)"


def user_error(what, exc, t=None):
    """The :class:`UserFunctionError` for exception ``exc`` raised by the user's
    function ``what``, to be raised ``from exc``."""
    text = str(exc)
    text = text if len(text) <= SHORT else text[:SHORT] + f"... ({len(text)} characters)"
    when = f" (at t = {float(t):.6g} s)" if t is not None else ""
    return UserFunctionError(f"{what} raised {type(exc).__name__}: {text}{when}", t=t)


def bad_return(what, value, t, expected):
    """The :class:`UserFunctionError` for the user's function ``what`` that
    returned ``value`` at time ``t`` [s] where ``expected`` was due."""
    shown = repr(float(value)) if isinstance(value, np.floating) else short(value)
    return UserFunctionError(f"{what} returned {shown} at t = {float(t):.6g} s; {expected}", t=t)


def floats(value):
    """``value`` as a float array, or None if it is not numbers (ragged, huge, text)."""
    if isinstance(value, (str, bytes)):
        return None
    try:
        return np.asarray(value, dtype=float)
    except (TypeError, ValueError, OverflowError):
        return None


def finite(name, value):
    """Return ``value`` as a float, or raise if it is not a finite number."""
    if isinstance(value, (bool, np.bool_, str, bytes)):  # float("1e5") and float(True) work
        raise ParameterError(f"`{name}` must be a number, got {short(value)}")
    try:
        x = float(value)
    except (TypeError, ValueError, OverflowError):
        raise ParameterError(f"`{name}` must be a number, got {short(value)}") from None
    if not math.isfinite(x):
        raise ParameterError(f"`{name}` must be finite, got {short(value)}")
    return x


def positive(name, value, unit=""):
    x = finite(name, value)
    if x <= 0.0:
        raise ParameterError(f"`{name}` must be > 0{unit}, got {short(value)}")
    return x


def non_negative(name, value, unit=""):
    x = finite(name, value)
    if x < 0.0:
        raise ParameterError(f"`{name}` must be >= 0{unit}, got {short(value)}")
    return x


def rotation(name, value, tol=1e-6):
    """Return ``value`` as a proper 3x3 rotation matrix (orthonormal to ``tol``, det +1);
    ``name`` is the parameter's name in the message."""
    try:
        r = np.asarray(value, dtype=float)
    except (TypeError, ValueError, OverflowError):
        r = None
    if r is None or r.shape != (3, 3) or not np.all(np.isfinite(r)):
        raise ParameterError(f"`{name}` must be a 3x3 matrix of finite numbers, got {short(value)}")
    if not (np.allclose(r.T @ r, np.eye(3), atol=tol) and np.linalg.det(r) > 0.0):
        raise ParameterError(f"`{name}` must be a rotation matrix (orthonormal, det +1), got {short(value)}")
    return r


def vector3(name, value):
    """Return ``value`` as a finite float array of shape (3,)."""
    try:
        arr = np.asarray(value, dtype=float)
    except (TypeError, ValueError, OverflowError):
        raise ParameterError(f"`{name}` must be three numbers, got {short(value)}") from None
    if arr.shape != (3,):
        raise ParameterError(f"`{name}` must have three components, got {short(value)}")
    if not np.all(np.isfinite(arr)):
        raise ParameterError(f"`{name}` must be finite, got {short(value)}")
    return arr


def integer_at_least(name, value, minimum):
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
        raise ParameterError(f"`{name}` must be an integer, got {short(value)}")
    if value < minimum:
        raise ParameterError(f"`{name}` must be >= {minimum}, got {short(value)}")
    return int(value)


def flag(name, value):
    """``value`` as a bool; only True and False (numpy's too) are accepted."""
    if not isinstance(value, (bool, np.bool_)):
        raise ParameterError(f"`{name}` must be True or False, got {short(value)}")
    return bool(value)


def choice(name, value, options):
    """``value`` if it is one of the strings ``options``, else a ParameterError
    naming it (an array or other unhashable value is refused, not compared)."""
    if not (isinstance(value, str) and value in options):
        raise ParameterError(f"unknown `{name}` {short(value)}{did_you_mean(value, options)}; "
                             f"choose one of {', '.join(map(repr, options))}")
    return value


def items(name, value, kind, what):
    """``value`` as a tuple of ``kind`` instances (a list, a tuple or another
    iterable of them); ``what`` names one item in messages ("a rodmol.Cable")."""
    if isinstance(value, kind):
        raise ParameterError(f"`{name}` must be a sequence (a single one: {name}=[...]), got {short(value)}")
    if isinstance(value, (str, bytes, dict)) or not hasattr(value, "__iter__"):
        raise ParameterError(f"`{name}` must be a sequence, each item {what}, got {short(value)}")
    try:
        found = tuple(value)
    except Exception:  # noqa: BLE001 (an iterable that fails to iterate is refused, named)
        raise ParameterError(f"`{name}` must be a sequence, each item {what}, got {short(value)}") from None
    for i, item in enumerate(found):
        if not isinstance(item, kind):
            raise ParameterError(f"`{name}[{i}]` must be {what}, got {short(item)}")
    return found


def did_you_mean(value, options):
    """``"; did you mean 'x'?"`` for a near miss among ``options``, else ``""``."""
    if not isinstance(value, str):
        return ""
    close = difflib.get_close_matches(value, [str(o) for o in options], n=1, cutoff=0.6)
    return f"; did you mean {close[0]!r}?" if close else ""
