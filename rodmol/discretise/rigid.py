"""Compiled physics of a system's free rigid bodies: the wrench of the rods
clamped to a body, the penalty joints' reactions and the body's Newton-Euler
rates (:mod:`rodmol.discretise.assembly` says the frames and the equations)."""

import numpy as np

from ..loads import P_HELD_SPIN, P_HELD_VELOCITY
from .external import hold
from .layout import QUAT, BlockLayout, U, V, W
from .physics import (
    add,
    cross,
    jit,
    quaternion_product,
    quaternion_rate,
    rotation,
    scale,
    sub,
    to_global,
    to_local,
)

#: Entries of a body's parameter row: net mass [kg] (minus the displaced
#: fluid), centre of mass (3) [m] (where the drag acts), drag coefficients
#: (6), and the net mass's first moment about the origin (3) [kg m] (where
#: the weight less buoyancy acts), body frame. The net mass and its moment
#: include what the body carries (the rods' base segments).
NET_MASS, CENTRE, DRAG, NET_MOMENT = 0, 1, 4, 10
N_BODY_PARAMS = 13
#: Fields of a free body's block in the state: the origin's position x [m] and the quaternion Q
#: (global), its velocity v [m/s] and angular velocity w [rad/s] (body frame); a fixed or driven
#: body's block holds the pose only (:data:`POSE_FIELDS`).
BODY_FIELDS = {"x": 3, "Q": 4, "v": 3, "w": 3}
POSE_FIELDS = {"x": 3, "Q": 4}
FREE_BODY = BlockLayout(1, BODY_FIELDS)
# Integer offsets for the compiled functions (numba freezes module-level ints).
BX, BQ, BV, BW = (FREE_BODY.slices()[f].start for f in BODY_FIELDS)


def pack_body(body, fluid_density):
    """The parameter row of ``body`` alone in a fluid of ``fluid_density`` [kg/m^3]."""
    row = np.empty(N_BODY_PARAMS)
    row[NET_MASS] = body.mass - fluid_density * body.volume
    row[CENTRE:CENTRE + 3] = body.centre_of_mass
    row[DRAG:DRAG + 6] = body.drag
    row[NET_MOMENT:NET_MOMENT + 3] = row[NET_MASS] * body.centre_of_mass
    return row


@jit
def _row3(a, i):
    return (a[i], a[i + 1], a[i + 2])


@jit
def clamp_wrench(stress, strains, shares, turns, points):
    """Total force and moment about the body origin [N, N m], body frame, of
    the rods clamped to a body: per rod, ``stress`` (6,) cell 0's total N, M
    and ``strains`` (6,) its q, k (local frame of the base), ``shares`` the
    base node's share of the cell [m] (``Scheme.base_share`` ds), ``turns``
    (9,) the base-to-body rotation (row-major), ``points`` (3,) the clamp [m]."""
    force, torque = (0.0, 0.0, 0.0), (0.0, 0.0, 0.0)
    for r in range(stress.shape[0]):
        n, m = _row3(stress[r], 0), _row3(stress[r], 3)
        q, k = _row3(strains[r], 0), _row3(strains[r], 3)
        h = shares[r]
        n_base = add(n, scale(h, cross(k, n)))
        m_base = add(m, scale(h, add(cross(k, m), cross(q, n))))
        f = to_global(turns[r], n_base)
        force = add(force, f)
        torque = add(torque, add(to_global(turns[r], m_base), cross(_row3(points[r], 0), f)))
    return force, torque


