"""Joints between two rigid bodies, or a body and the world, of a system
(:class:`rodmol.systems.BodyJoint`): the :class:`rodmol.Hold` law between
a point of each body.

Body a's joint frame (its point x_a + R_a p_a and axes R_a T_a, global)
plays the held node of a Hold, body b's joint frame the held point (the
world's: fixed where a's is at rest); the hold's force F and, for a clamp,
moment M act on a, -F and -M on b, the force at a's point on both (equal
and opposite with one line of action: momentum and angular momentum are
kept). The damping acts on a's velocities relative to b's point.

Default law (:func:`joint_law`): the joint's fastest modes at about a
frequency omega (:func:`body_joint_frequency`), and every mode of the joint
at least critically damped; a fixed or driven body or the world counts as
infinitely heavy. Between bodies omega is that of a rod element on
``HOLD_STIFFNESS_FACTOR`` E A / ds, the system's fastest (omega^2 =
HOLD_STIFFNESS_FACTOR E / (rho ds^2)); at a rod's end (a joint of a base
body: a pinned, joined or branched base) it is the rod's node on its
default Hold (:func:`hold_frequency`), whose compliance is O(ds^2) against
the rod's, so that the rod converges at second order. Its drift is the
joint's load over a stiffness of the order of the reduced mass times
omega^2 (docs/systems.md, "Joints of bodies").
"""

import numpy as np

from ..holds import HOLD_STIFFNESS_FACTOR, default_stiffness
from ..loads import KERNELS, N_PARAMS, P_DAMPING, P_STIFFNESS, P_TURN_DAMPING, P_TURN_STIFFNESS
from .external import hold
from .physics import add, cross, jit, quaternion_product, rotation, scale, to_global, to_local
from .rigid import BQ, BV, BW, BX, FREE_BODY, held_by, reaction
from .rotations import from_matrix


def joint_frequency(models):
    """omega [rad/s] of the default law of a joint between bodies: the fastest
    of the models' elements on HOLD_STIFFNESS_FACTOR E A / ds (omega^2 =
    HOLD_STIFFNESS_FACTOR E / (rho ds^2))."""
    return max(np.sqrt(HOLD_STIFFNESS_FACTOR * m.rod.material.E / m.rod.material.rho) / m.ds for m in models)


def hold_frequency(model):
    """omega [rad/s] of a node of ``model`` on its default Hold (its stiffness
    :func:`rodmol.holds.default_stiffness` on the node's mass rho A ds:
    omega^2 = HOLD_STIFFNESS_FACTOR E L / (rho ds^3))."""
    material = model.rod.material
    return np.sqrt(default_stiffness(material.E / model.ds, model.ds, model.rod.length) / (material.rho * model.ds))


def body_joint_frequency(system, joint):
    """omega [rad/s] of ``joint``'s default law (a :class:`rodmol.systems.BodyJoint`
    of ``system``): at a rod's end (a base body's joint) the fastest of its
    rods' nodes on their default Hold, so that its compliance is O(ds^2)
    against theirs as a Hold's; between other bodies :func:`joint_frequency`."""
    rod_of = {body: rod for rod, body in system.base_bodies.items()}
    ends = [system.rods[rod_of[body]] for body in (joint.a, joint.b) if body in rod_of]
    return max(map(hold_frequency, ends)) if ends else joint_frequency(system.rods.values())


def mobility(part, point, turn=None):
    """The 6x6 inverse mass matrix [1/kg, 1/(kg m^2)] of body ``part`` at
    ``point`` [m] (body frame), for the velocities (v_p, w) of the point in
    the frame ``turn`` maps the body frame to: zero for a fixed or driven body."""
    if part is None or not part.body.free:
        return np.zeros((6, 6))
    shift = np.eye(6)
    px, py, pz = point
    shift[:3, 3:] = [[0.0, -pz, py], [pz, 0.0, -px], [-py, px, 0.0]]  # origin velocity v_p + p x w
    frame = np.kron(np.eye(2), np.eye(3) if turn is None else turn)
    return frame @ np.linalg.inv(shift.T @ part.mass_matrix @ shift) @ frame.T


def joint_law(joint, parts, omega):
    """(stiffness [N/m], damping [N s/m], turning stiffness [N m], turning
    damping [N m s]) of ``joint`` between the body parts ``parts`` (a, b; b
    None for the world): the joint's own values, else the defaults (module
    docstring). G, the sum of the two bodies' mobilities at the joint (a's
    body frame, the poses at rest), makes the modes of the relative motion
    those of K^1/2 G K^1/2, K = diag(k, k, k, k_r, k_r, k_r) (a pin: its
    first block): k = omega^2 over G's largest translational eigenvalue,
    k_r = omega^2 over its largest rotational one (the fastest modes at about
    omega), and the damping proportional to K, C = 2 K / omega_min with
    omega_min^2 the smallest mode's: every mode at least critically damped,
    which BDF needs at long steps (its order 5 is stable there for modes
    damped more than 0.62 of critical only, order 4 more than 0.29)."""
    a, b = parts
    turn = np.eye(3) if b is None else a.body.rotation.T @ b.body.rotation
    g = mobility(a, joint.point_a) + mobility(b, joint.point_b, turn)
    clamp = KERNELS[joint.kind].holds_turning
    k = omega**2 / np.linalg.eigvalsh(g[:3, :3])[-1] if joint.stiffness is None else joint.stiffness
    k_r = k * np.linalg.eigvalsh(g[:3, :3])[-1] / np.linalg.eigvalsh(g[3:, 3:])[-1] if clamp else 0.0
    size = 6 if clamp else 3
    root = np.sqrt(np.r_[k, k, k, k_r, k_r, k_r][:size])
    slowest = np.sqrt(np.linalg.eigvalsh(root[:, None] * g[:size, :size] * root[None, :])[0])
    beta = 2.0 / slowest if joint.damping is None else joint.damping / k
    return k, beta * k, k_r, beta * k_r


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
    world), its law from :func:`joint_law` at the frequency ``omega``
    (:func:`body_joint_frequency`)."""

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
