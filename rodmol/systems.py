"""Several rods and rigid bodies joined into one model: :class:`Joint`, :class:`System`.

This stop supports *tree* joints only: a rod's base clamped to a rigid body
or to the world (a base with no joint stays clamped where its Model's
``base`` puts it). Joints at a rod's tip or between two bodies, pins and
closed loops raise :class:`rodmol.errors.NotSupportedYet`; they will be one
more joint kind (a penalty joint, as ``rodmol.Hold``).
"""

from dataclasses import dataclass

import numpy as np

from . import _checks
from .base_motion import BaseMotion
from .bodies import RigidBody
from .errors import NotSupportedYet, ParameterError
from .model import Model
from .parameters import Medium

#: Joint kinds (only "clamp" today).
JOINT_KINDS = ("clamp",)
#: Ends of a rod a joint may hold (only "base" today).
ROD_ENDS = ("base",)
_IDENTITY = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))


@dataclass(frozen=True)
class Joint:
    """A joint between two ends.

    Parameters
    ----------
    a, b : end
        Each ``"world"``, ``(body_name, point)`` or ``(body_name, point,
        rotation)``, a point [m] of a body in its body frame and the rotation
        (joint frame to body frame, default identity), or ``(rod_name,
        "base")``. A clamp of a rod's base to a body point makes the rod's
        base frame the joint frame: the rod leaves the body along the joint
        frame's x axis.
    kind : str
        ``"clamp"`` (all six relative motions fixed).
    """

    a: object
    b: object
    kind: str = "clamp"

    def __post_init__(self):
        _checks.choice("kind", self.kind, JOINT_KINDS)
        object.__setattr__(self, "a", _end("a", self.a))
        object.__setattr__(self, "b", _end("b", self.b))


def _end(name, value):
    """A checked joint end: "world", ("rod", name, end) or ("body", name, point, rotation)."""
    if isinstance(value, str) and value == "world":
        return value
    if isinstance(value, tuple) and len(value) == 2 and isinstance(value[0], str) and isinstance(value[1], str):
        return ("rod", value[0], value[1])
    if isinstance(value, tuple) and len(value) in (2, 3) and isinstance(value[0], str):
        point = _checks.vector3(f"{name}` point `", value[1])
        rotation = np.array(BaseMotion(rotation=value[2] if len(value) == 3 else _IDENTITY).rotation)
        return ("body", value[0], point, rotation)
    raise ParameterError(f"joint end `{name}` must be 'world', (body_name, point[, rotation]) or "
                         f"(rod_name, 'base'), got {_checks.short(value)}")


