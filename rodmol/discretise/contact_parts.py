"""Rods touching rigid bodies (:class:`rodmol.Contact`): the body's shape is
one of the rod's contact loads (a contact shape of
:data:`rodmol.loads.CONTACT_SHAPES`) whose geometry the body moves (its
points moved and turned, its directions turned: its record's ``geometry``).

As a penalty joint's hold (:mod:`rodmol.discretise.joints`), every velocity
node's entry of that load is one part of the system: before each
right-hand side its parameter row gets the shape where the body's pose puts
it (global) and the obstacle's motion there (the velocity of the body's
point at the row's first point and the body's angular velocity, global:
the law's damping and friction act on the relative sliding), and the body
feels the node's contact force with the opposite sign, acting at the
contact point on the tube's surface, with its moment about the body's
origin. The parts have a penalty joint part's interface (``joint.rod``,
``part``, ``node``, ``entry``, ``row``, ``value``, :meth:`ContactPart.wrench`),
so the assembly, its Jacobian pattern, the preconditioner's Schur
complement, the equilibrium and the rebuilt Results take them as joints.
"""

import numpy as np

from ..load_kinds import KERNELS
from ..loads import P_OBSTACLE_SPIN, P_OBSTACLE_VELOCITY, P_RADIUS
from .external import contact, contact_depth
from .layout import QUAT, U, V, W
from .load_entries import count
from .physics import add, cross, jit, rotation, scale, sub, to_global, to_local
from .rigid import BQ, BV, BW, BX, _row3

#: A part's reaction when its group's first part carried it (force, moment).
NOTHING = ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0))


@jit
def contact_reaction(kind, row, y, node, body, shape, moves, length):
    """Move a contact entry's obstacle with a body and return its reaction.

    Writes into ``row`` (the entry's parameter row) the shape's 3-vectors
    ``shape`` (n, 3), body frame, placed by the body in the state ``body``
    (x, Q, v, w: origin [m], quaternion, global; velocities [m/s, rad/s],
    body frame): each turned with the body and, where ``moves`` (n,) is 1
    (a point, not a direction), moved with its origin; and the obstacle's
    motion (global) at the first vector, a point. Returns the force and
    moment [N, N m] about the body's origin, body frame, on the body: the
    opposite of the force on the rod node whose element block starts at
    ``y[node]`` (its density times the node's ``length`` [m]), acting at
    the contact point."""
    x_b = _row3(body, BX)
    r_b = rotation((body[BQ], body[BQ + 1], body[BQ + 2], body[BQ + 3]))
    v_b, w_b = _row3(body, BV), _row3(body, BW)
    for k in range(shape.shape[0]):
        placed = add(scale(moves[k], x_b), to_global(r_b, _row3(shape[k], 0)))
        for i in range(3):
            row[3 * k + i] = placed[i]
    first = _row3(shape[0], 0)
    velocity, spin = to_global(r_b, add(v_b, cross(w_b, first))), to_global(r_b, w_b)
    for i in range(3):
        row[P_OBSTACLE_VELOCITY + i], row[P_OBSTACLE_SPIN + i] = velocity[i], spin[i]
    u = _row3(y, node + U)
    r = rotation((y[node + QUAT], y[node + QUAT + 1], y[node + QUAT + 2], y[node + QUAT + 3]))
    f, _ = contact(kind, row, u, r, _row3(y, node + V), _row3(y, node + W))
    _, normal = contact_depth(kind, row, u)
    at = sub(u, scale(row[P_RADIUS], normal))  # the contact point on the tube's surface, global
    force = to_local(r_b, scale(-length, to_global(r, f)))
    return force, cross(to_local(r_b, sub(at, x_b)), force)


@jit
def group_reaction(kind, rows, y, nodes, body, shape, moves, lengths):
    """:func:`contact_reaction` of the entries ``rows`` (n, N_PARAMS) at the
    element blocks starting at ``y[nodes]`` (n,) of nodes of ``lengths``
    (n,) [m], all moved by one body: their total force and moment on it."""
    force, moment = (0.0, 0.0, 0.0), (0.0, 0.0, 0.0)
    for i in range(nodes.shape[0]):
        f, m = contact_reaction(kind, rows[i], y, nodes[i], body, shape, moves, lengths[i])
        force, moment = add(force, f), add(moment, m)
    return force, moment


class ContactPart:
    """The entry of rod contact ``record`` (a :class:`rodmol.contacts.RodContact`:
    its rod, load and shape in the body frame) at one velocity node
    (element block ``block``) of the rod of system ``sd`` (state from
    ``rod_start``), moved by the body ``part``. ``group`` is the first
    part of the same record and rod (None for that one), which moves the
    whole group's rows in one compiled call."""

    def __init__(self, record, sd, rod_start, part, block, group=None):
        model = sd.model
        self.joint, self.part, self.leader = record, part, group is None
        self.entry = sum(count(item, model.s_nodes) for item in model.loads[:record.load]) + block
        self.kind = KERNELS[record.shape.kernel].code
        self.row, self.value = sd.entry_params[self.entry], sd.entry_values[self.entry]
        self.node = rod_start + sd.layout.header + sd.layout.block * block
        self.length = float(sd.grid_loads.weight[self.entry] * sd.node_lengths[block])
        self.shape = np.ascontiguousarray(record.shape.shape_vectors())
        roles = KERNELS[record.shape.kernel].geometry
        self.moves = np.array([1.0 if role == "point" else 0.0 for role in roles])
        if self.leader:  # the group's arrays, filled by the others as they are made
            self.rows = sd.entry_params[self.entry:self.entry]
            self.nodes, self.lengths = np.zeros(0, dtype=np.int64), np.zeros(0)
            group = self
        group.rows = sd.entry_params[group.entry:self.entry + 1]
        group.nodes = np.append(group.nodes, self.node)
        group.lengths = np.append(group.lengths, self.length)

    def wrench(self, y, body, row, value):
        """Write the obstacle's place and motion into ``row`` and return the
        body's reaction (:func:`contact_reaction`; ``value`` is not read).
        Given its own row (the kernel's: the right-hand side, the
        equilibrium's residual), the group's first part writes the whole
        group's rows and returns their total reaction, the others nothing
        (their rows are written); given another row (scratch, or a frame's
        replay), each part its own node."""
        if row is not self.row:
            return contact_reaction(self.kind, row, y, self.node, body, self.shape, self.moves, self.length)
        if not self.leader:
            return NOTHING
        return group_reaction(self.kind, self.rows, y, self.nodes, body, self.shape, self.moves, self.lengths)


def contact_parts(assembly):
    """The :class:`ContactPart` of every node of every rod contact of
    ``assembly``'s system (``System.rod_contacts``), each appended to its
    body's ``joints`` (the assembly's rods, parts and bodies made)."""
    parts = []
    for record in assembly.system.rod_contacts:
        sd, part = assembly.rods[record.rod], assembly.bodies[record.body]
        group = None
        for block in range(sd.layout.n_blocks):
            part.joints.append(ContactPart(record, sd, assembly.parts[record.rod].start, part, block, group))
            parts.append(part.joints[-1])
            group = parts[-1] if group is None else group
    return parts