@jit
def free_body_rates(state, params, rigid, inverse, gravity, force, torque, smoothing2, restoring, out):
    """Rates of a free body's block (x, Q, v, w) into ``out`` (``FREE_BODY.size``,): ``state``
    its block, ``params`` its :func:`pack_body` row (with what it carries),
    ``rigid`` its 6x6 mass matrix without its own added mass (the carried
    rods' base segments with theirs, as their nodes) and ``inverse`` the
    inverse of the one with all added mass, ``gravity`` (3,) global, ``force``, ``torque`` the rods'
    wrench about the origin (body frame)."""
    quat = (state[BQ], state[BQ + 1], state[BQ + 2], state[BQ + 3])
    v, w = _row3(state, BV), _row3(state, BW)
    r = rotation(quat)
    c = _row3(params, CENTRE)
    g = to_local(r, gravity)
    weight = scale(params[NET_MASS], g)
    v_c = add(v, cross(w, c))
    drag = (-params[DRAG] * v_c[0] * np.sqrt(v_c[0] * v_c[0] + smoothing2),
            -params[DRAG + 1] * v_c[1] * np.sqrt(v_c[1] * v_c[1] + smoothing2),
            -params[DRAG + 2] * v_c[2] * np.sqrt(v_c[2] * v_c[2] + smoothing2))
    spin = (-params[DRAG + 3] * w[0] * np.sqrt(w[0] * w[0] + smoothing2),
            -params[DRAG + 4] * w[1] * np.sqrt(w[1] * w[1] + smoothing2),
            -params[DRAG + 5] * w[2] * np.sqrt(w[2] * w[2] + smoothing2))
    total_f = add(add(weight, drag), force)
    total_t = add(add(add(cross(c, drag), cross(_row3(params, NET_MOMENT), g)), spin), torque)
    vw = (v[0], v[1], v[2], w[0], w[1], w[2])
    p = np.zeros(6)
    for i in range(6):
        for j in range(6):
            p[i] += rigid[i, j] * vw[j]
    lin, ang = _row3(p, 0), _row3(p, 3)
    total_f = sub(total_f, cross(w, lin))
    total_t = sub(total_t, add(cross(w, ang), cross(v, lin)))
    rhs = (total_f[0], total_f[1], total_f[2], total_t[0], total_t[1], total_t[2])
    for i in range(6):
        acc = 0.0
        for j in range(6):
            acc += inverse[i, j] * rhs[j]
        out[BV + i] = acc
    x_t = to_global(r, v)
    q_t = quaternion_rate(quat, w, restoring)
    for i in range(3):
        out[BX + i] = x_t[i]
    for i in range(4):
        out[BQ + i] = q_t[i]


@jit
def joint_wrench(kind, row, value, y, node, body, point, turn):
    """A penalty joint between the rod node whose element block starts at
    ``y[node]`` and the point ``point`` [m] (body frame) of a body in the
    state ``body`` (x, Q, v, w: origin [m] and quaternion, global;
    velocities [m/s, rad/s], body frame), the section's held orientation
    ``turn`` (quaternion, section to body frame).

    Writes the held point's pose and motion into the hold's parameter
    ``row`` (orientation, velocity and angular velocity, global) and its
    displacement from the row's rest position into ``value`` (3,), where the
    rod's kernel reads them (:func:`rodmol.discretise.external.hold`), and
    returns the reaction on the body: the force and moment [N, N m] about
    its origin, body frame, equal and opposite to the node's, the force
    acting where the node is (so momentum and angular momentum are kept)."""
    held_by(row, value, body, point, turn)
    u = _row3(y, node + U)
    quat = (y[node + QUAT], y[node + QUAT + 1], y[node + QUAT + 2], y[node + QUAT + 3])
    r = rotation(quat)
    f, m = hold(kind, row, (value[0], value[1], value[2]), u, quat, r, _row3(y, node + V), _row3(y, node + W))
    return reaction(body, u, to_global(r, f), to_global(r, m))


@jit
def held_by(row, value, body, point, turn):
    """Write into a hold's parameter ``row`` and ``value`` the frame of a
    body in the state ``body`` (x, Q, v, w) at ``point`` [m] with axes
    ``turn`` (quaternion), body frame: its displacement from the row's
    rest position, its orientation, velocity and angular velocity, global."""
    x_b = _row3(body, BX)
    q_b = (body[BQ], body[BQ + 1], body[BQ + 2], body[BQ + 3])
    v_b, w_b = _row3(body, BV), _row3(body, BW)
    r_b = rotation(q_b)
    target = add(x_b, to_global(r_b, _row3(point, 0)))
    for i in range(3):
        value[i] = target[i] - row[i]
    held = quaternion_product(q_b, (turn[0], turn[1], turn[2], turn[3]))
    for i in range(4):
        row[3 + i] = held[i]
    velocity = to_global(r_b, add(v_b, cross(w_b, _row3(point, 0))))
    spin = to_global(r_b, w_b)
    for i in range(3):
        row[P_HELD_VELOCITY + i] = velocity[i]
        row[P_HELD_SPIN + i] = spin[i]


@jit
def reaction(body, u, force, moment):
    """The force and moment [N, N m] about the origin of a body in the state
    ``body``, body frame, opposite to ``force`` and ``moment`` (global) on
    what it holds, the force acting at ``u`` [m] (global)."""
    r_b = rotation((body[BQ], body[BQ + 1], body[BQ + 2], body[BQ + 3]))
    f = scale(-1.0, to_local(r_b, force))
    return f, add(scale(-1.0, to_local(r_b, moment)), cross(to_local(r_b, sub(u, _row3(body, BX))), f))
