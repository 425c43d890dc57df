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

* a joint between two bodies, or a body and the world, clamp or pin at a
  point of each body, is the same penalty law between the two points (one
  body's joint frame held by the other's), equal and opposite on the two
  bodies (:class:`BodyJoint`);
* a rod's base *pinned* to the world or to a body, or joined to another
  rod's node (a branch), is a small free body of its own, the rod's base
  segment (the half cell the velocity nodes leave out), its base clamped to
  it (eliminated) and the body pinned by a body joint, or held to the other
  rod's node by a penalty joint, or to another such base body by a body
  joint (:attr:`System.base_bodies`).
"""

import numpy as np

from . import _checks
from .base_motion import BaseMotion
from .bodies import RigidBody
from .contacts import Contact, attach
from .errors import ParameterError
from .holds import Hold
from .load_kinds import KERNELS
from .loads import DistributedForce
from .model import Model
from .parameters import Medium
from .rod_contacts import LOAD_NAME, RodContact, check_rods
from .system_joints import BodyJoint, Joint, PenaltyJoint

__all__ = ["BodyJoint", "Joint", "PenaltyJoint", "System"]

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
    contacts : sequence of Contact or RodContact
        Bodies' shapes that rods touch (:class:`rodmol.Contact`), and rods that
        touch each other or themselves (:class:`rodmol.RodContact`).

    Attributes
    ----------
    rods, bodies : dict
        As given (the rods rebuilt with the system's gravity and medium).
    given_rods, given_bodies : dict
        The rods and bodies exactly as given (:meth:`replace` rebuilds from them).
    clamps : dict of str to (body_name or None, point (3,), rotation (3, 3))
        Where each rod's base is held: a body (or None for the world), the
        point [m] and the rotation (base to body frame; to global for the world).
    penalty_joints : list of PenaltyJoint
        The joints at other nodes; each rod's Model in ``rods`` carries their
        holds (:class:`rodmol.Hold`, named ``"joints[i]"``) after its own loads.
    body_joints : list of BodyJoint
        The joints between bodies or a body and the world (with the pins of
        the pinned bases).
    base_bodies : dict of str to str
        The rods whose base is pinned or joined to another rod, each to the
        name of its base body (``"<rod>.base"``, in ``bodies``: a free body
        carrying the rod's base segment only; its result is the base's pose).
    rod_contacts : list of rodmol.contacts.RodContact
        Each rod's side of each contact; the rod's Model carries the shape
        (named ``"contacts[i]"``, placed at the body's initial pose) after the holds.
    rod_pairs : list of (int, RodContact)
        The rod contacts with their index in ``contacts``; each rod in one carries
        the load ``rodmol.rod_contacts.LOAD_NAME`` (its nodes' contact forces) last.
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
        if shared:
            raise ParameterError(f"the name {shared[0]!r} is used twice, by a rod and a body: rods and bodies "
                                 "share one set of names, each unique")
        if "world" in rods or "world" in bodies:
            raise ParameterError(f"`{'rods' if 'world' in rods else 'bodies'}`: the name 'world' is reserved (a "
                                 "joint's end \"world\" is the fixed frame)")
        self.given_rods, self.given_bodies = dict(rods), dict(bodies)  # what replace() rebuilds from
        self.gravity = _checks.vector3("gravity", gravity)
        probe = next(iter(rods.values())).replace(medium=medium)  # Model checks the medium
        self.medium = probe.medium
        if not isinstance(self.medium, Medium):
            raise ParameterError(f"`medium` must be a Medium, a preset name or None, got {medium!r}")
        self.rods = {name: m.replace(gravity=tuple(self.gravity), medium=self.medium)
                     for name, m in rods.items()}
        self.bodies = dict(bodies)
        self.joints = _checks.items("joints", joints, Joint, "a rodmol.Joint")
        self.body_joints, self.base_bodies = [], {}
        self.clamps, self.penalty_joints = self._joints()
        self.contacts = _checks.items("contacts", contacts, (Contact, RodContact),
                                      "a rodmol.Contact or rodmol.RodContact")
        self.rods, self.rod_contacts = attach(self.contacts, self.rods, self.bodies)
        check_rods(self.contacts, self.rods)
        self.rod_pairs = [(i, c) for i, c in enumerate(self.contacts) if isinstance(c, RodContact)]
        touching = {name for _, c in self.rod_pairs for name in c.rods}
        self.rods = {name: m.replace(loads=tuple(m.loads) + (DistributedForce((0.0, 0.0, 0.0), "local", LOAD_NAME),))
                     if name in touching else m for name, m in self.rods.items()}

    def replace(self, *, rods=None, bodies=None, **changes):
        """A new System with ``changes`` (``joints``, ``medium``, ``gravity``,
        ``contacts``) and the parts named in ``rods`` and ``bodies`` ({name:
        Model} and {name: RigidBody}) in place of those given; the others as given."""
        for what, new, given in (("rods", rods, self.given_rods), ("bodies", bodies, self.given_bodies)):
            unknown = sorted(set(new or {}) - set(given))
            if unknown:
                raise ParameterError(f"`{what}`: the system has no part named {unknown[0]!r}"
                                     f"{_checks.did_you_mean(unknown[0], given)} ({what}: {list(given)})")
        arguments = dict(joints=self.joints, medium=self.medium, gravity=tuple(self.gravity), contacts=self.contacts)
        return System({**self.given_rods, **(rods or {})}, {**self.given_bodies, **(bodies or {})},
                      **{**arguments, **changes})

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
            if len(rod_ends) == 2 and any(e[2] == "base" for e in rod_ends):
                penalties += self._base_to_rod(i, joint, rod_ends, clamps, holds)
                continue
            if len(rod_ends) == 2:
                penalties += self._rod_to_rod(i, joint, rod_ends, holds)
                continue
            if not rod_ends:
                self.body_joints.append(self._body_joint(i, joint, *ends))
                continue
            _, rod, where = rod_ends[0]
            other = ends[1] if ends[0] is rod_ends[0] else ends[0]
            if where == "base":
                if rod in clamps:
                    raise ParameterError(f"`joints[{i}]`: the base of rod {rod!r} is already jointed; hold a "
                                         "rod's other nodes by joints at its tip or at an arc length s")
                if not KERNELS[joint.kind].holds_turning:  # only a clamp's base is eliminated
                    clamps[rod] = self._pinned_base(i, joint, rod, other)
                    continue
                if joint.stiffness is not None or joint.damping is not None:
                    raise ParameterError(f"`joints[{i}]` clamps the base of rod {rod!r}: the clamp is eliminated "
                                         "(exact), it takes no `stiffness` or `damping`")
                clamps[rod] = self._clamp(i, rod, other)
                continue
            penalties.append(self._node_joint(i, joint, rod, where, other, holds))
        self.rods = {name: m.replace(loads=tuple(m.loads) + tuple(holds[name])) if holds[name] else m
                     for name, m in self.rods.items()}
        return clamps, penalties

    def _base_to_rod(self, i, joint, rod_ends, clamps, holds):
        """``joints[i]`` at a rod's base and another rod's end: the base clamped to its base
        body, held to the other rod's node by a penalty joint (a branch) or, base to base, the
        two base bodies joined by a body joint; returns the penalty joints."""
        (_, a, where_a), (_, b, where_b) = rod_ends
        if a == b:
            raise ParameterError(f"`joints[{i}]` joins the base of rod {a!r} to its own node")
        bases = [rod for rod, where in ((a, where_a), (b, where_b)) if where == "base"]
        for rod in bases:
            if rod in clamps:
                raise ParameterError(f"`joints[{i}]`: the base of rod {rod!r} is already jointed")
        if len(bases) == 2:
            names = []
            for rod, other in ((a, b), (b, a)):
                name, clamps[rod] = self._base_body(i, rod, ("rod", other, "base"))
                names.append(("body", name, np.zeros(3), None))
            self.body_joints.append(self._body_joint(i, joint, *names))
            return []
        (base, other, where) = (a, b, where_b) if where_a == "base" else (b, a, where_a)
        name, clamps[base] = self._base_body(i, base, ("rod", other, where))
        return [self._node_joint(i, joint, other, where, ("body", name, np.zeros(3), None), holds)]

    def _node_joint(self, i, joint, rod, where, other, holds):
        """The :class:`PenaltyJoint` of ``joints[i]`` holding rod ``rod``'s node
        ``where`` (its tip or an arc length) to ``other`` (the world or a body
        point); its hold is appended to ``holds[rod]``."""
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
        holds[rod].append(hold)
        return PenaltyJoint(i, rod, len(model.loads) + len(holds[rod]) - 1, body, point, rotation, joint.kind)

    def _rod_to_rod(self, i, joint, rod_ends, holds):
        """The two penalty joints of ``joints[i]`` between two rods' nodes (not
        bases): each rod's hold held by the other's node, appended to ``holds``."""
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

    def _body_joint(self, i, joint, a, b):
        """The :class:`BodyJoint` of ``joints[i]`` between the ends ``a``, ``b`` (bodies or the world)."""
        if a == "world" and b == "world":
            raise ParameterError(f"`joints[{i}]` joins the world to itself")
        if a == "world":
            a, b = b, a
        name_a, point_a, turn_a = a[1], a[2], np.eye(3) if a[3] is None else a[3]
        body_a = self.bodies[name_a]
        at_rest = body_a.position + body_a.rotation @ point_a
        frame = body_a.rotation @ turn_a
        if b == "world":
            free = body_a.free
            name_b, point_b, turn_b = None, at_rest, frame
        else:
            name_b, point_b = b[1], b[2]
            if name_b == name_a:
                raise ParameterError(f"`joints[{i}]` joins body {name_a!r} to itself")
            body_b = self.bodies[name_b]
            free = body_a.free or body_b.free
            turn_b = body_b.rotation.T @ frame if b[3] is None else b[3]
            gap = float(np.linalg.norm(body_b.position + body_b.rotation @ point_b - at_rest))
            if gap > 1e-9 * max(1.0, float(np.linalg.norm(at_rest))):
                raise ParameterError(f"`joints[{i}]` joins body {name_a!r} at {tuple(map(float, point_a))} to body {name_b!r} "
                                     f"at {tuple(map(float, point_b))}, but at rest the two points are {gap:.3g} m apart: "
                                     "place the bodies (their `position`, `rotation`) so that they meet")
            turn_gap = float(np.linalg.norm(body_b.rotation @ turn_b - frame))
            if KERNELS[joint.kind].holds_turning and turn_gap > 1e-9:
                raise ParameterError(f"`joints[{i}]` clamps bodies {name_a!r} and {name_b!r} with joint frames "
                                     f"that differ at rest (by {turn_gap:.3g}): give one rotation or matching ones")
        if not free:
            raise ParameterError(f"`joints[{i}]` joins {_describe(('body', name_a))} and "
                                 f"{_describe(b if b == 'world' else ('body', name_b))}, neither of which is "
                                 "free: such a joint does nothing (make a body free, or drop the joint)")
        return BodyJoint(i, name_a, point_a, turn_a, name_b, point_b, turn_b, joint.kind,
                         joint.stiffness, joint.damping)

    def _pinned_base(self, i, joint, rod, other):
        """Pin rod ``rod``'s base to ``other`` (``joints[i]``) through its base
        body (:meth:`_base_body`); returns the clamp."""
        name, clamp = self._base_body(i, rod, other)
        self.body_joints.append(self._body_joint(i, joint, ("body", name, np.zeros(3), None), other))
        return clamp

    def _base_body(self, i, rod, other):
        """Rod ``rod``'s base body for ``joints[i]`` (a free :class:`RigidBody`
        standing for the rod's base segment, its mass properties replaced by
        the segment's when discretised), placed at the point of body ``other``
        or else (the world, another rod's node) at the Model's base; returns
        its name and the clamp of the rod's base to it."""
        name = f"{rod}.base"
        if name in self.bodies or name in self.rods:
            raise ParameterError(f"`joints[{i}]` joins the base of rod {rod!r}, whose base body is named {name!r}, "
                                 "but that name is taken: rename the rod or the body")
        model = self.rods[rod]
        if not (isinstance(other, tuple) and other[0] == "body"):
            base = model.base
            if not base.fixed:
                raise ParameterError(f"`joints[{i}]` joins the base of rod {rod!r} to {_describe(other)}, but its "
                                     "Model's `base` moves: drop the joint or the motion")
            position, rotation = np.array(base.position, dtype=float), np.array(base.rotation, dtype=float)
        else:
            self._clamp(i, rod, other)  # the same checks of the Model's base as for a clamp
            body = self.bodies[other[1]]
            position = body.position + body.rotation @ other[2]
            rotation = body.rotation @ (np.eye(3) if other[3] is None else other[3])
        half = 0.5 * model.ds * model.rod.material.rho  # a stand-in: the discretisation carries the segment
        self.bodies[name] = RigidBody(half * float(model.rod.area(0.0)), half * model.rod.second_moments(0.0),
                                      position=position, rotation=rotation)
        self.base_bodies[rod] = name
        return name, (name, np.zeros(3), np.eye(3))

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
