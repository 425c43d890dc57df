"""The inputs a stepping simulator holds: cable tensions, motor displacements,
point loads, as time inputs the model reads like any other.

While a step is integrated each held input is a :class:`Held` value, the same
whatever the time it is read at (a zero-order hold: the controller's command
is a constant over the control period, so nothing it computed is evaluated
at the integrator's trial states). The record of what was held is a
:class:`ZeroOrderHold` over the frames, from which the Result's tensions,
actuator positions and loads are derived.
"""

import dataclasses
import functools
from bisect import bisect_left

import numpy as np

from .. import _checks
from ..cables import Tension
from ..errors import ParameterError
from ..inputs import Constant, TimeInput
from ..loads import PointForce, PointMoment

#: The point loads whose vector a simulator holds.
HELD_LOADS = (PointForce, PointMoment)
#: Components of each kind of held input (a cable's one number, a vector's three).
WIDTHS = {"tension": 1, "displacement": 1, "load": 3, "velocity": 3, "angular_velocity": 3}


class Held(TimeInput):
    """A value [its input's unit] set between steps; ``value(t)`` ignores t. A held
    tension is read by ``SemiDiscrete.read_held``, not at every right-hand side."""

    held = True

    def __init__(self, current, width):
        self.current, self.width = current, width

    def value(self, t):
        return self.current

    def __repr__(self):
        return f"Held({self.current!r})"


class ZeroOrderHold(TimeInput):
    """The record of a held input: ``rows[k][index]`` acted over (times[k-1], times[k]]
    (row 0 at and before times[0]; the last row after the last time)."""

    def __init__(self, times, rows, index, width):
        self.times, self.rows, self.index, self.width = times, rows, index, width

    def value(self, t):
        k = min(bisect_left(self.times, t), len(self.rows) - 1)
        return self.rows[k][self.index]

    def __repr__(self):
        return f"ZeroOrderHold({len(self.rows)} values)"


