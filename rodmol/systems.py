"""Several rods and rigid bodies joined into one model: :class:`Joint`, :class:`System`.

Two methods hold the joints:

* a rod's *base* clamped to a rigid body or to the world is eliminated (a
  tree joint): the base takes the body's pose and velocities;
* a joint at any other node of a rod (its tip or an arc length ``s``),
  clamp or pin, to the world, to a body or to another rod's node, is a
  stiff penalty: the law of :class:`rodmol.Hold`
  (:func:`rodmol.discretise.external.hold`), whose held point moves with
  the body (between two rods, each rod's hold is held by the other's node).
  Such joints may close loops (several rods between the ground and one
  platform, a rod held at both ends).

Joints between two bodies (or a body and the world), a pinned base and a
base joined to a rod raise :class:`rodmol.errors.NotSupportedYet`.
"""

from dataclasses import dataclass

import numpy as np

from . import _checks
from .base_motion import BaseMotion
from .bodies import RigidBody
from .contacts import Contact, attach
from .errors import NotSupportedYet, ParameterError
from .holds import Hold
from .model import Model
from .parameters import Medium

#: Joint kinds: "clamp" holds the position and the orientation, "pin" the position only (a ball joint).
JOINT_KINDS = ("clamp", "pin")
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
    kind : str
        ``"clamp"`` (all six relative motions fixed) or ``"pin"`` (the
        positions only: a ball joint; not at a rod's base).
    stiffness, damping : float, optional
        Of a penalty joint (any node but the base): as for
        :class:`rodmol.Hold` [N/m, N s/m], whose law and defaults it takes.
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
        point = _checks.vector3(f"{name}` point `", value[1])
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


class System:
    """Named rods and rigid bodies joined by joints.

    Parameters
    ----------
    rods : dict of str to Model
        Each rod as a single-rod :class:`Model` (its grid, material, cables,
        loads, markers). Its gravity and medium are replaced by the system's.
    bodies : dict of str to RigidBody
    joints : sequence of Joint
        Each rod's base clamped at most once, to the world or to a body (a
        rod base with no joint is clamped to the world where its Model's
        ``base`` says, and moves as it says); any other node clamped or
        pinned to the world or to a body by a penalty joint, loops allowed.
    medium : Medium, str or None
        The fluid around every rod and body (a preset name as for Model).
    gravity : (3,) float
        Gravitational acceleration [m/s^2], global.
    contacts : sequence of Contact
        Bodies' shapes that rods touch (:class:`rodmol.Contact`).

    Attributes
    ----------
    rods, bodies : dict
        As given (the rods rebuilt with the system's gravity and medium).
    clamps : dict of str to (body_name or None, point (3,), rotation (3, 3))
        Where each rod's base is held: a body (or None for the world), the
        point [m] and the rotation (base to body frame; to global for the world).
    penalty_joints : list of PenaltyJoint
        The joints at other nodes; each rod's Model in ``rods`` carries their
        holds (:class:`rodmol.Hold`, named ``"joints[i]"``) after its own loads.
    rod_contacts : list of rodmol.contacts.RodContact
        Each rod's side of each contact; the rod's Model carries the shape
        (named ``"contacts[i]"``, placed at the body's initial pose) after the holds.
    """

    def __init__(self, rods, bodies=None, joints=(), *, medium=None, gravity=(0.0, -9.81, 0.0), contacts=()):
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
        self.clamps, self.penalty_joints = self._joints()
        self.contacts = _checks.items("contacts", contacts, Contact, "a rodmol.Contact")
        self.rods, self.rod_contacts = attach(self.contacts, self.rods, self.bodies)

    def _joints(self):
        """Each base-jointed rod's clamp: (body or None, point, rotation), and
        the penalty joints, whose holds are added to their rods' Models."""
        clamps, penalties, holds = {}, [], {name: [] for name in self.rods}
        for i, joint in enumerate(self.joints):
            ends = (joint.a, joint.b)
            rod_ends = [e for e in ends if isinstance(e, tuple) and e[0] == "rod"]
            for e in rod_ends:
                if e[1] not in self.rods:
                    raise ParameterError(f"`joints[{i}]` names the rod {e[1]!r}, which is not in `rods`"
                                         f"{_checks.did_you_mean(e[1], self.rods)}")
            for e in ends:
                if isinstance(e, tuple) and e[0] == "body" and e[1] not in self.bodies:
                    raise ParameterError(f"`joints[{i}]` names the body {e[1]!r}, which is not in `bodies`"
                                         f"{_checks.did_you_mean(e[1], self.bodies)}")
            if len(rod_ends) == 2:
                penalties += self._rod_to_rod(i, joint, rod_ends, holds)
                continue
            if len(rod_ends) != 1:
                raise NotSupportedYet(f"`joints[{i}]` joins {_describe(ends[0])} and {_describe(ends[1])}: "
                                      "only a rod to a body, to the world or to a rod is supported yet (not "
                                      "body to body or body to world)")
            _, rod, where = rod_ends[0]
            other = ends[1] if ends[0] is rod_ends[0] else ends[0]
            if where == "base":
                if joint.kind != "clamp":
                    raise NotSupportedYet(f"`joints[{i}]` pins the base of rod {rod!r}: a rod's base can only "
                                          "be clamped yet (pin any other node)")
                if joint.stiffness is not None or joint.damping is not None:
                    raise ParameterError(f"`joints[{i}]` clamps the base of rod {rod!r}: the clamp is eliminated "
                                         "(exact), it takes no `stiffness` or `damping`")
                if rod in clamps:
                    raise ParameterError(f"`joints[{i}]`: the base of rod {rod!r} is already jointed; hold a "
                                         "rod's other nodes by joints at its tip or at an arc length s")
                clamps[rod] = self._clamp(i, rod, other)
                continue
            model = self.rods[rod]
            s = model.rod.length if where == "tip" else where
            name = f"joints[{i}]"
            if other == "world":
                hold = Hold(s, joint.kind, stiffness=joint.stiffness, damping=joint.damping, name=name)
                body, point, rotation = None, None, None
            else:
                _, body, point, rotation = other
                b = self.bodies[body]
                held = None if rotation is None else b.rotation @ rotation
                hold = Hold(s, joint.kind, position=b.position + b.rotation @ point, rotation=held,
                            stiffness=joint.stiffness, damping=joint.damping, name=name)
            penalties.append(PenaltyJoint(i, rod, len(model.loads) + len(holds[rod]), body, point, rotation,
                                          joint.kind))
            holds[rod].append(hold)
        self.rods = {name: m.replace(loads=tuple(m.loads) + tuple(holds[name])) if holds[name] else m
                     for name, m in self.rods.items()}
        return clamps, penalties

    def _rod_to_rod(self, i, joint, rod_ends, holds):
        """The two penalty joints of ``joints[i]`` between two rods' nodes (not
        bases): each rod's hold held by the other's node, appended to ``holds``."""
        if any(where == "base" for _, _, where in rod_ends):
            raise NotSupportedYet(f"`joints[{i}]` joins a rod's base to a rod: a base can only be clamped to a "
                                  "body or the world yet (join a rod's tip or node s to the other rod)")
        (_, a, where_a), (_, b, where_b) = rod_ends
        if a == b and where_a == where_b:
            raise ParameterError(f"`joints[{i}]` joins a node of rod {a!r} to itself")
        loads = []
        for rod, where in ((a, where_a), (b, where_b)):
            model = self.rods[rod]
            s = model.rod.length if where == "tip" else where
            loads.append(len(model.loads) + len(holds[rod]))
            holds[rod].append(Hold(s, joint.kind, stiffness=joint.stiffness, damping=joint.damping,
                                   name=f"joints[{i}]"))
        return [PenaltyJoint(i, a, loads[0], None, None, None, joint.kind, b, loads[1]),
                PenaltyJoint(i, b, loads[1], None, None, None, joint.kind, a, loads[0])]

    def _clamp(self, i, rod, other):
        """(body or None, point, rotation) of ``joints[i]``, the clamp of rod ``rod``'s base to ``other``."""
        base = self.rods[rod].base
        if other == "world":  # where the Model's base is
            if not base.fixed:
                raise ParameterError(f"`joints[{i}]` clamps rod {rod!r} to the world, but its Model's "
                                     "`base` moves: drop the joint or the motion")
            return (None, np.array(base.position, dtype=float), np.array(base.rotation, dtype=float))
        if not base.fixed or np.any(np.asarray(base.position, dtype=float) != 0.0) or not np.array_equal(
                np.asarray(base.rotation, dtype=float), np.eye(3)):
            raise ParameterError(f"rod {rod!r} is clamped to body {other[1]!r}, so its Model's `base` "
                                 f"must be the default (the body gives its pose and motion), got {base!r}")
        return (other[1], other[2], np.eye(3) if other[3] is None else other[3])

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
    return f"{end[0]} {end[1]!r}" + (f" ({end[2]!r})" if end[0] == "rod" else "")
