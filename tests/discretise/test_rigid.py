"""The compiled rigid-body physics (rodmol.discretise.rigid) against Newton-Euler
written independently about the centre of mass, in the global frame."""

import numpy as np

import rodmol
from rodmol.discretise.rigid import clamp_wrench, free_body_rates, pack_body
from rodmol.discretise.rotations import from_matrix, matrices


def _skew(a):
    """[a]x: [a]x b = a x b."""
    return np.array([[0.0, -a[2], a[1]], [a[2], 0.0, -a[0]], [-a[1], a[0], 0.0]])


def _rotation(axis, angle):
    k = _skew(np.asarray(axis, dtype=float) / np.linalg.norm(axis))
    return np.eye(3) + np.sin(angle) * k + (1 - np.cos(angle)) * k @ k


def test_free_body_rates_about_the_origin_match_newton_euler_about_the_centre_of_mass():
    rng = np.random.default_rng(7)
    c = np.array([0.03, -0.02, 0.05])
    a = rng.standard_normal((3, 3))
    inertia = a @ a.T * 1e-3 + 1e-3 * np.eye(3)
    body = rodmol.RigidBody(1.7, inertia, volume=4e-4, centre_of_mass=c)
    r = _rotation([1.0, 2.0, -0.5], 0.8)
    x, v, w = np.array([0.1, 0.2, 0.3]), np.array([0.4, -0.3, 0.2]), np.array([1.5, -2.0, 0.7])
    gravity = np.array([0.0, 0.0, -9.81])
    force, torque = np.array([0.3, -0.1, 0.2]), np.array([0.01, 0.02, -0.03])  # about the origin, body frame
    state = np.concatenate([x, from_matrix(r), v, w])
    out = np.empty(13)
    free_body_rates(state, pack_body(body, 1000.0), body.mass_matrix, np.linalg.inv(body.mass_matrix), gravity,
                    tuple(force), tuple(torque), 0.0, 0.0, out)
    # Independent: global frame, about the centre of mass.
    m, w_g = body.mass, r @ w
    f_g = r @ force + (m - 1000.0 * 4e-4) * gravity
    torque_c = r @ (torque - np.cross(c, force))  # the rods' moment moved to the centre of mass
    inertia_g = r @ inertia @ r.T
    w_dot_g = np.linalg.solve(inertia_g, torque_c - np.cross(w_g, inertia_g @ w_g))
    a_c = f_g / m
    c_g = r @ c
    a_origin = a_c - np.cross(w_dot_g, c_g) - np.cross(w_g, np.cross(w_g, c_g))
    # The body-frame rates of (v, w): d/dt (R v) = R (v_t + w x v).
    np.testing.assert_allclose(out[7:10], r.T @ a_origin - np.cross(w, v), rtol=1e-10, atol=1e-12)
    np.testing.assert_allclose(out[10:13], r.T @ w_dot_g, rtol=1e-10, atol=1e-12)
    np.testing.assert_allclose(out[:3], r @ v, rtol=1e-12)
    # Q_t = Q (x) (0, w) / 2: the rotation's rate is R [w]x.
    q = state[3:7]
    dt = 1e-7
    r_next = matrices(q + dt * out[3:7])
    np.testing.assert_allclose((r_next - r) / dt, r @ _skew(w), atol=1e-5)


def test_clamp_wrench_adds_the_base_share_and_the_moment_arm():
    stress = np.array([[1.0, 2.0, -1.0, 0.1, -0.2, 0.3]])
    strains = np.array([[1.0, 0.0, 0.0, 0.0, 0.0, 2.0]])  # straight but curving about z
    turn = _rotation([0.0, 0.0, 1.0], 0.4)
    point = np.array([[0.05, 0.0, 0.01]])
    h = 0.01
    force, torque = clamp_wrench(stress, strains, np.array([h]), np.ascontiguousarray(turn.reshape(1, 9)), point)
    n, m, k, q = stress[0, :3], stress[0, 3:], strains[0, 3:], strains[0, :3]
    n_base = n + h * np.cross(k, n)
    m_base = m + h * (np.cross(k, m) + np.cross(q, n))
    np.testing.assert_allclose(force, turn @ n_base, rtol=1e-14)
    np.testing.assert_allclose(torque, turn @ m_base + np.cross(point[0], turn @ n_base), rtol=1e-14)
