"""A run's derivative by one parameter: :class:`Derivative`, shaped like the run's result.

Every field of a result (a :class:`rodmol.Result`'s ``states``, ``tip``,
``positions``, ``markers``, ``tensions``, ``internal_force`` ...; a
:class:`rodmol.SystemResult`'s rods and bodies by ``result[name]``) is
derived from its states by the result's own post-processing. Its derivative
is ONE rule: the central difference of that post-processing along the
sensitivities S = dy/dp, each side built by the model at its perturbed value::

    d field / dp = [field(y + h S; p + h) - field(y - h S; p - h)] / (2 h)

so a field's direct dependence on the parameter (the tip strain's on E, the
tensions' on a knot value) is in it too. Units: the field's per unit of the
parameter; frames as the field's (``tip`` global, ``curvature`` local ...).
"""

import numpy as np

from .errors import ParameterError

#: Fields that are not differentiated: the times, and what describes the run.
AS_THEY_ARE = ("t", "success", "message", "stats", "meta", "error", "names", "rods", "bodies")


class Derivative:
    """The derivative of a result by one parameter: ``plus`` and ``minus`` are the
    result's post-processing on each side of a central difference of step ``h``
    (lists of them, for a parameter of several components: every field then has
    a leading axis over the components, e.g. a knot tension's knots)."""

    def __init__(self, plus, minus, h, stacked=False):
        self._plus, self._minus = list(plus), list(minus)
        self._h, self._stacked = np.asarray(h, dtype=float).reshape(-1), bool(stacked)
        self._cache = {}

    def __getattr__(self, name):
        if name.startswith("_"):
            raise AttributeError(name)
        cache = self.__dict__["_cache"]
        if name not in cache:
            if name in AS_THEY_ARE:
                return getattr(self._plus[0], name)
            pairs = [(getattr(a, name), getattr(b, name)) for a, b in zip(self._plus, self._minus)]
            if callable(pairs[0][0]):
                return _method(self, pairs)
            cache[name] = self._combine([_difference(a, b, h) for (a, b), h in zip(pairs, self._h)])
        return cache[name]

    def __getitem__(self, name):
        """The derivative of ``result[name]`` (a System's rod or body)."""
        return Derivative([a[name] for a in self._plus], [b[name] for b in self._minus], self._h, self._stacked)

    def _combine(self, values):
        if not self._stacked:
            return values[0]
        if isinstance(values[0], Derivative):
            return Derivative([p for v in values for p in v._plus], [m for v in values for m in v._minus],
                              np.concatenate([v._h for v in values]), True)
        if isinstance(values[0], tuple):
            return tuple(np.stack(parts) for parts in zip(*values))
        return np.stack(values)

    def __repr__(self):
        n = len(self._plus)
        return f"Derivative({type(self._plus[0]).__name__}{f', {n} components' if self._stacked else ''})"


def _method(derivative, pairs):
    """A result's method, differentiated: its values on each side, differenced."""

    def call(*args, **kwargs):
        values = [_difference(a(*args, **kwargs), b(*args, **kwargs), h) for (a, b), h in zip(pairs, derivative._h)]
        return derivative._combine(values)
    return call


def _difference(a, b, h):
    if isinstance(a, tuple):
        return tuple(_difference(x, y, h) for x, y in zip(a, b))
    if isinstance(a, (np.ndarray, float, int, np.floating)) and not isinstance(a, bool):
        return (np.asarray(a, dtype=float) - np.asarray(b, dtype=float)) / (2.0 * h)
    return Derivative([a], [b], [h])


def lookup(result, key):
    """``result``'s derivative by the parameter ``key`` (one of those asked of
    :func:`rodmol.simulate` with ``sensitivities=``), or a ParameterError naming the key."""
    table = result.__dict__.get("sensitivities") or {}
    if key not in table:
        asked = ", ".join(map(repr, table)) or "none (simulate(..., sensitivities=[keys]) computes them)"
        raise ParameterError(f"no sensitivity to {key!r} in this result; its sensitivities: {asked}")
    return table[key]
