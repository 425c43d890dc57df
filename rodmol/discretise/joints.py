"""Penalty joints of a system (:mod:`rodmol.discretise.assembly`): a rod
node held to a rigid body by its hold (rodmol.Hold, one of the rod's load
entries) whose held point the body moves, and a rod's system replaying the
held points of recorded frames for its Result."""

import numpy as np

from ..errors import ParameterError
from ..loads import KERNELS
from .layout import FIELDS
from .load_entries import count
from .physics import quaternion_product
from .rigid import joint_wrench
from .rotations import from_matrix
from .system import SemiDiscrete


def block_entries(*fields):
    """Indices of ``fields`` within an element block."""
    return np.concatenate([np.arange(FIELDS[f].start, FIELDS[f].stop) for f in fields])


class JointPart:
    """A penalty joint between a rod node and a body: the rod's hold entry
    (its parameter row and value, the kernel's arrays), the node's element
    block in the state, the body point [m] and the section's held
    orientation ``turn`` (quaternion, section to body frame)."""

    def __init__(self, joint, sd, rod_start, part):
        model = sd.model
        hold = model.loads[joint.load]
        entry = sum(count(load, model.s_nodes) for load in model.loads[:joint.load])
        self.joint, self.sd, self.part, self.entry = joint, sd, part, entry
        self.kind = KERNELS[hold.kernel].code
        self.row, self.value = sd.entry_params[entry], sd.entry_values[entry]
        node = int(round(hold.s / model.ds))
        self.node = rod_start + sd.layout.header + sd.layout.block * (node - 1)
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
