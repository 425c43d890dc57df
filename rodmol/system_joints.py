"""The joints of a :class:`rodmol.System`: :class:`Joint`, what a user
gives (two ends and a kind), and what the System makes of each one that
is not a rod's clamped base: a :class:`PenaltyJoint` at a rod's node or a
:class:`BodyJoint` between bodies (docs/systems.md, "Joints")."""

from dataclasses import dataclass

import numpy as np

from . import _checks
from .errors import ParameterError
from .load_kinds import HOLD_KINDS

#: Joint kinds: a joint is held by the Hold law ("clamp" holds the position and
#: the orientation, "pin" the position only: a ball joint), so its kinds are the holds'.
JOINT_KINDS = HOLD_KINDS
#: Named ends of a rod a joint may hold (else an arc length s [m], a velocity node).
ROD_ENDS = ("base", "tip")


@dataclass(frozen=True)
class Joint:
    """A joint between two ends.

    Parameters
    ----------
    a, b : end
        Each ``"world"``, ``(body_name, point)`` or ``(body_name, point,
        rotation)``, a point [m] of a body in its body frame and the rotation
        (joint frame to body frame), or ``(rod_name, "base")``,
        ``(rod_name, "tip")`` or ``(rod_name, s)``, s [m] a velocity node
        of the rod's grid. A clamp of a rod's base to a body point makes the
        rod's base frame the joint frame (default rotation: identity): the
        rod leaves the body along the joint frame's x axis. At any other
        node the rotation, if given, is the section's held orientation in
        the body frame (default: the section's orientation at rest). Two
        rods' tips or nodes s may be joined (the relative orientation of
        their sections at rest is held by a clamp).
        Two bodies (or a body and the world) are joined at a point of
        each: the two points must meet at rest, and a clamp holds the two
        joint frames' relative orientation (a missing rotation: as at rest).
        A body's point joined to ``"world"`` is held where it is at rest.
    kind : str
        ``"clamp"`` (all six relative motions fixed) or ``"pin"`` (the
        positions only: a ball joint; at a rod's base, the base pinned
        where its clamp would be).
    stiffness, damping : float, optional
        Of a penalty joint (any node but the base): as for
        :class:`rodmol.Hold` [N/m, N s/m], whose law and defaults it takes.
        Of a joint between bodies (or a pinned base) the defaults put the
        joint's fastest mode at the frequency of a rod element on 100 E A /
        ds (the system's fastest; at a pinned, joined or branched base, of
        its rod's node on its default Hold) and damp every mode of the joint
        at least critically (:func:`rodmol.discretise.body_joints.joint_law`;
        docs/systems.md, "Joints of bodies"); a given stiffness [N/m] is the
        translational one, the turning one scaled with it.
    """

    a: object
    b: object
    kind: str = "clamp"
    stiffness: float | None = None
    damping: float | None = None

    def __post_init__(self):
        _checks.choice("kind", self.kind, JOINT_KINDS)
        object.__setattr__(self, "a", _end("a", self.a))
        object.__setattr__(self, "b", _end("b", self.b))
        for name, unit in (("stiffness", " N/m"), ("damping", " N s/m")):
            value = getattr(self, name)
            if value is not None:
                check = _checks.positive if name == "stiffness" else _checks.non_negative
                object.__setattr__(self, name, check(name, value, unit))


def _end(name, value):
    """A checked joint end: "world", ("rod", name, "base" | "tip" | s) or ("body", name, point, rotation or None)."""
    if isinstance(value, str) and value == "world":
        return value
    if isinstance(value, tuple) and len(value) == 2 and isinstance(value[0], str):
        where = value[1]
        if isinstance(where, str):
            if where not in ROD_ENDS:
                raise ParameterError(f"joint end `{name}`: a rod's end must be one of {list(ROD_ENDS)} or an "
                                     f"arc length s [m], got {where!r}")
            return ("rod", value[0], where)
        if np.ndim(where) == 0 and not isinstance(where, bool):
            return ("rod", value[0], _checks.positive(f"{name}` arc length `s", where, " m"))
    if isinstance(value, tuple) and len(value) in (2, 3) and isinstance(value[0], str):
        point = _checks.vector3(f"{name} point", value[1])
        rotation = _checks.rotation(f"joint end {name} rotation", value[2], tol=1e-9) if len(value) == 3 else None
        return ("body", value[0], point, rotation)
    raise ParameterError(f"joint end `{name}` must be 'world', (body_name, point[, rotation]) or "
                         f"(rod_name, 'base' | 'tip' | s), got {_checks.short(value)}")


@dataclass(frozen=True)
class PenaltyJoint:
    """A joint held by a penalty (:class:`rodmol.Hold`'s law): rod ``rod``'s
    hold ``loads[load]`` (its Model's), held by the body ``body`` (None: the
    world, or a rod) at ``point`` [m], body frame, with the section's
    orientation ``rotation`` (section to body frame; None: as at rest), or
    by the node of rod ``partner`` whose hold is its ``loads[partner_load]``
    (each of the two rods holds the other's node: the pair is equal and opposite)."""

    index: int
    rod: str
    load: int
    body: str | None
    point: np.ndarray | None
    rotation: np.ndarray | None
    kind: str
    partner: str | None = None
    partner_load: int | None = None


@dataclass(frozen=True)
class BodyJoint:
    """A joint between two bodies (or a body and the world) at a point of
    each, held by the :class:`rodmol.Hold` law: body ``a``'s joint frame
    (origin ``point_a`` [m], axes ``rotation_a``, body frame of ``a``) held
    by body ``b``'s (``point_b``, ``rotation_b`` in its body frame), or for
    ``b`` None by the world's (``point_b`` [m] and ``rotation_b``, global:
    where a's joint frame is at rest). ``stiffness``, ``damping`` None: the
    defaults (:mod:`rodmol.discretise.body_joints`)."""

    index: int
    a: str
    point_a: np.ndarray
    rotation_a: np.ndarray
    b: str | None
    point_b: np.ndarray
    rotation_b: np.ndarray
    kind: str
    stiffness: float | None = None
    damping: float | None = None
