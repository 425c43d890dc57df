"""Markers (surface points tracked like the paper's camera markers) and the
errors of eq. (15): e_t = |u(L) - u_4| / L, e_m = (e_t + sum_j |u(L_j) - u_j| / L) / 4.
"""

import math

import numpy as np
import pytest

import rodmol

L_ARM = 0.418  # m, Table I
ANCHORAGES = (0.098, 0.203, 0.311)  # m, L1-L3


def paper_radius(s):
    """Table I taper: 15 mm at the base to 4 mm at the tip, linear."""
    return 0.015 + (0.004 - 0.015) * s / L_ARM


@pytest.fixture(scope="module")
def moving():
    """The bending test for 1 s at N = 10: markers that move in time."""
    model = rodmol.scenarios.get("bending").model(10)
    result = rodmol.simulate(model, 1.0, output_dt=0.05)
    assert result.success
    return result


def test_markers_on_straight_arm_sit_on_the_surface():
    """No gravity, no tension: the arm stays straight along x; the default
    markers are on the +y surface, at (L_j, r(L_j), 0)."""
    model = rodmol.paper_arm(10, gravity=(0.0, 0.0, 0.0))
    result = rodmol.simulate(model, 0.1, output_dt=0.05)
    assert [m["name"] for m in result.meta["markers"]] == ["L1", "L2", "L3", "L"]
    s = np.array([*ANCHORAGES, L_ARM])
    expected = np.column_stack([s, paper_radius(s), np.zeros(4)])
    for frame in result.markers:
        np.testing.assert_allclose(frame, expected, atol=1e-12)


def test_markers_follow_a_circular_arc():
    """A uniform rod (r = 10 mm, L = 0.3 m) bent by a tip-anchored tendon at
    p_y = 5 mm, T = 1 N is a circle of radius rho = (1 + eps)/k_z about
    (0, rho) (eps = -T/EA, k_z = T p_y/(E J)); at arc angle phi = k_z s a +y
    surface marker is at the centre + (rho - r)(sin phi, -cos phi), a +z
    marker at the centreline + (0, 0, p_z)."""
    mat = rodmol.Material(E=110e3, nu=0.5, mu=300.0, rho=1080.0)
    L, r, T, py = 0.3, 0.01, 1.0, 0.005
    markers = (rodmol.Marker(0.1, name="a"), rodmol.Marker(0.2, name="b"),
               rodmol.Marker(0.3, offset=(0.0, 0.004), name="tip +z"))
    model = rodmol.Model(rodmol.Rod(L, r, mat), 30, gravity=(0.0, 0.0, 0.0), markers=markers,
                         cables=[rodmol.Cable((py, 0.0), L, T, name="tendon")])
    result = rodmol.simulate(model, 0.02, output_dt=0.01)
    eps = -T / (mat.E * math.pi * r**2)
    kz = T * py / (mat.E * math.pi * r**4 / 4)
    rho = (1 + eps) / kz
    centre = np.array([0.0, rho, 0.0])

    def on_arc(s, radius):
        phi = kz * s
        return centre + radius * np.array([math.sin(phi), -math.cos(phi), 0.0])

    expected = np.array([on_arc(0.1, rho - r), on_arc(0.2, rho - r),
                         on_arc(0.3, rho) + [0.0, 0.0, 0.004]])
    # The discrete arc is inscribed in a circle rho (1 + theta^2/24), theta = ds k_z.
    np.testing.assert_allclose(result.markers[-1], expected, atol=1e-4)


def test_errors_vanish_for_own_markers(moving):
    errors = rodmol.marker_errors(moving, moving.markers)
    np.testing.assert_array_equal(errors.t, moving.t)
    np.testing.assert_allclose(errors.tip, 0.0, atol=1e-15)
    np.testing.assert_allclose(errors.mean, 0.0, atol=1e-15)
    assert errors.tip_average == 0.0 and errors.mean_average == 0.0


