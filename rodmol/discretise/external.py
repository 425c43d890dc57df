"""External loads at the velocity nodes, compiled: the kinds, their parameter
rows, what each reads of the state, and the one function that evaluates them.

A model's external loads (:mod:`rodmol.loads`) become *entries*: (kind,
velocity node, weight, parameter row, value). Every entry adds ``weight`` times
its force and moment densities to its node's balance laws, in the local frame.

To add a kind: give it a record in :data:`rodmol.load_kinds.KERNELS` (its
code, the state fields it reads, what it adds up as and, for a hold or a
contact shape, its turning and geometry) and a branch here: a hold kind in
:func:`hold` and :func:`hold_energy`, a contact shape in
:func:`contact_depth` (its law, energy and motion with a body are shared),
another in :func:`load`. Its loads tell the grid how they spread and what
parameter row they hand the kernel (:mod:`rodmol.discretise.load_entries`).
The Jacobian's pattern, colouring and preconditioner are derived from the
records; ``tests/test_load_records.py`` walks every record and names what a
half-added kind lacks (docs/systems.md, "Adding a joint kind or a contact
shape").
"""

import numpy as np

from ..load_kinds import KERNELS, codes
from ..loads import (
    N_PARAMS,  # noqa: F401 (the row width, read here by the system)
    P_DAMPING,
    P_FRICTION,
    P_HELD_SPIN,
    P_HELD_VELOCITY,
    P_OBSTACLE_SPIN,
    P_OBSTACLE_VELOCITY,
    P_RADIUS,
    P_SLIP,
    P_SMOOTHING,
    P_STIFFNESS,
    P_TURN_DAMPING,
    P_TURN_STIFFNESS,
)
from .physics import add, cross, dot, jit, quaternion_product, rotation, scale, sub, to_local

# The codes as module constants: the compiled branches read them as such (numba
# freezes them at compile time; the kernel cache's digest holds load_kinds.py).
FOLLOWER_FORCE, DEAD_FORCE = KERNELS["follower_force"].code, KERNELS["dead_force"].code
FOLLOWER_MOMENT, DEAD_MOMENT = KERNELS["follower_moment"].code, KERNELS["dead_moment"].code
PLANE, CAPSULE = KERNELS["plane"].code, KERNELS["capsule"].code
PIN, CLAMP = KERNELS["pin"].code, KERNELS["clamp"].code
#: The codes of the holds (rodmol.Hold, a system's joints), of those that hold the
#: section's turning too, and of the contact shapes: from the records' fields.
HOLDS, TURNING_HOLDS, CONTACTS = codes("hold"), codes("hold", holds_turning=True), codes("contact")

#: Which fields of its own element block each kind reads (force rows "v" and
#: moment rows "w" of that block are the ones written).
DEPENDS = {k.code: k.depends for k in KERNELS.values()}


def dependency_table(kinds):
    """The dependency table (see :mod:`rodmol.discretise.layout`) of a set of kinds."""
    cols = tuple(dict.fromkeys(f for kind in kinds for f in DEPENDS[int(kind)]))
    return {"v": {0: cols}, "w": {0: cols}} if cols else {}


@jit
def contact_depth(kind, p, u):
    """Penetration depth [m] of a tube section centred at u (global) into the
    obstacle of parameter row p, and the obstacle's outward unit normal there."""
    if kind == PLANE:
        n = (p[3], p[4], p[5])
        return p[P_RADIUS] - dot(n, sub(u, (p[0], p[1], p[2]))), n
    a, b = (p[0], p[1], p[2]), (p[3], p[4], p[5])
    axis = sub(b, a)
    length2 = dot(axis, axis)
    x = 0.0 if length2 == 0.0 else min(1.0, max(0.0, dot(sub(u, a), axis) / length2))
    d = sub(u, add(a, scale(x, axis)))
    dist = np.sqrt(dot(d, d))
    n = scale(1.0 / dist, d) if dist > 0.0 else (0.0, 1.0, 0.0)
    return p[6] + p[P_RADIUS] - dist, n


@jit
def penalty(depth, smoothing):
    """Penetration measure of the penalty law and its damping ramp: d - h/2
    beyond the smoothing depth h, d^2 / (2 h) below it (so the force and its
    slope are continuous at first touch, which Newton iterations and BDF
    steps need), 0 outside."""
    if depth <= 0.0:
        return 0.0, 0.0
    if depth >= smoothing:
        return depth - 0.5 * smoothing, 1.0
    return 0.5 * depth * depth / smoothing, depth / smoothing


@jit
def contact(kind, p, u, r, v, w):
    """Penalty contact with regularised Coulomb friction (see rodmol.loads),
    acting at the surface point; returns (force, moment) densities, local.
    The damping and friction act on the surface point's velocity relative to
    the obstacle's material point there (the row's obstacle motion: zero for
    a fixed obstacle)."""
    depth, n_global = contact_depth(kind, p, u)
    measure, ramp = penalty(depth, p[P_SMOOTHING])
    if measure <= 0.0:
        return (0.0, 0.0, 0.0), (0.0, 0.0, 0.0)
    n = to_local(r, n_global)
    arm = scale(-p[P_RADIUS], n)  # from the centreline to the contact point
    spin = (p[P_OBSTACLE_SPIN], p[P_OBSTACLE_SPIN + 1], p[P_OBSTACLE_SPIN + 2])
    at = sub(sub(u, scale(p[P_RADIUS], n_global)), (p[0], p[1], p[2]))  # the surface point from the row's first
    moving = add((p[P_OBSTACLE_VELOCITY], p[P_OBSTACLE_VELOCITY + 1], p[P_OBSTACLE_VELOCITY + 2]), cross(spin, at))
    vp = sub(add(v, cross(w, arm)), to_local(r, moving))
    vn = dot(vp, n)
    normal = p[P_STIFFNESS] * measure - ramp * p[P_DAMPING] * vn  # d_t = -vn
    if normal <= 0.0:
        return (0.0, 0.0, 0.0), (0.0, 0.0, 0.0)
    vt = sub(vp, scale(vn, n))
    slip = np.sqrt(dot(vt, vt) + p[P_SLIP] * p[P_SLIP])
    f = sub(scale(normal, n), scale(p[P_FRICTION] * normal / slip, vt))
    return f, cross(arm, f)


