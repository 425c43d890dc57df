"""Penalty joints of a system (:mod:`rodmol.discretise.assembly`): a rod
node held to a rigid body by its hold (rodmol.Hold, one of the rod's load
entries) whose held point the body moves, and a rod's system replaying the
held points of recorded frames for its Result."""

import numpy as np

from ..errors import ParameterError
from ..loads import KERNELS, P_DAMPING, P_STIFFNESS, P_TURN_DAMPING, P_TURN_STIFFNESS
from .layout import FIELDS
from .load_entries import count
from .physics import quaternion_product
from .rigid import joint_wrench
from .rotations import from_matrix
from .system import SemiDiscrete

#: The columns of a hold's parameter row that make its law: both sides of a joint between rods share them.
SHARED_LAW = [P_STIFFNESS, P_DAMPING, P_TURN_STIFFNESS, P_TURN_DAMPING]


def block_entries(*fields):
    """Indices of ``fields`` within an element block."""
    return np.concatenate([np.arange(FIELDS[f].start, FIELDS[f].stop) for f in fields])


#: A joint node's entries within its element block: the rows its reaction moves (the velocities)
#: and the entries the reaction reads (the node's pose and velocities).
JOINT_ROWS, JOINT_COLUMNS = block_entries("v", "w"), block_entries("u", "Q", "v", "w")


class JointPart:
    """A penalty joint between a rod node and a body: the rod's hold entry
    (its parameter row and value, the kernel's arrays), the node's element
    block in the state, the body point [m] and the section's held
    orientation ``turn`` (quaternion, section to body frame)."""

    def __init__(self, joint, sd, rod_start, part):
        model = sd.model
        hold = model.loads[joint.load]
        entry = _entry(model, joint.load)
        self.joint, self.part, self.entry = joint, part, entry
        self.kind = KERNELS[hold.kernel].code
        self.row, self.value = sd.entry_params[entry], sd.entry_values[entry]
        self.node = _node(sd, rod_start, hold.s)
        self.point = np.asarray(joint.point, dtype=float)
        q_b = from_matrix(part.body.rotation)
        self.turn = np.array(quaternion_product((q_b[0], -q_b[1], -q_b[2], -q_b[3]), tuple(self.row[3:7])))
        gap = float(np.linalg.norm(self.value))
        if gap > 1e-6 * model.rod.length:
            raise ParameterError(f"`{hold.name}` joins rod node s = {hold.s:g} m to body {part.name!r}, but the "
                                 f"body point is {gap:.3g} m from where the node is at rest: place the body so "
                                 "that they meet (its `position`, `rotation` or the joint's point)")

    def wrench(self, y, body, row, value):
        """Write the held point into ``row``, ``value`` and return the body's reaction (:func:`joint_wrench`)."""
        return joint_wrench(self.kind, row, value, y, self.node, body, self.point, self.turn)


class RecordedJoints(SemiDiscrete):
    """A rod's system whose penalty joints' held points replay those of
    recorded frames (exact at the frames, linear between): rebuilds the
    rod's Result (its joint forces, the tip's boundary rows) frame by frame.
    ``replay`` lists (entry, rows (n_t, N_PARAMS), values (n_t, 3)) at ``t``."""

    def __init__(self, model, scheme, t, replay):
        super().__init__(model, scheme)
        self._t, self._replay = np.asarray(t, dtype=float), replay
        self._inputs_vary = True

    def __reduce__(self):
        return RecordedJoints, (self.model, self.scheme.name, self._t, self._replay)

    def update_inputs(self, t, y=None, tensions=None):
        super().update_inputs(t, y, tensions)
        for entry, rows, values in self._replay:
            self.entry_params[entry] = [np.interp(t, self._t, column) for column in rows.T]
            self.entry_values[entry] = [np.interp(t, self._t, column) for column in values.T]


class RodJointPart:
    """One side of a penalty joint between two rods' nodes: rod
    ``joint.rod``'s hold (entry ``entry`` of its system ``sd``) held by the
    node of rod ``joint.partner`` (its system ``partner``, state from
    ``partner_start``) with the orientation it had relative to it at rest,
    ``turn`` (quaternion, this section to the partner's frame). The
    partner's hold is the other side: the two forces are equal and opposite
    (and the clamps' moments), acting at the two nodes."""

    def __init__(self, joint, sd, rod_start, partner, partner_start):
        model, other = sd.model, partner.model
        hold, partner_hold = model.loads[joint.load], other.loads[joint.partner_load]
        self.joint, self.entry = joint, _entry(model, joint.load)
        self.kind = KERNELS[hold.kernel].code
        self.row, self.value = sd.entry_params[self.entry], sd.entry_values[self.entry]
        self.node = _node(sd, rod_start, hold.s)
        self.partner_node = _node(partner, partner_start, partner_hold.s)
        self.partner_fields = self.partner_node + JOINT_COLUMNS
        partner_row = partner.entry_params[_entry(other, joint.partner_load)]
        # One law for both sides, or the pair is not equal and opposite: each hold took its own
        # rod's defaults (k from E A / ds, c from its node's mass, k_r from its radius).
        shared = np.minimum(self.row[SHARED_LAW], partner_row[SHARED_LAW])
        self.row[SHARED_LAW] = partner_row[SHARED_LAW] = shared
        q_p = partner_row[3:7]
        self.turn = np.array(quaternion_product((q_p[0], -q_p[1], -q_p[2], -q_p[3]), tuple(self.row[3:7])))
        self.point = np.zeros(3)
        gap = float(np.linalg.norm(self.row[:3] - partner_row[:3]))
        if gap > 1e-6 * min(model.rod.length, other.rod.length):
            raise ParameterError(f"`{hold.name}` joins rod {joint.rod!r} at s = {hold.s:g} m to rod "
                                 f"{joint.partner!r} at s = {partner_hold.s:g} m, but at rest the two nodes are "
                                 f"{gap:.3g} m apart: place the rods (their Models' `base`) so that they meet")

    def wrench(self, y, row, value):
        """Write the partner node's pose and motion into ``row``, ``value`` (:func:`joint_wrench`)."""
        partner = np.ascontiguousarray(y[self.partner_fields])  # (u, Q, v, w): a body state in its local frame
        return joint_wrench(self.kind, row, value, y, self.node, partner, self.point, self.turn)


def _entry(model, load):
    """The index of the entry of hold ``model.loads[load]`` among the model's load entries."""
    return sum(count(item, model.s_nodes) for item in model.loads[:load])


def _node(sd, start, s):
    """Where the element block of the velocity node at arc length ``s`` starts in the state."""
    return start + sd.layout.header + sd.layout.block * (int(round(s / sd.model.ds)) - 1)
