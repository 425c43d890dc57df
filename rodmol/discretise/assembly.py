"""The semi-discrete system of a :class:`rodmol.System`: rods and rigid
bodies in one state vector, dy/dt = f(t, y).

The state is the rods' states (each a :class:`SemiDiscrete`'s, in ``rods``
order) followed by the bodies' blocks (in ``bodies`` order). A body's block
(:data:`BODY_FIELDS`) holds the position x [m] of its origin (global), its
quaternion Q (body to global) and, for a free body only, the velocity v
[m/s] of its origin and its angular velocity w [rad/s], both in the body
frame, as the rods' nodes. A fixed or driven body's velocities are not
state: they are zero or its BaseMotion's, and its pose integrates them.

Coupling (tree joints, the constraint eliminated): a rod clamped at point p
with rotation Rj (base to body frame) of a body moving with (v, w) has the
base velocities v0 = Rj^T (v + w x p), w0 = Rj^T w. A body feels, from each
rod clamped to it, the total stress of the rod's cell 0 (with the cables)
plus the base node's share of that cell's products (``Scheme.base_share``),
the same force and moment that node 1 feels with the opposite sign: the pair
is then the same as between any two nodes of a rod. The rod's header (u0,
Q0) integrates v0, w0 as for a single rod: it is not tied to the body's pose
but drifts from it by the integration error only (``pose_drift``).

Coupling (penalty joints, at any other node, loops allowed): the joint is
the rod's hold (rodmol.Hold, one of its load entries), whose held point is
the body's point x + R p with the orientation R Rj and the velocities
R (v + w x p), R w (global), written into the hold's row before each call
(:func:`rodmol.discretise.rigid.joint_wrench`). The body feels the hold's
force and moment with the opposite sign, the force acting where the node
is. A joint to the world is the rod's plain hold. A joint between two
rods' nodes is two holds, each rod's held by the other's node: their
forces (and clamp moments) are equal and opposite, acting at the two nodes
(the couple of the pair, gap x F, is O(F^2 / k)). :mod:`rodmol.discretise.joints`
holds the joints' parts.

Coupling (joints of bodies): two bodies, or a body and the world, joined at
a point of each by the same hold law between the two points, equal and
opposite on the two bodies (:mod:`rodmol.discretise.body_joints`,
:meth:`Assembly.add_body_joints`). A pinned rod base is clamped to a free
body that is its base segment alone (``BodyPart.segment_only``), pinned so.

What a free body carries: the rods' velocity nodes stand for their
``node_lengths``, which leave out the length next to the base node (ds/2
in the centred scheme, none upwind); on a body that piece, the rod's base
segment, moves with the clamp, so the body carries it
(:meth:`BodyPart.carry`): the base section's mass (with the fluid's added
mass if the rod's model has it) and rotational inertia times that length,
lumped at the clamp point as the nodes' masses are at theirs, in the mass
matrix with their parallel-axis terms, and their weight less buoyancy at
the clamp.

Newton-Euler of a body about its origin, body frame, with the momentum
(P, H) = M_r (v, w) of its own mass and its base segments (M_r: the 6x6
mass matrix without the body's added mass, as P = m (v + w x c),
H = I_o w + m c x v for the body alone):
M [v_t, w_t] = [F - w x P, T - w x H - v x P], where the 6x6 mass matrix M
adds the body's added mass (its gyroscopic terms are left out), F, T the
rods' wrenches, weight minus buoyancy (the body's at its centre of mass,
the segments' at their clamps) and quadratic drag.
"""

import numpy as np

from ..inputs import knot_times
from .body_joints import BodyJointPart, body_joint_frequency
from .body_part import BodyPart, clamp_map
from .contact_parts import contact_parts
from .joints import JointPart, RodJointPart
from .physics import quaternion_rate
from .protocol import pattern_bandwidths
from .rigid import clamp_wrench, free_body_rates
from .rod_contact import RodPairs
from .rod_scales import field_scales
from .rotations import from_matrix, matrices
from .state_checks import least_stretch, parts_problem, parts_step_problem
from .system import DRAG_SMOOTHING_SPEED, QUATERNION_RESTORING_RATE, SemiDiscrete
from .system_jacobian import assembly_pattern
from .system_state_view import SystemStateView


