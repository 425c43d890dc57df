"""The outputs inverse statics of a :class:`rodmol.System` aims at: each rod's tip, tangent
and markers (:class:`rodmol.control._targets.Targets`) and bodies' poses."""

import numpy as np
from scipy.spatial.transform import Rotation

from .. import _checks
from ..discretise import rotations
from ..errors import ParameterError
from ._targets import Targets, check_aims, path_rows


def distinct(what, value, pool, kind):
    """The names ``value`` gives (a name or names; None: none), each in ``pool``, distinct."""
    if value is None:
        return []
    names = [value] if isinstance(value, str) else list(value)
    if len(set(names)) != len(names):
        raise ParameterError(f"`{what}` must name distinct {kind}s, got {_checks.short(value)}")
    for name in names:
        check_name(what, name, pool, kind)
    return names


def check_name(what, name, pool, kind):
    """Refuse a ``name`` given in ``what`` that is no {kind} of ``pool`` (the system's)."""
    if name not in pool:
        raise ParameterError(f"`{what}`: no {kind} named {name!r} in the system" + _checks.did_you_mean(name, pool))


def path_steps(system, tips, directions, poses):
    """The n targets of a path, each {"tip": {rod: (3,)} or None, "direction": ..., "pose":
    {body: pose} or None}, of ``tips`` and ``directions`` ({rod: (n, 3)}) and ``poses``
    ({body: n poses}) of ``system``; every sequence of the same length n. Each pose
    itself is checked by :class:`SystemTargets`."""
    rows = {}
    for what, value in (("tips", tips), ("directions", directions), ("poses", poses)):
        if value is None:
            continue
        if not isinstance(value, dict) or not value:
            kind = "body names to sequences of poses" if what == "poses" else "rod names to (n, 3) arrays"
            raise ParameterError(f"`{what}` must map {kind}, got {_checks.short(value)}")
        for name, sequence in value.items():
            check_name(what, name, system.bodies if what == "poses" else system.rods,
                       "body" if what == "poses" else "rod")
            label = f"{what}[{name!r}]"
            if what != "poses":
                sequence = path_rows(label, sequence)
            elif isinstance(sequence, (str, bytes)) or not hasattr(sequence, "__len__") or len(sequence) == 0:
                raise ParameterError(f"`{label}` must be a sequence of poses (each a position (3,) [m] or "
                                     f"(position, rotation)), got {_checks.short(sequence)}")
            rows[what, name] = sequence
    if not rows:
        raise ParameterError("give a path: `tips`, `directions` or `poses`")
    lengths = {key: len(sequence) for key, sequence in rows.items()}
    n = max(lengths.values())
    for (what, name), length in lengths.items():
        if length != n:
            raise ParameterError(f"`{what}[{name!r}]` has {length} targets, others {n}: give every path the "
                                 "same number of targets")
    steps = []
    for k in range(n):
        step = {"tip": None, "direction": None, "pose": None}
        for (what, name), sequence in rows.items():
            key = {"tips": "tip", "directions": "direction", "poses": "pose"}[what]
            step[key] = {**(step[key] or {}), name: sequence[k]}
        steps.append(step)
    return steps


class SystemTargets:
    """The outputs aimed at: each rod's (:class:`Targets`), then each body's position and
    w_d times its rotation's difference from the target's (a rotation vector, global)."""

    def __init__(self, system, assembly, tip, direction, markers, pose, direction_weight, marker_weight):
        self.assembly = assembly
        given = {}
        for what, value in (("tip", tip), ("direction", direction), ("markers", markers)):
            if value is None:
                continue
            if not isinstance(value, dict) or not value:
                raise ParameterError(f"`{what}` must map rod names to targets, got {_checks.short(value)}")
            for name, aim in value.items():
                check_name(what, name, system.rods, "rod")
                given.setdefault(name, {})[what] = aim
        marker_weight = _checks.positive("marker_weight", marker_weight)
        if direction_weight is not None:
            direction_weight = _checks.positive("direction_weight", direction_weight, " m")
        self.rods, self.tips, parts = {}, {}, []
        for name in system.rods:  # in the system's order
            if name not in given:
                continue
            model, aims = system.rods[name], given[name]
            try:
                point, tangent, names, positions = check_aims(model, aims.get("tip"), aims.get("direction"),
                                                              aims.get("markers"))
            except ParameterError as exc:
                raise ParameterError(f"rod {name!r}: {exc}") from None
            weight = model.rod.length if direction_weight is None else direction_weight
            targets = Targets(model, assembly.rods[name].layout, point is not None, tangent is not None, names,
                              weight, marker_weight)
            self.rods[name] = targets
            parts.append(targets.aim(point, tangent, positions))
            if point is not None:
                self.tips[name] = point
        self.bodies = self._poses(system, pose)
        self.weight = (max(m.rod.length for m in system.rods.values()) if direction_weight is None
                       else direction_weight)
        parts += [target for target, _ in self.bodies.values()]
        parts += [np.zeros(3) for _, rotation in self.bodies.values() if rotation is not None]
        if not parts:
            raise ParameterError("give a target: `tip`, `direction`, `markers` or `pose`")
        self.aim = np.concatenate(parts)

    @staticmethod
    def _poses(system, pose):
        """{body: (position (3,), rotation (3, 3) or None)} of the checked ``pose``."""
        if pose is None:
            return {}
        if not isinstance(pose, dict) or not pose:
            raise ParameterError(f"`pose` must map body names to a position or (position, rotation), got "
                                 f"{_checks.short(pose)}")
        out = {}
        for name, value in pose.items():
            check_name("pose", name, system.bodies, "body")
            arr = _checks.floats(value)
            if arr is not None and arr.shape == (3,):
                out[name] = (_checks.vector3(f"pose[{name!r}]", value), None)
                continue
            try:
                position, rotation = value
            except (TypeError, ValueError):
                raise ParameterError(f"`pose[{name!r}]` must be a position (3,) [m] or (position, rotation "
                                     f"(3, 3)), got {_checks.short(value)}") from None
            out[name] = (_checks.vector3(f"pose[{name!r}] position", position),
                         _checks.rotation(f"pose[{name!r}] rotation", rotation))
        return out

    def _body(self, y, name):
        part = self.assembly.bodies[name]
        return y[part.fields["x"]], rotations.matrices(y[part.fields["Q"]])

    def values(self, y):
        parts = [targets.values(y[self.assembly.parts[name]]) for name, targets in self.rods.items()]
        parts += [self._body(y, name)[0] for name in self.bodies]
        for name, (_, rotation) in self.bodies.items():
            if rotation is not None:
                turn = self._body(y, name)[1] @ rotation.T
                parts.append(self.weight * Rotation.from_matrix(turn).as_rotvec())
        return np.concatenate(parts)

    def errors(self, y):
        """({rod: tip error}, {rod: angle}, {rod: {marker: error}}, {body: position error},
        {body: rotation error})."""
        tips, angles, marks, k = {}, {}, {}, 0
        for name, targets in self.rods.items():
            aim = self.aim[k:k + targets.size]
            k += targets.size
            tip, angle, found = targets.errors(y[self.assembly.parts[name]], aim)
            if tip is not None:
                tips[name] = tip
            if angle is not None:
                angles[name] = angle
            if found:
                marks[name] = found
        positions, turns = {}, {}
        for name, (target, rotation) in self.bodies.items():
            position, matrix = self._body(y, name)
            positions[name] = float(np.linalg.norm(position - target))
            if rotation is not None:
                turns[name] = float(np.linalg.norm(Rotation.from_matrix(matrix @ rotation.T).as_rotvec()))
        return tips, angles, marks, positions, turns