@jit
def pin_force(gap, gap_rate, stiffness, damping):
    """Penalty force [N] of a pin joint, -stiffness gap - damping gap_rate,
    in the frame of the gap [m] and its rate [m/s] (a body-side joint passes
    the gap between the two points and their relative velocity)."""
    return sub(scale(-stiffness, gap), scale(damping, gap_rate))


@jit
def clamp_moment(quat, held, w, stiffness, damping):
    """Penalty moment [N m], local, turning a section of orientation ``quat``
    toward the orientation ``held`` (quaternions, global): stiffness sin(theta) n
    - damping w, theta n the rotation (local) from the section to ``held`` and
    ``w`` [rad/s] the section's angular velocity relative to ``held``, local.
    sin(theta) n = 2 e0 e (e = conj(quat) held) is smooth and even in the
    quaternions' signs; its energy is stiffness (1 - cos theta)."""
    a, b, c, d = quaternion_product((quat[0], -quat[1], -quat[2], -quat[3]), held)
    norms = ((quat[0] * quat[0] + quat[1] * quat[1] + quat[2] * quat[2] + quat[3] * quat[3])
             * (held[0] * held[0] + held[1] * held[1] + held[2] * held[2] + held[3] * held[3]))
    f = 2.0 * a / norms
    return sub(scale(stiffness * f, (b, c, d)), scale(damping, w))


@jit
def hold(kind, p, value, u, quat, r, v, w):
    """(force, moment) [N, N m], local, of a hold (rodmol.Hold) at a node of
    pose (u, quat) moving with (v, w) (local): held at p[0:3] + ``value`` (its
    rest position plus the held displacement, global) and, for a clamp, at the
    orientation p[3:7]. The held point moves with the velocity and angular
    velocity of the row's ``P_HELD_VELOCITY``, ``P_HELD_SPIN`` (global: zero
    on the world, a body's for a joint of a system): the damping acts on the
    velocities relative to it."""
    gap = sub(u, add((p[0], p[1], p[2]), value))
    held_v = (p[P_HELD_VELOCITY], p[P_HELD_VELOCITY + 1], p[P_HELD_VELOCITY + 2])
    f = pin_force(to_local(r, gap), sub(v, to_local(r, held_v)), p[P_STIFFNESS], p[P_DAMPING])
    if kind not in TURNING_HOLDS:
        return f, (0.0, 0.0, 0.0)
    held_w = (p[P_HELD_SPIN], p[P_HELD_SPIN + 1], p[P_HELD_SPIN + 2])
    return f, clamp_moment(quat, (p[3], p[4], p[5], p[6]), sub(w, to_local(r, held_w)), p[P_TURN_STIFFNESS],
                           p[P_TURN_DAMPING])


@jit
def load(kind, p, value, u, quat, v, w):
    """(force, moment) densities of one entry of ``kind``, local frame, before
    its weight; ``value`` is the entry's vector (in its own frame)."""
    zero = (0.0, 0.0, 0.0)
    if kind == FOLLOWER_FORCE:
        return value, zero
    if kind == FOLLOWER_MOMENT:
        return zero, value
    r = rotation(quat)
    if kind == DEAD_FORCE:
        return to_local(r, value), zero
    if kind == DEAD_MOMENT:
        return zero, to_local(r, value)
    if kind in HOLDS:
        return hold(kind, p, value, u, quat, r, v, w)
    return contact(kind, p, u, r, v, w)


@jit
def contact_energy(kind, p, u):
    """Elastic energy density [J/m] of the contact penalty at u (the integral
    of the penalty force over the depth)."""
    if kind not in CONTACTS:
        return 0.0
    depth, _ = contact_depth(kind, p, u)
    h = p[P_SMOOTHING]
    if depth <= 0.0:
        return 0.0
    if depth < h:
        return p[P_STIFFNESS] * depth ** 3 / (6.0 * h)
    return p[P_STIFFNESS] * (h * h / 6.0 + 0.5 * (depth - h) * (depth + h) - 0.5 * h * (depth - h))


@jit
def hold_energy(kind, p, value, u, quat):
    """Elastic energy [J] of a hold's penalty at a node of pose (u, quat):
    stiffness |u - p|^2 / 2, plus for a clamp turning stiffness (1 - cos
    theta), the potential of :func:`clamp_moment` (1 - cos theta = 2 sin^2(theta / 2),
    from e = conj(quat) held: its vector part's squared norm over its own)."""
    if kind not in HOLDS:
        return 0.0
    gap = sub(u, add((p[0], p[1], p[2]), value))
    energy = 0.5 * p[P_STIFFNESS] * dot(gap, gap)
    if kind in TURNING_HOLDS:
        a, b, c, d = quaternion_product((quat[0], -quat[1], -quat[2], -quat[3]), (p[3], p[4], p[5], p[6]))
        energy += p[P_TURN_STIFFNESS] * 2.0 * (b * b + c * c + d * d) / (a * a + b * b + c * c + d * d)
    return energy