class Assembly:
    """The method-of-lines system of a :class:`rodmol.System`, a
    :class:`rodmol.discretise.protocol.Discretised`.

    Parameters
    ----------
    system : System
    scheme : str or Scheme
        The spatial scheme of every rod (``rodmol.SCHEMES``).

    Attributes
    ----------
    rods : dict of str to SemiDiscrete
        Each rod's system; a rod on a driven body or the world moves by its
        own ``base`` (the body's motion carried to its clamp).
    parts : dict of str to slice
        Where each rod's and body's entries sit in the state.
    size : int
    """

    def __init__(self, system, scheme=None):
        self.system = system
        self.rods, self.parts, self.bodies = {}, {}, {}
        start = 0
        for name in system.rods:
            sd = SemiDiscrete(system.rods[name].replace(base=self._rod_base(name)),
                              *(() if scheme is None else (scheme,)))
            self.rods[name] = sd
            self.parts[name] = slice(start, start + sd.size)
            start += sd.size
        self.scheme = next(iter(self.rods.values())).scheme
        pinned = set(system.base_bodies.values())
        for name, body in system.bodies.items():
            part = BodyPart(name, body, start, system.medium.rho, segment_only=name in pinned)
            for rod in system.rods_on(name):
                _, point, rotation = system.clamps[rod]
                part.clamp(rod, self.rods[rod], self.parts[rod].start, point, rotation)
            self.bodies[name] = part
            self.parts[name] = part.slice
            start = part.slice.stop
        self.size = start
        self.joints, self.rod_joints = contact_parts(self), []  # to bodies (rods' contacts first), between rods
        for joint in system.penalty_joints:
            rod = (self.rods[joint.rod], self.parts[joint.rod].start)
            if joint.body is not None:
                part = self.bodies[joint.body]
                part.joints.append(JointPart(joint, *rod, part))
                self.joints.append(part.joints[-1])
            elif joint.partner is not None:
                self.rod_joints.append(RodJointPart(joint, *rod, self.rods[joint.partner],
                                                    self.parts[joint.partner].start))
        self.body_joints = [BodyJointPart(j, self.bodies[j.a], None if j.b is None else self.bodies[j.b],
                                          body_joint_frequency(system, j)) for j in system.body_joints]
        for joint in self.body_joints:
            for part in joint.parts:
                part.body_joints.append(joint)
        self.free = [p for p in self.bodies.values() if p.body.free]
        # What every right-hand side walks, once: each rod's system and entries, the free bodies
        # whose penalty or body joints' reactions it sums.
        self._rod_parts = [(sd, self.parts[name]) for name, sd in self.rods.items()]
        self._reacting = [p.name for p in self.free if p.joints or p.body_joints]
        self.rod_pairs = RodPairs(self) if system.rod_pairs else None
        self.lightly_damped = any(sd.lightly_damped for sd in self.rods.values())
        self.scan_arguments = None  # the step check's compiled scan arguments, made at its first call
        self._gravity = np.ascontiguousarray(system.gravity, dtype=float)

    def _rod_base(self, name):
        """The Model ``base`` of rod ``name``: its clamp's pose, moving with a driven body."""
        system = self.system
        base = system.base_motion(name)
        body = system.clamps.get(name, (None,))[0]
        if body is None or not system.bodies[body].driven:
            return base
        _, point, rj = system.clamps[name]
        motion = system.bodies[body].motion

        moves = clamp_map(point, np.asarray(rj)[None])

        def velocities(t):
            return moves @ np.concatenate([np.asarray(a, dtype=float) for a in motion.velocities(t)])

        return type(base)(lambda t: velocities(t)[:3], lambda t: velocities(t)[3:], base.position, base.rotation)

    #: The rods' inputs are evaluated when their Results are built: a run checks no frame again
    #: against them (:func:`rodmol.solve.outputs.keep_before_failure`), and a failing one stops it there.
    inputs_vary = False

    # ------------------------------------------------------------------ state

    def undeformed_state(self):
        """Every rod at rest in its rest shape at its base, every body at rest at its initial pose."""
        y = np.zeros(self.size)
        for name, sd in self.rods.items():
            y[self.parts[name]] = sd.undeformed_state()
        for part in self.bodies.values():
            y[part.fields["x"]] = part.body.position
            y[part.fields["Q"]] = from_matrix(part.body.rotation)
        return y

    def entry_name(self, index):
        """A readable name of state entry ``index`` (``"rod 'arm' (k[2] of element 7)"``, ``"body 'head' (w)"``)."""
        for name, part in self.parts.items():
            if part.start <= index < part.stop:
                if name in self.rods:
                    return f"rod {name!r} ({self.rods[name].layout.entry_name(index - part.start)})"
                fields = self.bodies[name].fields.items()
                field = next(f for f, entries in fields if entries.start <= index < entries.stop)
                return f"body {name!r} ({field})"
        raise IndexError(f"state entry {index} of a system of {self.size}")

    def knot_times(self):
        """The times [s] of the kinks of every rod's and body's inputs (:func:`rodmol.inputs.knot_times`)."""
        return knot_times(self.system)

    def bending_period(self):
        """The shortest of the rods' first bending periods [s]."""
        return min(sd.bending_period() for sd in self.rods.values())

    def body_state(self, part, t, y):
        """A body's (x, Q, v, w) at (t, y) (``rigid.FREE_BODY.size``,): its pose and velocities
        (:meth:`body_velocities`)."""
        if part.body.free:
            return np.ascontiguousarray(y[part.slice])
        return np.concatenate([y[part.slice], *self.body_velocities(part, t, y)])

    def body_velocities(self, part, t, y):
        """(v, w) of a body's origin at (t, y) [m/s, rad/s], body frame."""
        if part.body.free:
            return y[part.fields["v"]], y[part.fields["w"]]
        if part.body.driven:
            return part.body.motion.velocities(t)
        return np.zeros(3), np.zeros(3)

    def project_quaternions(self, y):
        """Scale every quaternion of the states ``y`` (..., size) to unit norm, in place."""
        y = y.reshape(-1, self.size)
        for name, sd in self.rods.items():
            rod = np.ascontiguousarray(y[:, self.parts[name]])
            sd.layout.project_quaternions(rod)
            y[:, self.parts[name]] = rod
        for part in self.bodies.values():
            q = y[:, part.fields["Q"]]
            y[:, part.fields["Q"]] = q / np.linalg.norm(q, axis=-1, keepdims=True)

    def state_view(self, t, y):
        """The state ``y`` at ``t`` [s] by part (:class:`SystemStateView`)."""
        return SystemStateView(self, t, y)

    def read_held(self, t):
        """Read every rod's held tensions at ``t`` [s] (:meth:`SemiDiscrete.read_held`)."""
        for sd in self.rods.values():
            sd.read_held(t)

    # ------------------------------------------------------------------ evaluation

    def __call__(self, t, y, out=None):
        """dy/dt at (t, y); writes into ``out`` if given (CVODE's ``yp``)."""
        if out is None:
            out = np.empty(self.size)
        for part in self.free:  # the rods' base velocities first
            part.move_bases(y)
        reactions = {name: np.zeros(6) for name in self._reacting}
        for joint in self.joints:  # and the held points of the penalty joints, with their bodies' reactions
            f, m = joint.wrench(y, self.body_state(joint.part, t, y), joint.row, joint.value)
            if joint.part.name in reactions:
                reactions[joint.part.name] += (*f, *m)
        if self.body_joints:
            self.add_body_joints(t, y, reactions)
        for joint in self.rod_joints:
            joint.wrench(y, joint.row, joint.value)
        if self.rod_pairs is not None:  # after the base velocities: the base nodes' move
            self.rod_pairs.apply(y)
        for sd, sl in self._rod_parts:
            sd(t, y[sl], out[sl])
        for part in self.bodies.values():
            self.body_rates(part, t, y, out, reactions.get(part.name))
        return out

    def body_rates(self, part, t, y, out, reactions=None):
        """The rates of body ``part``'s block at (t, y) into ``out`` (the whole
        state's rates), after the rods' rates at y (their cell 0's stress);
        ``reactions`` (6,), its penalty joints' force and moment if computed
        already at y (else here, on scratch rows)."""
        if part.body.free:
            force, torque = self.body_wrench(part, y) if part.rods else ((0.0,) * 3, (0.0,) * 3)
            if part.joints or part.body_joints:
                if reactions is None:
                    reactions, body = np.zeros(6), np.ascontiguousarray(y[part.slice])
                    for joint in part.joints:  # the rods' own rows stay as the last call set them
                        f, m = joint.wrench(y, body, joint.row.copy(), joint.value.copy())
                        reactions += (*f, *m)
                    reactions = self.add_body_joints(t, y, {part.name: reactions}, part.body_joints)[part.name]
                force = tuple(np.add(force, reactions[:3]))
                torque = tuple(np.add(torque, reactions[3:]))
            if part.contacts is not None:
                contact = part.contacts.wrench(y[part.slice])
                force, torque = tuple(np.add(force, contact[:3])), tuple(np.add(torque, contact[3:]))
            free_body_rates(y[part.slice], part.params, part.rigid_mass, part.inverse_mass, self._gravity,
                            force, torque, DRAG_SMOOTHING_SPEED**2, QUATERNION_RESTORING_RATE, out[part.slice])
            return
        quat = y[part.fields["Q"]]
        v, w = self.body_velocities(part, t, y)
        out[part.fields["x"]] = matrices(quat) @ v
        out[part.fields["Q"]] = quaternion_rate(tuple(quat), tuple(w), QUATERNION_RESTORING_RATE)

    def add_body_joints(self, t, y, reactions, joints=None):
        """Add to ``reactions`` ({free body name: (6,)}) the force and moment
        of each body joint (default: all of them) at (t, y) on its bodies named there."""
        for joint in self.body_joints if joints is None else joints:
            states = [self.body_state(part, t, y) for part in joint.parts]
            for part, wrench in zip(joint.parts, joint.wrench(*states)):
                if part.name in reactions:
                    reactions[part.name] += (*wrench[0], *wrench[1])
        return reactions

    def body_wrench(self, part, y):
        """Force and moment about the origin [N, N m] of the rods clamped to
        ``part``, body frame, after the rods' rates at ``y``
        (:func:`rodmol.discretise.rigid.clamp_wrench`)."""
        stress = np.array(part.stress_rows).reshape(-1, 6)
        return clamp_wrench(stress, np.ascontiguousarray(y[part.strains]), part.shares, part.flat_turns, part.points)

    # ------------------------------------------------------------------ structure

    def pattern(self):
        """Structural Jacobian pattern (scipy CSC, size x size):
        :func:`rodmol.discretise.system_jacobian.assembly_pattern`."""
        return assembly_pattern(self)

    def bandwidths(self):
        """(lower, upper) half-bandwidths of :meth:`pattern`."""
        return pattern_bandwidths(self.pattern())

    def linear_solvers(self):
        """CVODE's linear solvers on a system (:meth:`rodmol.discretise.protocol.Discretised.linear_solvers`):

        * ``"gmres"`` (``"auto"``): GMRES preconditioned by the rods' exact block
          preconditioners, the bodies' own blocks and, for free bodies with clamped
          rods or penalty joints, their Schur complement, and the blocks of penalty
          joints between two rods' nodes by theirs (:meth:`preconditioner`); about
          2-3x faster than "sparse" on the octopus (``solvers/octopus.py``,
          docs/performance.md), as fast or faster on loops, 1.1 to 2 times faster
          from N = 32 per rod (``solvers/loops.py``, docs/systems.md);
        * ``"sparse"``: SuperLU_MT on :meth:`pattern`, the Jacobian by scikit-sundae's
          coloured differences over it (twice as fast on the octopus as the
          differences of :meth:`jacobian`, run by Python);
        * ``"dense"``: small systems and cross-checks.

        No band solver: a body's rows couple entries far apart in the state. With rod
        contacts (:class:`rodmol.RodContact`) no "sparse" either (:attr:`refused_solvers`)."""
        return {name: jacobian for name, jacobian in
                {"gmres": "compiled", "sparse": "sundials", "dense": "sundials"}.items()
                if name not in self.refused_solvers}

    @property
    def refused_solvers(self):
        """{linear solver: why this system refuses it}: with rod contacts the sparse
        solver's pattern would leave out the coupling of nodes that come into contact
        during the run (GMRES's products and the dense differences see it)."""
        if self.rod_pairs is None:
            return {}
        return {"sparse": "its Jacobian pattern leaves out the rod contacts' coupling, which comes and "
                          "goes with the rods' motion (`contacts` holds a rodmol.RodContact): use 'gmres' "
                          "(default) or 'dense'"}

    def jacobian(self, scale, matrix="sparse"):
        """The Jacobian by coloured differences on :meth:`pattern`
        (:class:`rodmol.discretise.system_jacobian.SystemJacobian`), sparse only (else ValueError)."""
        from .system_jacobian import SystemJacobian

        if matrix != "sparse":
            raise ValueError(f"a system's compiled Jacobian is sparse only, not {matrix!r}")
        return SystemJacobian(self, scale)

    def preconditioner(self, scale):
        """The block preconditioner of CVODE's Newton matrix
        (:class:`rodmol.discretise.system_preconditioner.SystemPreconditioner`)."""
        from .system_preconditioner import SystemPreconditioner

        return SystemPreconditioner(self, scale)

    def atol_scale(self):
        """Typical magnitude of each entry: the rods' own
        (:meth:`SemiDiscrete.atol_scale`); a body's position the longest rod,
        its velocity the slowest rod's speed scale, its angular velocity that
        speed over the longest rod (:func:`field_scales`)."""
        scales = [sd.atol_scale() for sd in self.rods.values()]
        per_field = self.body_scales()
        for part in self.bodies.values():
            scales.append(np.concatenate([np.full(n, per_field[f]) for f, n in part.layout.fields.items()]))
        return np.concatenate(scales)

    def body_scales(self):
        """Typical size of a body's fields {"x", "Q", "v", "w"} (see :meth:`atol_scale`)."""
        rods = [field_scales(sd.model) for sd in self.rods.values()]
        length, speed = max(f["u"] for f in rods), min(f["v"] for f in rods)
        return {"x": length, "Q": 1.0, "v": speed, "w": speed / length}

    # ------------------------------------------------------------------ checks

    def state_problem(self, t, y):
        """What is wrong with the state ``y`` at ``t`` [s]: each rod's part as a single rod's
        state (the message names the rod), the bodies' entries for finiteness; or None."""
        return parts_problem(self, "state_problem", t, y)

    def step_problem(self, t, y):
        """:meth:`state_problem` after a step of a run, and each rod's tip section, in one
        compiled scan (:func:`rodmol.discretise.state_checks.parts_step_problem`)."""
        return parts_step_problem(self, t, y)

    def describe_stall(self, y):
        """The stall's diagnosis of the most compressed rod (its ``describe_stall``), naming it."""
        name = min(self.rods, key=lambda n: least_stretch(self.rods[n].layout, y[self.parts[n]]))
        return f"In rod {name!r}: {self.rods[name].describe_stall(y[self.parts[name]])}"
