"""The compiled joint between two bodies (rodmol.discretise.body_joints):
the Hold law between two body points, equal and opposite, and its default
law; a pinned base needs a scheme that leaves its base segment to it."""

import numpy as np
import pytest
from newton_check import NewtonCheck

import rodmol
from rodmol.discretise.assembly import Assembly
from rodmol.discretise.body_joints import joint_frequency, pair_wrench
from rodmol.discretise.rotations import from_matrix, from_rotation_vector, matrices
from rodmol.loads import KERNELS, N_PARAMS, P_DAMPING, P_STIFFNESS, P_TURN_DAMPING, P_TURN_STIFFNESS


def _state(rng):
    """A body state (x, Q, v, w) with a random pose and motion."""
    quat = from_rotation_vector(rng.standard_normal(3))
    return np.concatenate([rng.standard_normal(3), quat, rng.standard_normal(3), rng.standard_normal(3)])


def _law(k=2e3, c=3.0, k_r=5.0, c_r=0.1):
    row = np.zeros(N_PARAMS)
    row[[P_STIFFNESS, P_DAMPING, P_TURN_STIFFNESS, P_TURN_DAMPING]] = k, c, k_r, c_r
    return row


@pytest.mark.parametrize("kind", ["pin", "clamp"])
def test_the_two_bodies_feel_equal_and_opposite_wrenches_that_keep_momentum_and_angular_momentum(kind):
    rng = np.random.default_rng(3)
    a, b = _state(rng), _state(rng)
    point_a, point_b = rng.standard_normal(3), rng.standard_normal(3)
    turn_a, turn_b = from_rotation_vector(rng.standard_normal(3)), from_rotation_vector(rng.standard_normal(3))
    (f_a, m_a), (f_b, m_b) = pair_wrench(KERNELS[kind].code, _law(), np.zeros(3), a, point_a, turn_a, b,
                                         point_b, turn_b)
    r_a, r_b = matrices(a[3:7]), matrices(b[3:7])
    force_a, force_b = r_a @ np.asarray(f_a), r_b @ np.asarray(f_b)
    np.testing.assert_allclose(force_a + force_b, 0.0, atol=1e-12 * np.linalg.norm(force_a))
    # Moments about the global origin: each body's about its origin plus its origin's arm.
    moment_a = r_a @ np.asarray(m_a) + np.cross(a[:3], force_a)
    moment_b = r_b @ np.asarray(m_b) + np.cross(b[:3], force_b)
    np.testing.assert_allclose(moment_a + moment_b, 0.0, atol=1e-12 * np.linalg.norm(moment_a))
    # The force is the law's: stiffness times the gap between the points, plus damping of their
    # relative velocity (global).
    u_a, u_b = a[:3] + r_a @ point_a, b[:3] + r_b @ point_b
    v_a = r_a @ (a[7:10] + np.cross(a[10:], point_a))
    v_b = r_b @ (b[7:10] + np.cross(b[10:], point_b))
    np.testing.assert_allclose(force_a, -2e3 * (u_a - u_b) - 3.0 * (v_a - v_b), rtol=1e-12)
    if kind == "pin":  # a ball joint: no moment about the joint point
        np.testing.assert_allclose(r_a @ np.asarray(m_a), np.cross(u_a - a[:3], force_a), atol=1e-12)


def test_bodies_whose_joint_frames_meet_feel_nothing():
    rng = np.random.default_rng(5)
    a = _state(rng)
    a[7:] = 0.0
    r_a = matrices(a[3:7])
    point_a, turn_a = np.array([0.1, -0.2, 0.3]), from_rotation_vector([0.2, 0.1, -0.3])
    b = np.concatenate([a[:3] + r_a @ point_a, from_matrix(r_a @ matrices(turn_a)), np.zeros(6)])
    (f_a, m_a), (f_b, m_b) = pair_wrench(KERNELS["clamp"].code, _law(), np.zeros(3), a, point_a, turn_a, b,
                                         np.zeros(3), np.array([1.0, 0.0, 0.0, 0.0]))
    np.testing.assert_allclose(np.r_[f_a, m_a, f_b, m_b], 0.0, atol=1e-9)


