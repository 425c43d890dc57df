"""A rigid body's place in a system's state (:class:`BodyPart`): its block,
its constant data with what it carries (the rods' base segments), the rods
clamped to it and its joints; and the clamped rods' base velocities
(:func:`clamp_map`). :mod:`rodmol.discretise.assembly` says the
frames and the equations."""

import numpy as np

from ..bodies import mass_matrix_about_origin
from ..errors import NotSupportedYet
from .body_contact import BodyContacts
from .layout import BlockLayout
from .rigid import BODY_FIELDS, NET_MASS, NET_MOMENT, POSE_FIELDS, pack_body
from .sampling import section_masses
from .stencil import WORK_TOTAL


def clamp_map(points, turns):
    """(6 n, 6) matrix M of the base velocities (v0, w0) = (Rj^T (v + w x p), Rj^T w) of n
    rods clamped at ``points`` (n, 3) [m] with ``turns`` (n, 3, 3) (base to body frame) to a
    body moving with (v, w) (body frame): the rods' rows (v0, w0) stacked are M (v, w), local
    frames of the bases. A constant of the clamps: one product per right-hand side (the
    same with cross products and einsum cost 27 us a call, most of the octopus's body)."""
    points, turns = np.asarray(points, dtype=float).reshape(-1, 3), np.asarray(turns, dtype=float)
    back = np.transpose(turns, (0, 2, 1))  # Rj^T
    skew = np.zeros((len(points), 3, 3))  # skew(p) w = p x w, so w x p = -skew(p) w
    skew[:, 0, 1], skew[:, 0, 2], skew[:, 1, 2] = -points[:, 2], points[:, 1], -points[:, 0]
    skew -= np.transpose(skew, (0, 2, 1))
    m = np.zeros((len(points), 6, 6))
    m[:, :3, :3], m[:, :3, 3:], m[:, 3:, 3:] = back, -back @ skew, back
    return m.reshape(-1, 6)


def first_element(start, sd):
    """State indices of the header and first element block of the rod of system ``sd`` whose
    entries start at ``start``: the rows a clamp's body velocities move (its base velocities)."""
    return np.arange(start, start + sd.layout.header + sd.layout.block)


