"""The inputs a stepping simulator holds on a :class:`rodmol.System`: each rod's
(its :class:`~rodmol.control.held.HeldInputs`: cable tensions, motor
displacements, point loads) and each driven body's velocities.

A held row of a System is its rods' rows one after the other (in ``rods``
order), then each driven body's velocity and angular velocity [m/s, rad/s],
body frame, as its :class:`rodmol.BaseMotion` gives them. The System with
other inputs is the same System (joints, contacts, base bodies) with its rods
and driven bodies replaced: only inputs change, never the loads' order the
joints and contacts refer to.
"""

import copy
import dataclasses
import functools

from .. import _checks
from ..base_motion import BaseMotion
from ..errors import ParameterError
from .held import HeldInputs

#: A driven body's held velocities, in the order of its row.
MOTION_KINDS = ("velocity", "angular_velocity")


@dataclasses.dataclass(frozen=True)
class SystemHeld(HeldInputs):
    """Which inputs of a System are held: ``rods`` maps each rod to its
    :class:`HeldInputs`, ``driven`` names the driven bodies (in ``bodies`` order)."""

    rods: dict = None
    driven: tuple = ()

    @classmethod
    def of(cls, system):
        rods = {}
        for name, model in system.rods.items():
            try:
                rods[name] = HeldInputs.of(model)
            except ParameterError as exc:
                raise ParameterError(f"rod {name!r}: {exc}") from None
        driven = tuple(name for name, body in system.bodies.items() if body.driven)
        kinds = [kind for held in rods.values() for kind in held.kinds] + list(MOTION_KINDS) * len(driven)
        targets = [(name, i) for name, held in rods.items() for i in held.targets]
        targets += [(name, kind) for name in driven for kind in MOTION_KINDS]
        return cls(system, tuple(kinds), tuple(targets), rods, driven)

    @functools.cached_property
    def _spans(self):
        """Each rod's and driven body's slice of a held row."""
        spans, start = {}, 0
        for name, held in self.rods.items():
            spans[name] = slice(start, start + len(held.kinds))
            start += len(held.kinds)
        for name in self.driven:
            spans[name] = slice(start, start + len(MOTION_KINDS))
            start += len(MOTION_KINDS)
        return spans

    def initial_row(self, t):
        """The held values at time ``t`` [s]: the rods' inputs and the driven bodies' velocities there."""
        row = []
        for held in self.rods.values():
            row += held.initial_row(t)
        for name in self.driven:
            row += [value.astype(float) for value in map(_checks.floats, self.model.bodies[name].motion.velocities(t))]
        return tuple(row)

    def model_with(self, inputs):
        """The System with held input ``j`` replaced by the time input ``inputs[j]``."""
        system = copy.copy(self.model)
        system.rods = {name: held.model_with(inputs[self._spans[name]]) for name, held in self.rods.items()}
        system.bodies = dict(system.bodies)
        for name in self.driven:
            velocity, angular = inputs[self._spans[name]]
            body = system.bodies[name]
            motion = BaseMotion(velocity.value, angular.value, body.motion.position, body.motion.rotation)
            system.bodies[name] = dataclasses.replace(body, motion=motion, position=None, rotation=None)
        return system

    def by_name(self, row):
        """The held values of ``row``: ``{rod: {"tensions": ..., "displacements": ..., "loads": ...},
        driven body: {"velocity": (3,), "angular_velocity": (3,)}}``."""
        out = {name: held.by_name(row[self._spans[name]]) for name, held in self.rods.items()}
        for name in self.driven:
            out[name] = {kind: value.copy() for kind, value in zip(MOTION_KINDS, row[self._spans[name]])}
        return out

    def command(self, row, tensions=None, displacements=None, loads=None, motions=None):
        """``row`` with the commanded values put in, checked: ``tensions``, ``displacements`` and
        ``loads`` as dicts {rod: what the rod's :meth:`HeldInputs.command` takes}, ``motions`` a
        dict {driven body: {"velocity": (3,), "angular_velocity": (3,)}} [m/s, rad/s], body frame."""
        row = list(row)
        for arg, given in (("tensions", tensions), ("displacements", displacements), ("loads", loads)):
            for rod, value in _per_part(arg, given, "rod", list(self.rods)):
                span = self._spans[rod]
                try:
                    row[span] = self.rods[rod].command(tuple(row[span]), **{arg: value})
                except ParameterError as exc:
                    raise ParameterError(f"rod {rod!r}: {exc}") from None
        for body, value in _per_part("motions", motions, "driven body", list(self.driven), self.model.bodies):
            if not isinstance(value, dict):
                raise ParameterError(f"`motions[{body!r}]` must be a dict {{'velocity': (3,), 'angular_velocity': "
                                     f"(3,)}} [m/s, rad/s], body frame, got {_checks.short(value)}")
            span = self._spans[body]
            for key, vector in value.items():
                if key not in MOTION_KINDS:
                    raise ParameterError(f"`motions[{body!r}]`: unknown key {_checks.short(key)}; valid: "
                                         f"{', '.join(map(repr, MOTION_KINDS))}")
                row[span.start + MOTION_KINDS.index(key)] = _checks.vector3(f"motions[{body!r}][{key!r}]",
                                                                            vector).copy()
        return tuple(row)


def _per_part(arg, given, what, valid, others=()):
    """The (part name, value) pairs of the argument ``arg`` (a dict by part, or None), each
    part one of ``valid`` (else refused naming it and the valid ones; a name in ``others``
    is a part that exists but takes no such input)."""
    if given is None:
        return []
    if not isinstance(given, dict):
        raise ParameterError(f"`{arg}` of a System must be a dict {{{what} name: ...}}, got {_checks.short(given)}")
    for key in given:
        if key not in valid:
            exists = " (it is not driven: its motion is not held)" if key in others else _checks.did_you_mean(key, valid)
            listed = ", ".join(map(repr, valid)) or "none"
            raise ParameterError(f"`{arg}`: unknown {what} {_checks.short(key)}{exists}; valid: {listed}")
    return list(given.items())
