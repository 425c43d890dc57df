"""Unit quaternions and rotation matrices (rodmol.discretise.rotations)."""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from rodmol.discretise import physics, rotations


@pytest.fixture
def quats():
    q = np.random.default_rng(0).normal(size=(20, 4))
    return q / np.linalg.norm(q, axis=1, keepdims=True)


def test_matrices_match_scipy(quats):
    scipy_r = Rotation.from_quat(quats[:, [1, 2, 3, 0]]).as_matrix()  # scipy: scalar last
    np.testing.assert_allclose(rotations.matrices(quats), scipy_r, atol=1e-14)


def test_matrices_of_unnormalised_quaternions_are_orthogonal(quats):
    r = rotations.matrices(3.7 * quats)
    np.testing.assert_allclose(r @ np.swapaxes(r, -1, -2), np.broadcast_to(np.eye(3), r.shape),
                               atol=1e-14)


def test_multiply_composes_rotations(quats):
    p, q = quats[:10], quats[10:]
    np.testing.assert_allclose(rotations.matrices(rotations.multiply(p, q)),
                               rotations.matrices(p) @ rotations.matrices(q), atol=1e-14)


def test_rotation_vector_matches_scipy_and_small_angles():
    theta = np.random.default_rng(1).normal(size=(10, 3))
    theta[0] = 1e-10  # below the series switch
    ours = rotations.matrices(rotations.from_rotation_vector(theta))
    np.testing.assert_allclose(ours, Rotation.from_rotvec(theta).as_matrix(), atol=1e-14)


def test_from_matrix_round_trip(quats):
    for q in quats:
        back = rotations.from_matrix(rotations.matrices(q))
        np.testing.assert_allclose(back, q if q[0] >= 0 else -q, atol=1e-13)


def test_rate_is_the_body_frame_angular_velocity(quats):
    """R_t = R [w]x: differentiate R along Q_t numerically."""
    w = np.array([0.3, -1.2, 0.7])
    h = 1e-7
    for q in quats[:5]:
        q_t = np.array(physics.quaternion_rate(tuple(q), tuple(w), 0.0))  # the kernel's, unit |Q|: no restoring
        dr = (rotations.matrices(q + h * q_t) - rotations.matrices(q - h * q_t)) / (2 * h)
        skew = np.array([[0, -w[2], w[1]], [w[2], 0, -w[0]], [-w[1], w[0], 0]])
        np.testing.assert_allclose(dr, rotations.matrices(q) @ skew, atol=1e-7)


def test_rotate_applies_the_rotations_to_strided_vectors_in_place(quats):
    # The frames' rotations of nodes 1..4 applied to a strided slice, written into a slice of a
    # larger array: what the loads in the global frame need, without copies.
    matrices = rotations.matrices(quats).reshape(4, 5, 3, 3)
    vectors = np.random.default_rng(1).normal(size=(4, 5, 6))
    out = np.zeros((4, 5, 3))
    got = rotations.rotate(matrices[:, 1:], vectors[:, 1:, 3:], out[:, 1:])
    scipy_r = Rotation.from_quat(quats[:, [1, 2, 3, 0]]).apply(vectors[..., 3:].reshape(20, 3)).reshape(4, 5, 3)
    np.testing.assert_allclose(out[:, 1:], scipy_r[:, 1:], atol=1e-14)
    assert np.shares_memory(got, out) and not out[:, 0].any()
