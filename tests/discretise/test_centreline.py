"""Positions rebuilt from the strains (rodmol.discretise.centreline)."""

import numpy as np

from rodmol.discretise import centreline, rotations


def test_constant_curvature_gives_exact_circle_points():
    """Constant k = (0, 0, kappa), q = (1, 0, 0), orientations from exp(s k):
    each chord points along the exact chord of the arc and has the arc's
    length ds, so the nodes lie on the exact circle scaled by arc / chord
    (an O(ds^2) error)."""
    n, length, kappa = 16, 2.0, 1.3
    ds = length / n
    s = np.arange(n + 1) * ds
    quat = rotations.from_rotation_vector(np.outer(s, [0.0, 0.0, kappa]))
    q = np.tile([1.0, 0.0, 0.0], (n, 1))
    k = np.tile([0.0, 0.0, kappa], (n, 1))
    pos = centreline.positions(np.zeros(3), quat, q, k, ds)
    exact = np.stack([np.sin(kappa * s) / kappa, (1 - np.cos(kappa * s)) / kappa, 0 * s], axis=1)
    chord_factor = np.sin(kappa * ds / 2) / (kappa * ds / 2)  # chord / arc of one element
    np.testing.assert_allclose(pos, exact / chord_factor, atol=1e-14)


def test_stretch_scales_chords_and_base_pose_moves_everything():
    n, ds = 5, 0.1
    quat = np.tile([1.0, 0.0, 0.0, 0.0], (n + 1, 1))
    q = np.tile([1.1, 0.0, 0.0], (n, 1))
    pos = centreline.positions(np.array([1.0, 2.0, 3.0]), quat, q, np.zeros((n, 3)), ds)
    np.testing.assert_allclose(pos[:, 0], 1.0 + 1.1 * ds * np.arange(n + 1))
    np.testing.assert_allclose(pos[:, 1:], np.tile([2.0, 3.0], (n + 1, 1)))


def test_shear_strain_tilts_the_chord():
    quat = np.tile([1.0, 0.0, 0.0, 0.0], (2, 1))
    pos = centreline.positions(np.zeros(3), quat, np.array([[1.0, 0.2, -0.1]]), np.zeros((1, 3)), 0.5)
    np.testing.assert_allclose(pos[1], [0.5, 0.1, -0.05])