_turn = matrices(from_rotation_vector([0.3, -0.2, 0.5]))


def _arm(n=4):
    material = rodmol.Material(E=2e5, nu=0.5, mu=100.0, rho=1100.0)
    return rodmol.Model(rodmol.Rod(0.2, radius=0.01, material=material), n)


def test_the_default_law_puts_the_fastest_joint_mode_at_a_held_rod_nodes_frequency_and_damps_every_mode():
    heavy = rodmol.RigidBody(2.0, (1e-3, 2e-3, 3e-3), centre_of_mass=(0.05, 0.0, 0.0))
    light = rodmol.RigidBody(0.5, (1e-4, 1e-4, 2e-4), position=(0.1, 0.0, 0.0), rotation=_turn)
    omega2 = 100.0 * 2e5 / (1100.0 * 0.05**2)  # HOLD_STIFFNESS_FACTOR E / (rho ds^2)
    assert joint_frequency([_arm()]) ** 2 == pytest.approx(omega2, rel=1e-12)
    for kind, size in (("clamp", 6), ("pin", 3)):
        system = rodmol.System({"arm": _arm()}, {"heavy": heavy, "light": light},
                               [rodmol.Joint(("heavy", (0.1, 0.0, 0.0)), ("light", (0.0, 0.0, 0.0)), kind)])
        assembly = Assembly(system)
        (joint,) = assembly.body_joints
        k, c, k_r, c_r = joint.row[[P_STIFFNESS, P_DAMPING, P_TURN_STIFFNESS, P_TURN_DAMPING]]
        # Independently: the relative motion's mass matrix at the joint, both bodies in the global frame.
        mass = np.zeros((6, 6))
        for part, point in ((assembly.bodies["heavy"], (0.1, 0.0, 0.0)), (assembly.bodies["light"], (0.0, 0.0, 0.0))):
            r = part.body.rotation
            arm = r @ np.asarray(point)
            shift = np.eye(6)
            shift[:3, 3:] = np.array([[0.0, -arm[2], arm[1]], [arm[2], 0.0, -arm[0]], [-arm[1], arm[0], 0.0]])  # v_o = v_p + arm x w
            frame = np.kron(np.eye(2), r)
            about_point = shift.T @ frame @ part.mass_matrix @ frame.T @ shift  # (v, w) of the point, global
            mass += np.linalg.inv(about_point)
        mass = np.linalg.inv(mass[:size, :size]) if size == 3 else np.linalg.inv(mass)
        stiffness = np.diag([k] * 3 + [k_r] * 3)[:size, :size]
        damping = np.diag([c] * 3 + [c_r] * 3)[:size, :size]
        # The modes of M x'' + C x' + K x = 0: the fastest at omega (the translation's or the turning's
        # block alone), every one damped at least critically (real eigenvalues), the slowest critically.
        system_matrix = np.block([[np.zeros((size, size)), np.eye(size)],
                                  [-np.linalg.solve(mass, stiffness), -np.linalg.solve(mass, damping)]])
        rates = np.linalg.eigvals(system_matrix)
        assert np.max(np.abs(rates.imag)) < 1e-4 * np.max(np.abs(rates))
        frequencies = np.sqrt(np.linalg.eigvals(np.linalg.solve(mass, stiffness)).real)
        assert 0.99 < np.max(frequencies) / np.sqrt(omega2) < 2.0
        assert c / k == pytest.approx(2.0 / np.min(frequencies), rel=1e-6)
        assert (k_r == 0.0) == (kind == "pin")


def test_a_pinned_base_carries_its_rods_base_segment_and_needs_the_centred_scheme():
    system = rodmol.System({"arm": _arm()}, joints=[rodmol.Joint(("arm", "base"), "world", "pin")])
    part = Assembly(system).bodies["arm.base"]
    segment = 1100.0 * np.pi * 0.01**2 * 0.05 / 2  # rho A ds / 2, the base node's half cell
    np.testing.assert_allclose(np.diag(part.mass_matrix)[:3], segment, rtol=1e-12)
    with pytest.raises(rodmol.NotSupportedYet, match="centred"):
        Assembly(system, "upwind")