@dataclasses.dataclass(frozen=True)
class HeldInputs:
    """Which inputs of a model are held, in the order of a held row.

    ``kinds[j]`` is ``"tension"``, ``"displacement"`` or ``"load"``;
    ``targets[j]`` the index of the cable or load in the model.
    """

    model: object
    kinds: tuple
    targets: tuple

    @classmethod
    def of(cls, model):
        kinds, targets = [], []
        for i, cable in enumerate(model.cables):
            if cable.actuated:
                kinds.append("displacement")
            elif cable.tension.feedback:
                raise ParameterError(
                    f"cable {cable.name!r} has a feedback tension T(t, state): a stepping simulator "
                    "holds the tensions its controller gives to step(), so give the cable a plain "
                    "tension (its initial value) and compute the law outside")
            else:
                kinds.append("tension")
            targets.append(i)
        for i, load in enumerate(model.loads):
            if isinstance(load, HELD_LOADS):
                kinds.append("load")
                targets.append(i)
        return cls(model, tuple(kinds), tuple(targets))

    @functools.cached_property
    def _names(self):
        """The cables' names and the loads' (None for a load without one), a step looks them up."""
        return ([c.name for c in self.model.cables], [getattr(x, "name", None) for x in self.model.loads])

    @functools.cached_property
    def _slots(self):
        """(kind, index of the cable or load) -> position in a held row."""
        return {(kind, i): j for j, (kind, i) in enumerate(zip(self.kinds, self.targets))}

    def initial_row(self, t):
        """The held values at time ``t`` [s]: the model's inputs there."""
        row = []
        for kind, i in zip(self.kinds, self.targets):
            if kind == "tension":
                row.append(float(self.model.cables[i].tension_at(t)))
            elif kind == "displacement":
                row.append(float(self.model.cables[i].displacement.value(t)))
            else:
                load = self.model.loads[i]
                row.append(np.array(getattr(load, load._what).value(t), dtype=float))
        return tuple(row)

    def model_with(self, inputs):
        """The model with held input ``j`` replaced by the time input ``inputs[j]``."""
        m = self.model
        cables, loads = list(m.cables), list(m.loads)
        for kind, i, signal in zip(self.kinds, self.targets, inputs):
            if kind == "tension":
                cables[i] = dataclasses.replace(cables[i], tension=Tension(signal))
            elif kind == "displacement":
                cables[i] = dataclasses.replace(cables[i], displacement=signal, tension=None)
            else:
                loads[i] = dataclasses.replace(loads[i], **{loads[i]._what: signal})
        return m.replace(cables=cables, loads=loads)

    def constant(self, row):
        """The model holding ``row`` for all time (constant inputs), as ``rodmol.linearize``
        and ``rodmol.equilibrium`` take it."""
        return self.model_with([Constant(np.atleast_1d(value), WIDTHS[kind])
                                for kind, value in zip(self.kinds, row)])

    def live(self, row):
        """(model, its :class:`Held` inputs) holding ``row``."""
        held = [Held(value, WIDTHS[kind]) for kind, value in zip(self.kinds, row)]
        return self.model_with(held), held

    def recorded(self, times, rows):
        """The model whose inputs are the record ``rows`` at frame ``times`` (:class:`ZeroOrderHold`)."""
        return self.model_with([ZeroOrderHold(times, rows, j, WIDTHS[kind])
                                for j, kind in enumerate(self.kinds)])

    def by_name(self, row):
        """The held values of ``row`` by name: ``{"tensions": {cable: N}, "displacements":
        {cable: m}, "loads": {load: (3,)}}``."""
        out = {"tensions": {}, "displacements": {}, "loads": {}}
        for kind, i, value in zip(self.kinds, self.targets, row):
            pool = self.model.loads if kind == "load" else self.model.cables
            out[f"{kind}s"][pool[i].name] = value.copy() if kind == "load" else value
        return out

    def command(self, row, tensions=None, displacements=None, loads=None, motions=None):
        """``row`` with the commanded values put in, checked (names, indices, values);
        ``motions`` (a System's driven bodies') are refused: a Model has none."""
        if motions is not None:
            raise ParameterError(f"`motions` {_checks.short(motions)}: they drive the driven bodies of a "
                                 "rodmol.System; a Model has none")
        row = list(row)
        for what, given in (("tension", tensions), ("displacement", displacements), ("load", loads)):
            if given is None:
                continue
            for key, value in self._items(what, given):
                j = self._slot(what, key)
                row[j] = self._value(what, key, value)
        return tuple(row)

    def _items(self, what, given):
        arg = f"{what}s"
        if isinstance(given, dict):
            return given.items()
        if what == "load" or isinstance(given, (str, bytes)):
            raise ParameterError(f"`{arg}` must be a dict {{name or index: value}}, got {_checks.short(given)}")
        values = _checks.floats(given)
        count = len(self.model.cables)
        if values is None or values.shape != (count,):
            raise ParameterError(f"`{arg}` must be a dict {{cable name or index: value}} or {count} "
                                 f"numbers (one per cable), got {_checks.short(given)}")
        return enumerate(values)

    def _slot(self, what, key):
        """Position in the row of the input ``key`` (a name or an index among the cables or loads)."""
        pool = self.model.loads if what == "load" else self.model.cables
        names = self._names[what == "load"]
        if isinstance(key, (int, np.integer)) and not isinstance(key, bool):
            if not 0 <= key < len(pool):
                raise ParameterError(f"`{what}s`: index {key!r} is out of range (the model has "
                                     f"{len(pool)} {'loads' if what == 'load' else 'cables'})")
            i = int(key)
        elif isinstance(key, str) and names.count(key) == 1:
            i = names.index(key)
        elif isinstance(key, str) and key in names:
            raise ParameterError(f"`{what}s`: {names.count(key)} loads are named {key!r}: give the "
                                 "index, or distinct names")
        else:
            raise ParameterError(f"`{what}s`: unknown {'load' if what == 'load' else 'cable'} "
                                 f"{_checks.short(key)}{_checks.did_you_mean(key, names)}; valid: "
                                 f"{', '.join(map(repr, names))} or an index")
        j = self._slots.get((what, i))
        if j is not None:
            return j
        label = f"{'load' if what == 'load' else 'cable'} {names[i]!r}"
        if what == "load":
            raise ParameterError(f"`loads`: {label} is not a point load (only PointForce and PointMoment "
                                 "vectors are held)")
        other = "displacements" if what == "tension" else "tensions"
        raise ParameterError(f"`{what}s`: {label} is {'displacement' if what == 'tension' else 'tension'}-"
                             f"controlled; command it through `{other}`")

    @staticmethod
    def _value(what, key, value):
        name = f"{what}s[{key!r}]"
        if what == "load":
            return _checks.vector3(name, value).copy()
        if what == "tension":
            return _checks.non_negative(name, value, " N")
        return _checks.finite(name, value)
