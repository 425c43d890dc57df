"""DLT calibration (eq. 14) and triangulation on synthetic cameras with known parameters."""

import numpy as np
import pytest

from rodmol import ParameterError
from rodmol.calibrate import Camera, calibrate_dlt, reprojection_errors, synthetic, triangulate

CAMERAS = synthetic.cameras()
CONTROL = synthetic.control_points()


def workspace_points(n, seed=0):
    """Points spread over the arm's workspace [m], global."""
    return np.random.default_rng(seed).uniform((0.05, -0.3, -0.25), (0.42, 0.3, 0.05), (n, 3))


def test_pinhole_camera_projects_as_a_pinhole():
    """The synthetic front camera looks along -z from z = 1.2 m with f = 1300 px:
    a point at depth d off the axis by (dx, dy) lands at centre + f (dx, -dy) / d."""
    front = CAMERAS[0]
    uv = front.project(np.array([0.22 + 0.1, 0.05, 0.2]))
    assert uv == pytest.approx([620 + 1300 * 0.1 / 1.0, 500 - 1300 * 0.05 / 1.0])


def test_calibration_recovers_the_parameters_without_noise():
    for true in CAMERAS:
        cam = calibrate_dlt(CONTROL, true.project(CONTROL))
        assert np.allclose(cam.H, true.H, rtol=1e-8, atol=1e-10 * np.abs(true.H).max())
        assert cam.rms < 1e-8


def test_six_points_suffice_and_five_do_not():
    true = CAMERAS[0]
    cam = calibrate_dlt(CONTROL[:6], true.project(CONTROL[:6]))
    pts = workspace_points(50)
    assert np.max(np.abs(cam.project(pts) - true.project(pts))) < 1e-6
    with pytest.raises(ParameterError, match="at least 6 control points"):
        calibrate_dlt(CONTROL[:5], true.project(CONTROL[:5]))


def test_coplanar_control_points_are_refused():
    flat = CONTROL.copy()
    flat[:, 2] = 0.0
    with pytest.raises(ParameterError, match="coplanar"):
        calibrate_dlt(flat, CAMERAS[0].project(flat))


@pytest.mark.parametrize("noise", [0.5, 2.0])
def test_reprojection_error_is_at_the_noise_level(noise):
    """Least squares with 16 equations for 11 unknowns leaves residuals of about
    noise * sqrt((16 - 11) / 16) per coordinate; and the calibrated camera maps
    new workspace points within a few noise levels of the true projection."""
    rng = np.random.default_rng(1)
    residuals, transfer = [], []
    for _ in range(40):
        true = CAMERAS[0]
        cam = calibrate_dlt(CONTROL, true.project(CONTROL) + noise * rng.standard_normal((8, 2)))
        residuals.append(cam.errors)
        transfer.append(np.linalg.norm(cam.project(workspace_points(100)) - true.project(workspace_points(100)),
                                       axis=1))
    per_coordinate = np.sqrt(np.mean(np.concatenate(residuals) ** 2) / 2)
    assert per_coordinate == pytest.approx(noise * np.sqrt(5 / 16), rel=0.2)
    assert np.sqrt(np.mean(np.concatenate(transfer) ** 2)) < 2.0 * noise


def test_triangulation_is_exact_without_noise():
    pts = workspace_points(300).reshape(100, 3, 3)
    xyz = triangulate(CAMERAS, [c.project(pts) for c in CAMERAS])
    assert np.max(np.abs(xyz - pts)) < 1e-12
    assert np.max(reprojection_errors(CAMERAS, [c.project(pts) for c in CAMERAS], xyz)) < 1e-9


def test_triangulation_error_shrinks_with_the_pixel_noise():
    """Linear in the noise: a quarter of the noise gives a quarter of the error."""
    pts = workspace_points(4000, seed=2)
    rng = np.random.default_rng(3)
    errors = []
    for noise in (4.0, 1.0, 0.25):
        uvs = [c.project(pts) + noise * rng.standard_normal(pts.shape[:1] + (2,)) for c in CAMERAS]
        errors.append(np.sqrt(np.mean(np.sum((triangulate(CAMERAS, uvs) - pts) ** 2, axis=1))))
    assert errors[0] > errors[1] > errors[2]
    assert errors[0] / errors[1] == pytest.approx(4.0, rel=0.1)
    assert errors[1] / errors[2] == pytest.approx(4.0, rel=0.1)
    # A pixel is 1.2 m / 1300 = 0.92 mm at the arm; x is seen by both cameras, y and z
    # by one each: sqrt(0.92^2 / 2 + 2 * 0.92^2) = 1.4 mm at 1 px (more for far points).
    assert 1.2e-3 < errors[1] < 1.8e-3


def test_occluded_samples_give_nan_only_where_fewer_than_two_cameras_see():
    third = Camera.looking_at((1.2, 0.3, 0.8), (0.22, 0.0, 0.0), name="side")
    cams = list(CAMERAS) + [third]
    pts = workspace_points(30)
    uvs = [c.project(pts) for c in cams]
    uvs[0][:10] = np.nan  # front camera misses 0-9: two cameras left
    uvs[1][5:15] = np.nan  # top camera misses 5-14: samples 5-9 seen by one camera only
    xyz = triangulate(cams, uvs)
    assert np.all(np.isnan(xyz[5:10]))
    ok = np.r_[0:5, 10:30]
    assert np.max(np.abs(xyz[ok] - pts[ok])) < 1e-12


def test_one_camera_is_not_enough():
    with pytest.raises(ParameterError, match="two or more cameras"):
        triangulate(CAMERAS[:1], [CAMERAS[0].project(CONTROL)])


def test_camera_centre_is_where_it_was_put():
    assert CAMERAS[0].centre == pytest.approx([0.22, 0.0, 1.2], abs=1e-12)
    assert CAMERAS[1].centre == pytest.approx([0.22, 1.2, 0.0], abs=1e-12)


def test_identical_cameras_are_degenerate():
    pts = workspace_points(5)
    twin = Camera(CAMERAS[0].H.copy(), name="twin")
    with pytest.raises(ParameterError, match=r"cameras are degenerate: 'front', 'twin' all have their centre "
                                             r"at \(0.22, 0.0, 1.2\) m"):
        triangulate([CAMERAS[0], twin], [CAMERAS[0].project(pts)] * 2)
    # The same centre, turned to look elsewhere: still one position, still refused.
    turned = Camera.looking_at((0.22, 0.0, 1.2), (0.3, 0.1, 0.0), name="turned")
    with pytest.raises(ParameterError, match="cameras are degenerate"):
        triangulate([CAMERAS[0], turned], [CAMERAS[0].project(pts), turned.project(pts)])


def test_a_point_on_the_cameras_baseline_gives_nan_not_an_error():
    """The rays of both cameras through a point on the line joining their centres coincide."""
    front, top = CAMERAS
    on_baseline = 0.5 * (front.centre + top.centre)
    pts = np.vstack([on_baseline, workspace_points(3)])
    xyz = triangulate(CAMERAS, [front.project(pts), top.project(pts)])
    assert np.all(np.isnan(xyz[0]))
    assert np.max(np.abs(xyz[1:] - pts[1:])) < 1e-10