def _joined_bodies():
    """A rod pinned at its base to the world, its tip clamped to a free bar; the bar pinned to a free
    weight, the weight clamped to a fixed post; a free ball clamped to the world."""
    rod = _arm().replace(gravity=(0.0, -9.81, 0.0))
    bar = rodmol.RigidBody(0.02, (1e-5, 2e-5, 3e-5), position=(0.2, 0.0, 0.0), centre_of_mass=(0.0, 0.01, 0.0))
    weight = rodmol.RigidBody(0.05, (2e-5, 2e-5, 2e-5), position=(0.2, 0.05, 0.0), rotation=_turn)
    post = rodmol.RigidBody(1.0, (1e-3, 1e-3, 1e-3), motion="fixed", position=(0.2, 0.1, 0.0))
    ball = rodmol.RigidBody(0.01, (1e-6, 1e-6, 1e-6), position=(0.0, 0.3, 0.0), centre_of_mass=(0.0, -0.01, 0.0))
    joints = [rodmol.Joint("world", ("arm", "base"), "pin"),
              rodmol.Joint(("bar", (0.0, 0.0, 0.0)), ("arm", "tip")),
              rodmol.Joint(("bar", (0.0, 0.05, 0.0)), ("weight", (0.0, 0.0, 0.0)), "pin"),
              rodmol.Joint(("weight", _turn.T @ (0.0, 0.05, 0.0)), ("post", (0.0, 0.0, 0.0))),
              rodmol.Joint(("ball", (0.0, 0.0, 0.0)), "world")]
    return Assembly(rodmol.System({"arm": rod}, {"bar": bar, "weight": weight, "post": post, "ball": ball},
                                  joints, gravity=(0.0, -9.81, 0.0)))


def test_the_pattern_holds_every_nonzero_the_body_joints_make():
    assembly = _joined_bodies()
    scale = assembly.atol_scale()
    y = assembly.undeformed_state() + 1e-2 * np.random.default_rng(3).standard_normal(assembly.size) * scale
    f0 = assembly(0.0, y).copy()
    pattern = assembly.pattern().toarray()
    touched = np.zeros_like(pattern)
    for j in range(assembly.size):
        z = y.copy()
        z[j] += 1e-6 * scale[j]
        touched[:, j] = assembly(0.0, z) != f0
    assert not np.argwhere(touched & ~pattern).size
    bar, weight, ball = (assembly.bodies[name].slice for name in ("bar", "weight", "ball"))
    assert touched[weight, bar].any() and touched[bar, weight].any()  # the pin between two free bodies
    assert touched[ball, ball][7:, :3].any()  # the ball's clamp to the world reads its position


def test_the_schur_preconditioner_inverts_the_newton_matrix_with_body_joints_and_a_pinned_base():
    # Every coupling of the free bodies is kept (the joints between them, the pinned base's body with its
    # rod's first cell, the bar with its rod joint): the preconditioner is the Newton matrix itself, to
    # the error of its forward differences; without the bodies' couplings it is far off.
    check, gamma = NewtonCheck(_joined_bodies()), 1e-4
    precond = check.preconditioner(gamma)
    assert [p.name for p in precond.coupled] == ["bar", "weight", "arm.base"]
    v = np.random.default_rng(6).standard_normal(check.assembly.size) * check.scale
    # The fixed post's pose has no correction (its rates read nothing else and are zero at its pose), so
    # the weight's rows against it, left out of the weight's block, never act.
    v[check.assembly.bodies["post"].slice] = 0.0
    r = check.newton(gamma) @ v
    error = check.error(check.solve(precond, r, gamma), v)
    assert error < 2e-4
    assert check.error(check.apart(precond, r, gamma), v) > 100 * error
