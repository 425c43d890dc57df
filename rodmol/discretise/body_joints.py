"""Joints between two rigid bodies, or a body and the world, of a system
(:class:`rodmol.systems.BodyJoint`): the :class:`rodmol.Hold` law between
a point of each body.

Body a's joint frame (its point x_a + R_a p_a and axes R_a T_a, global)
plays the held node of a Hold, body b's joint frame the held point (the
world's: fixed where a's is at rest); the hold's force F and, for a clamp,
moment M act on a, -F and -M on b, the force at a's point on both (equal
and opposite with one line of action: momentum and angular momentum are
kept). The damping acts on a's velocities relative to b's point.

Default law: the joint's reduced mass m (1/m = 1/m_a + 1/m_b, a body's mass
at the joint point; a fixed or driven body or the world counts as
infinite) and reduced rotational inertia I about the point (likewise) on a
spring of the frequency omega of a rod node on its default Hold, the
system's fastest (``HOLD_STIFFNESS_FACTOR`` E A / ds on rho A ds:
omega^2 = HOLD_STIFFNESS_FACTOR E / (rho ds^2)): stiffness m omega^2,
turning stiffness I omega^2, both dampings critical. The joint's mode is
then no faster than the rods' held nodes', and its drift is the joint's
load over m omega^2 (docs/systems.md, "Joints of bodies").
"""

import numpy as np

from ..holds import HOLD_STIFFNESS_FACTOR
from ..loads import KERNELS, N_PARAMS, P_DAMPING, P_STIFFNESS, P_TURN_DAMPING, P_TURN_STIFFNESS
from .external import hold
from .physics import add, cross, jit, quaternion_product, rotation, scale, to_global, to_local
from .rigid import BQ, BV, BW, BX, FREE_BODY, held_by, reaction
from .rotations import from_matrix


def joint_frequency(models):
    """omega [rad/s] of a body joint's default law: the fastest of the
    models' nodes on their default Hold (HOLD_STIFFNESS_FACTOR E / (rho ds^2))."""
    return max(np.sqrt(HOLD_STIFFNESS_FACTOR * m.rod.material.E / m.rod.material.rho) / m.ds for m in models)


def point_masses(mass_matrix, point):
    """(mass [kg], rotational inertia [kg m^2]) of a body at ``point`` [m]
    (body frame): the means of the diagonals of its 6x6 ``mass_matrix``
    (about the origin) moved to the point."""
    shift = np.eye(6)
    px, py, pz = point
    shift[:3, 3:] = [[0.0, -pz, py], [pz, 0.0, -px], [-py, px, 0.0]]  # origin velocity v_p + p x w
    moved = shift.T @ mass_matrix @ shift
    return np.trace(moved[:3, :3]) / 3.0, np.trace(moved[3:, 3:]) / 3.0


def joint_law(joint, parts, omega):
    """(stiffness [N/m], damping [N s/m], turning stiffness [N m], turning
    damping [N m s]) of ``joint`` between the body parts ``parts`` (a, b; b
    None for the world): the joint's own values, else the defaults (module
    docstring); the turning law is the translational one times I / m."""
    inverse_mass, inverse_inertia = 0.0, 0.0
    for part, point in zip(parts, (joint.point_a, joint.point_b)):
        if part is not None and part.body.free:
            m, i = point_masses(part.mass_matrix, point)
            inverse_mass, inverse_inertia = inverse_mass + 1.0 / m, inverse_inertia + 1.0 / i
    mass, inertia = 1.0 / inverse_mass, 1.0 / inverse_inertia
    k = mass * omega**2 if joint.stiffness is None else joint.stiffness
    c = 2.0 * np.sqrt(k * mass) if joint.damping is None else joint.damping
    arm2 = inertia / mass
    return k, c, k * arm2, c * arm2


@jit
def pair_wrench(kind, row, value, a, point_a, turn_a, b, point_b, turn_b):
    """The hold between body a's joint frame and body b's: ``a``, ``b`` the
    bodies' states (x, Q, v, w: origin [m] and quaternion, global;
    velocities, body frame), ``point_*`` [m] and ``turn_*`` (quaternion) the
    joint frames in the body frames; ``row`` the hold's parameter row (its
    rest position zero: ``value`` takes b's point), written as
    :func:`rodmol.discretise.rigid.held_by` does. Returns the force and
    moment [N, N m] about each body's origin, body frame: (a's, b's)."""
    held_by(row, value, b, point_b, turn_b)
    q_a = (a[BQ], a[BQ + 1], a[BQ + 2], a[BQ + 3])
    r_a = rotation(q_a)
    p = (point_a[0], point_a[1], point_a[2])
    u = add((a[BX], a[BX + 1], a[BX + 2]), to_global(r_a, p))
    quat = quaternion_product(q_a, (turn_a[0], turn_a[1], turn_a[2], turn_a[3]))
    r = rotation(quat)
    w_a = (a[BW], a[BW + 1], a[BW + 2])
    velocity = to_local(r, to_global(r_a, add((a[BV], a[BV + 1], a[BV + 2]), cross(w_a, p))))
    spin = to_local(r, to_global(r_a, w_a))
    f, m = hold(kind, row, (value[0], value[1], value[2]), u, quat, r, velocity, spin)
    force, moment = to_global(r, f), to_global(r, m)
    return reaction(a, u, scale(-1.0, force), scale(-1.0, moment)), reaction(b, u, force, moment)


class BodyJointPart:
    """A :class:`rodmol.systems.BodyJoint` between the body parts ``a`` and
    ``b`` (:class:`rodmol.discretise.body_part.BodyPart`; b None for the
    world), its law from :func:`joint_law` at the frequency ``omega``."""

    def __init__(self, joint, a, b, omega):
        self.joint, self.a, self.b = joint, a, b
        self.parts = [part for part in (a, b) if part is not None]
        self.kind = KERNELS[joint.kind].code
        self.row, self.value = np.zeros(N_PARAMS), np.zeros(3)
        self.row[[P_STIFFNESS, P_DAMPING, P_TURN_STIFFNESS, P_TURN_DAMPING]] = joint_law(joint, (a, b), omega)
        self.point_a, self.turn_a = np.asarray(joint.point_a, dtype=float), from_matrix(joint.rotation_a)
        self.point_b, self.turn_b = np.asarray(joint.point_b, dtype=float), from_matrix(joint.rotation_b)
        self.world = None
        if b is None:  # the world as a body at rest, its origin and axes a's joint frame at rest
            self.world = np.zeros(FREE_BODY.size)
            self.world[BX:BX + 3], self.world[BQ:BQ + 4] = self.point_b, self.turn_b
            self.point_b, self.turn_b = np.zeros(3), np.array([1.0, 0.0, 0.0, 0.0])

    def wrench(self, a, b=None):
        """((a's force, moment), (b's force, moment)) [N, N m] about their
        origins, body frames, for the bodies' states ``a``, ``b`` (b None: the world)."""
        b = self.world if b is None else b
        return pair_wrench(self.kind, self.row, self.value, a, self.point_a, self.turn_a, b, self.point_b,
                           self.turn_b)