def test_rigid_shift_gives_its_length_over_L(moving):
    """Every marker shifted by d: e_t = e_m = |d| / L = 0.013 / 0.418."""
    d = np.array([0.003, -0.004, 0.012])  # |d| = 13 mm
    errors = rodmol.marker_errors(moving, moving.markers + d)
    np.testing.assert_allclose(errors.tip, 0.013 / L_ARM, rtol=1e-12)
    np.testing.assert_allclose(errors.mean, 0.013 / L_ARM, rtol=1e-12)
    assert errors.tip_average == pytest.approx(0.0311005, rel=1e-5)  # 3.1 %


def test_mean_error_averages_the_four_markers(moving):
    """Marker j shifted by j mm along y: e_t = 4 mm / L, e_m = (1+2+3+4)/4 mm / L;
    a drift growing as a t on the tip only averages to a mean(t) / L."""
    shift = np.zeros((4, 3))
    shift[:, 1] = [0.001, 0.002, 0.003, 0.004]
    errors = rodmol.marker_errors(moving, moving.markers + shift)
    np.testing.assert_allclose(errors.tip, 0.004 / L_ARM, rtol=1e-12)
    np.testing.assert_allclose(errors.mean, 0.0025 / L_ARM, rtol=1e-12)

    a = 0.02  # m/s
    drift = np.zeros(moving.markers.shape)
    drift[:, 3, 2] = a * moving.t
    errors = rodmol.marker_errors(moving, moving.markers + drift)
    np.testing.assert_allclose(errors.tip, a * moving.t / L_ARM, rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(errors.mean, a * moving.t / (4 * L_ARM), rtol=1e-12, atol=1e-15)
    assert errors.tip_average == pytest.approx(a * 0.5 / L_ARM, rel=1e-12)  # mean of t on [0, 1]


def _interpolated(result, times):
    """Markers linearly interpolated to ``times`` (what a camera between frames sees)."""
    flat = result.markers.reshape(len(result.t), -1)
    cols = [np.interp(times, result.t, flat[:, i]) for i in range(flat.shape[1])]
    return np.column_stack(cols).reshape(len(times), *result.markers.shape[1:])


def test_measured_markers_from_csv(tmp_path, moving):
    """Camera rows between the output frames, in a CSV with a header: the
    simulation is interpolated to them, so a rigid shift still gives |d| / L."""
    times = np.arange(0.025, 1.0, 0.05)  # 20 rows, all between frames
    d = np.array([0.0, 0.005, 0.0])
    measured = _interpolated(moving, times) + d
    path = tmp_path / "camera.csv"
    header = "t [s]," + ",".join(f"{c}{j} [m]" for j in range(1, 5) for c in "xyz")
    rows = np.column_stack([times, measured.reshape(len(times), 12)])
    np.savetxt(path, rows, delimiter=",", header=header, comments="")
    errors = rodmol.marker_errors(moving, path)
    np.testing.assert_allclose(errors.t, times, rtol=1e-15)
    np.testing.assert_allclose(errors.tip, 0.005 / L_ARM, rtol=1e-9)
    np.testing.assert_allclose(errors.mean, 0.005 / L_ARM, rtol=1e-9)
    # Array input at the same times gives the same numbers.
    again = rodmol.marker_errors(moving, measured, times=times)
    np.testing.assert_allclose(again.mean, errors.mean, rtol=1e-12)


def test_bad_measured_markers_are_rejected(tmp_path, moving):
    with pytest.raises(rodmol.ParameterError, match="shape"):
        rodmol.marker_errors(moving, moving.markers[:, :3])
    late = np.array([0.5, 1.5])
    with pytest.raises(rodmol.ParameterError, match="outside"):
        rodmol.marker_errors(moving, _interpolated(moving, [0.5, 1.0]), times=late)
    path = tmp_path / "short.csv"
    np.savetxt(path, np.ones((3, 10)), delimiter=",")
    with pytest.raises(rodmol.ParameterError, match=f"{path}.*13 numeric columns"):
        rodmol.marker_errors(moving, path)
