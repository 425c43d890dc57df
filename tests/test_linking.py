"""Twist, writhe and link of a rod held at both ends (rodmol.analysis), each
against a case known without them."""

import numpy as np
import pytest

import rodmol
from rodmol import analysis


def framed(x, y):
    """Rotations (n, 3, 3) along the polyline ``x``: x axis its tangent, y axis ``y`` made normal to it."""
    t = np.gradient(x, axis=0)
    t /= np.linalg.norm(t, axis=1)[:, None]
    y = y - t * np.einsum("ni,ni->n", y, t)[:, None]
    y /= np.linalg.norm(y, axis=1)[:, None]
    return np.stack([t, y, np.cross(t, y)], axis=-1)


def twisted_straight(turns, n=200, length=1.0):
    s = np.linspace(0.0, length, n + 1)
    x = np.stack([0 * s, 0 * s, s], axis=1)
    angle = 2 * np.pi * turns * s / length
    return x, framed(x, np.stack([np.cos(angle), np.sin(angle), 0 * s], axis=1))


@pytest.mark.parametrize("turns", [-2.5, 0.0, 3.0, 10.0])
def test_a_straight_rod_twisted_uniformly_has_its_turns_as_twist_and_no_writhe(turns):
    lk, tw, wr = analysis.link(*twisted_straight(turns))
    assert tw == pytest.approx(turns, abs=1e-9)
    assert wr == pytest.approx(0.0, abs=1e-9)
    assert lk == pytest.approx(turns, abs=1e-9)


def test_a_planar_curve_has_no_writhe():
    s = np.linspace(0.0, 1.0, 301)
    x = np.stack([s, 0.3 * np.sin(3 * np.pi * s) + 0.2 * s**2, 0 * s], axis=1)  # an S in the xy plane
    rotations = framed(x, np.tile([0.0, 0.0, 1.0], (len(s), 1)))
    assert analysis.writhe(x, rotations) == pytest.approx(0.0, abs=1e-9)
    assert analysis.twist(x, rotations) == pytest.approx(0.0, abs=1e-9)  # the plane's normal: no twist


@pytest.mark.parametrize("turns, pitch", [(5, 0.05), (3, 0.01), (4, -0.03)])
def test_a_helix_has_fullers_writhe(turns, pitch):
    """A helix of ``turns`` between ends held along its axis: Fuller's
    writhe against the straight axis, turns (1 - cos alpha), alpha the
    tangent's angle to the axis (negative for a left-handed helix)."""
    a = 0.1
    phi = np.linspace(0.0, 2 * np.pi * turns, 1200)
    x = np.stack([a * np.cos(phi), a * np.sin(phi), pitch * phi], axis=1)
    rotations = framed(x, np.stack([np.cos(phi), np.sin(phi), 0 * phi], axis=1))
    along = np.sign(pitch)
    rotations[[0, -1]] = np.array([[0, 1, 0], [0, 0, along], [along, 0, 0]], dtype=float)  # held along the axis
    alpha = np.arctan2(a, abs(pitch))
    assert analysis.writhe(x, rotations) == pytest.approx(np.sign(pitch) * turns * (1 - np.cos(alpha)), rel=2e-3)


def coiled(x, rotations, coils, radius=0.1, length=1.0, h=1e-6):
    """``x``, ``rotations`` carried by a smooth map of space that leaves the
    ends in place: each plane z = const shifted (not turned) by radius (cos
    theta - 1, sin theta, 0), theta = 2 pi coils times a smooth step in z over
    the middle 60% of the rod, so that it coils ``coils`` times (a
    diffeomorphism, the identity beyond that stretch)."""
    def step(z):
        w = np.clip((z / length - 0.2) / 0.6, 0.0, 1.0)
        return w * w * w * (10 - 15 * w + 6 * w * w)

    def carry(p):
        theta = 2 * np.pi * coils * step(p[:, 2])
        return p + radius * np.stack([np.cos(theta) - 1, np.sin(theta), 0 * theta], axis=1)

    y = rotations[:, :, 1]
    moved_y = (carry(x + h * y) - carry(x - h * y)) / (2 * h)  # the map's Jacobian carries each y axis
    moved = carry(x)
    out = framed(moved, moved_y)
    out[[0, -1]] = rotations[[0, -1]]
    return moved, out


@pytest.mark.parametrize("coils", [0.5, 1.0, 3.0])
def test_the_link_is_unchanged_by_a_smooth_deformation_that_keeps_the_ends(coils):
    x, rotations = twisted_straight(4.0, n=600)
    lk, tw, wr = analysis.link(*coiled(x, rotations, coils))
    assert wr > 0.1 * coils  # the twist turned into writhe
    assert lk == pytest.approx(4.0, abs=1e-4)  # while Tw and Wr trade up to 2.2 turns


def test_the_link_of_a_result_is_one_per_frame():
    x, rotations = twisted_straight(2.0, n=50)
    frames = type("R", (), dict(positions=np.stack([x, x]), rotations=np.stack([rotations, rotations])))()
    lk, tw, wr = analysis.result_link(frames)
    assert np.allclose(lk, 2.0) and lk.shape == (2,)


def test_bad_shapes_are_refused_naming_them():
    x, rotations = twisted_straight(1.0, n=10)
    with pytest.raises(rodmol.errors.ParameterError, match="rotations"):
        analysis.link(x, rotations[:-1])
    with pytest.raises(rodmol.errors.ParameterError, match="positions"):
        analysis.twist(x[:, :2], rotations)
    with pytest.raises(rodmol.errors.ParameterError, match="finite"):
        analysis.writhe(x * np.nan, rotations)