class BodyPart:
    """One rigid body's place in the state, its constant data and its rods'
    clamps stacked for the coupling (points (n, 3) [m] and rotations (n, 3, 3),
    base to body frame). ``mass_matrix`` (6, 6), ``rigid_mass`` (the same
    without the body's added mass) and ``params`` (:func:`pack_body`'s row)
    include the rods' base segments it carries (:meth:`carry`). A pinned
    base's body (``segment_only``) is the segment of its rod alone: its
    RigidBody's own mass properties are left out."""

    def __init__(self, name, body, start, fluid_density, segment_only=False):
        self.name, self.body, self.segment_only = name, body, segment_only
        self.params = pack_body(body, fluid_density) * (not segment_only)
        self.layout = BlockLayout(1, dict(BODY_FIELDS if body.free else POSE_FIELDS))
        self.slice = slice(start, start + self.layout.size)
        self.fields = {f: slice(start + s.start, start + s.stop) for f, s in self.layout.slices().items()}
        own = 0.0 if segment_only else 1.0
        self.mass_matrix = own * body.mass_matrix  # with the rods' base segments (clamp)
        self.inverse_mass = None if segment_only else np.linalg.inv(self.mass_matrix)
        # Gyroscopic terms and momentum: no body added mass.
        self.rigid_mass = own * (body.mass_matrix - body.added_mass)
        self.rods, self.systems = [], []
        self.works = []  # each rod kernel's scratch: cell 0's total stress after a call (stencil.rhs)
        self.stress_rows = []  # views of that stress in each of them, (6,)
        self.points, self.turns = np.zeros((0, 3)), np.zeros((0, 3, 3))
        self.velocity_map = clamp_map(self.points, self.turns)  # (6 n, 6): :func:`clamp_map`
        self._bases = np.zeros(0)  # (6 n,) its rods' base velocities (:meth:`move_bases`)
        #: Its velocities (v, w), consecutive in its block (BODY_FIELDS), if free.
        self.velocities = slice(self.fields["v"].start, self.fields["w"].stop) if body.free else None
        self.shares = np.zeros(0)  # the base node's share of cell 0 [m] (Scheme.base_share ds)
        self.strains = np.zeros((0, 6), dtype=np.int64)  # state indices of (q, k) of each rod's cell 0
        self.joints = []  # its penalty joints (JointPart)
        self.body_joints = []  # its joints to other bodies or the world (BodyJointPart)
        self.contacts = BodyContacts(body) if body.contacts else None

    def clamp(self, name, sd, start, point, turn):
        """Hold the base of rod ``name`` (its system ``sd``, its state from ``start``)."""
        self.shares = np.append(self.shares, sd.scheme.base_share * sd.model.ds)
        self.carry(sd, point, turn)
        self.rods.append(name)
        self.systems.append(sd)
        self.works.append(sd.kernel_arguments()[-1])
        self.stress_rows.append(self.works[-1][0, WORK_TOTAL:WORK_TOTAL + 6])
        self.points = np.vstack([self.points, point])
        self.turns = np.concatenate([self.turns, np.asarray(turn, dtype=float)[None]])
        self.flat_turns = np.ascontiguousarray(self.turns.reshape(-1, 9))  # row-major, for the kernel
        self.velocity_map = clamp_map(self.points, self.turns)
        # The rods' base velocities, one row each, which their systems read (one product a call).
        self._bases = np.concatenate([self._bases, sd.base_velocities])
        for i, system in enumerate(self.systems):
            system.read_base_velocities_from(self._bases[6 * i:6 * i + 6])
        sl, first = sd.layout.slices(), start + sd.layout.header
        index = np.r_[first + sl["q"].start:first + sl["q"].stop, first + sl["k"].start:first + sl["k"].stop]
        self.strains = np.vstack([self.strains, index])

    def carry(self, sd, point, turn):
        """Add to the body the base segment of the rod of system ``sd``
        clamped at ``point`` [m] with ``turn`` (base to body frame): the
        length of rod its velocity nodes leave out (the base node's,
        ``Scheme.node_lengths``: ds/2 centred, none upwind) with the base
        section's masses, lumped at the clamp as the nodes' are at theirs."""
        length = max(sd.model.rod.length - float(np.sum(sd.node_lengths)), 0.0)
        if self.segment_only and length <= 1e-9 * sd.model.ds:
            raise NotSupportedYet(f"body {self.name!r} is a pinned base, the segment its rod's velocity nodes "
                                  f"leave out, but the scheme {sd.scheme.name!r} leaves none: pin a base with "
                                  "the centred scheme")
        mass, _, inertia, net_mass = (length * a[0] for a in section_masses(sd.model, [0.0]))
        turn = np.asarray(turn, dtype=float)
        segment = mass_matrix_about_origin(turn @ np.diag(mass) @ turn.T, turn @ np.diag(inertia) @ turn.T, point)
        self.mass_matrix += segment
        self.inverse_mass = np.linalg.inv(self.mass_matrix)
        self.rigid_mass += segment  # its added mass too, as the rods' nodes count theirs
        self.params[NET_MASS] += net_mass
        self.params[NET_MOMENT:NET_MOMENT + 3] += net_mass * np.asarray(point, dtype=float)

    def base_velocities(self, v, w):
        """(n, 6) base velocities of the rods for the body velocities (v, w) (:func:`clamp_map`)."""
        return (self.velocity_map @ np.concatenate([v, w])).reshape(-1, 6)

    def move_bases(self, y):
        """Set its rods' base velocities (their systems' ``base_velocities``) from its
        velocities in the state ``y`` (a free body's)."""
        np.dot(self.velocity_map, y[self.velocities], out=self._bases)