class System:
    """Named rods and rigid bodies joined by joints.

    Parameters
    ----------
    rods : dict of str to Model
        Each rod as a single-rod :class:`Model` (its grid, material, cables,
        loads, markers). Its gravity and medium are replaced by the system's.
    bodies : dict of str to RigidBody
    joints : sequence of Joint
        Tree joints only: each rod's base clamped at most once, to the world
        or to a body. A rod base with no joint is clamped to the world where
        its Model's ``base`` says (and moves as it says).
    medium : Medium, str or None
        The fluid around every rod and body (a preset name as for Model).
    gravity : (3,) float
        Gravitational acceleration [m/s^2], global.

    Attributes
    ----------
    rods, bodies : dict
        As given (the rods rebuilt with the system's gravity and medium).
    clamps : dict of str to (body_name or None, point (3,), rotation (3, 3))
        Where each rod's base is held: a body (or None for the world), the
        point [m] and the rotation (base to body frame; to global for the world).
    """

    def __init__(self, rods, bodies=None, joints=(), *, medium=None, gravity=(0.0, -9.81, 0.0)):
        bodies = {} if bodies is None else bodies
        for what, mapping, kind in (("rods", rods, Model), ("bodies", bodies, RigidBody)):
            if not isinstance(mapping, dict):
                raise ParameterError(f"`{what}` must be a dict of names to {kind.__name__}, got "
                                     f"{_checks.short(mapping)}")
            for key, item in mapping.items():
                if not isinstance(key, str) or not key:
                    raise ParameterError(f"`{what}` names must be non-empty strings, got {key!r}")
                if not isinstance(item, kind):
                    raise ParameterError(f"`{what}[{key!r}]` must be a rodmol.{kind.__name__}, got "
                                         f"{_checks.short(item)}")
        if not rods:
            raise ParameterError("`rods` must hold at least one rod")
        shared = sorted(set(rods) & set(bodies))
        if shared or "world" in rods or "world" in bodies:
            clash = shared[0] if shared else "world"
            raise ParameterError(f"the name {clash!r} is used twice (or is 'world'): names must be unique")
        self.gravity = _checks.vector3("gravity", gravity)
        probe = next(iter(rods.values())).replace(medium=medium)  # Model checks the medium
        self.medium = probe.medium
        if not isinstance(self.medium, Medium):
            raise ParameterError(f"`medium` must be a Medium, a preset name or None, got {medium!r}")
        self.rods = {name: m.replace(gravity=tuple(self.gravity), medium=self.medium)
                     for name, m in rods.items()}
        self.bodies = dict(bodies)
        self.joints = _checks.items("joints", joints, Joint, "a rodmol.Joint")
        self.clamps = self._clamps()

    def _clamps(self):
        """Each jointed rod's base: (body or None, point, rotation), checking the graph."""
        clamps = {}
        for i, joint in enumerate(self.joints):
            ends = (joint.a, joint.b)
            rod_ends = [e for e in ends if isinstance(e, tuple) and e[0] == "rod"]
            for e in rod_ends:
                if e[1] not in self.rods:
                    raise ParameterError(f"`joints[{i}]` names the rod {e[1]!r}, which is not in `rods`"
                                         f"{_checks.did_you_mean(e[1], self.rods)}")
                if e[2] not in ROD_ENDS:
                    raise NotSupportedYet(f"`joints[{i}]` holds the {e[2]!r} of rod {e[1]!r}: only a rod's "
                                          "'base' can be jointed yet (tip joints are not supported yet)")
            for e in ends:
                if isinstance(e, tuple) and e[0] == "body" and e[1] not in self.bodies:
                    raise ParameterError(f"`joints[{i}]` names the body {e[1]!r}, which is not in `bodies`"
                                         f"{_checks.did_you_mean(e[1], self.bodies)}")
            if len(rod_ends) != 1:
                raise NotSupportedYet(f"`joints[{i}]` joins {_describe(ends[0])} and {_describe(ends[1])}: "
                                      "only a rod's base to a body or to the world is supported yet")
            rod = rod_ends[0][1]
            other = ends[1] if ends[0] is rod_ends[0] else ends[0]
            if rod in clamps:
                raise NotSupportedYet(f"`joints[{i}]`: the base of rod {rod!r} is already jointed; "
                                      "closed loops are not supported yet")
            base = self.rods[rod].base
            if other == "world":  # where the Model's base is
                if not base.fixed:
                    raise ParameterError(f"`joints[{i}]` clamps rod {rod!r} to the world, but its Model's "
                                         "`base` moves: drop the joint or the motion")
                clamps[rod] = (None, np.array(base.position, dtype=float), np.array(base.rotation, dtype=float))
                continue
            if not base.fixed or np.any(np.asarray(base.position, dtype=float) != 0.0) or not np.array_equal(
                    np.asarray(base.rotation, dtype=float), np.eye(3)):
                raise ParameterError(f"rod {rod!r} is clamped to body {other[1]!r}, so its Model's `base` "
                                     f"must be the default (the body gives its pose and motion), got {base!r}")
            clamps[rod] = (other[1], other[2], other[3])
        return clamps

    def rods_on(self, body):
        """Names of the rods whose base is clamped to ``body``, in ``rods`` order."""
        return [name for name in self.rods if name in self.clamps and self.clamps[name][0] == body]

    def base_motion(self, rod):
        """The Model ``base`` of rod ``rod`` at t = 0: the joint's pose, fixed
        (bodies move it through the system); a rod without joint: its own."""
        model = self.rods[rod]
        if rod not in self.clamps:
            return model.base
        body, point, rotation = self.clamps[rod]
        if body is None:
            return model.base
        b = self.bodies[body]
        return BaseMotion(position=tuple(b.position + b.rotation @ point),
                          rotation=tuple(map(tuple, b.rotation @ rotation)))

    def __repr__(self):
        return (f"System(rods={list(self.rods)}, bodies={list(self.bodies)}, "
                f"joints={len(self.joints)})")


def _describe(end):
    if end == "world":
        return "the world"
    return f"{end[0]} {end[1]!r}" + (f" ({end[2]})" if end[0] == "rod" else "")
