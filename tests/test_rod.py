"""The rod's sectional laws and the material (rodmol.rod, rodmol.parameters)."""

import numpy as np
import pytest

import rodmol


def test_sectional_stiffness_and_viscosity_of_a_circle():
    mat = rodmol.Material(E=2e6, nu=0.25, mu=10.0, rho=1000.0)
    rod = rodmol.Rod(1.0, 0.02, mat)
    a, j = np.pi * 0.02**2, np.pi * 0.02**4 / 4
    g = 2e6 / 2.5
    kl, kth = rod.stiffness(np.array([0.3]))
    vl, vth = rod.viscosity(np.array([0.3]))
    np.testing.assert_allclose(kl[0], [2e6 * a, g * a, g * a])
    np.testing.assert_allclose(kth[0], [g * 2 * j, 2e6 * j, 2e6 * j])
    np.testing.assert_allclose(vl[0], [30 * a, 10 * a, 10 * a])
    np.testing.assert_allclose(vth[0], [20 * j, 30 * j, 30 * j])


def test_taper_and_volume():
    rod = rodmol.Rod(2.0, (0.3, 0.1), rodmol.Material(E=1.0, nu=0.0, rho=2.0))
    np.testing.assert_allclose(rod.radius_at([0.0, 1.0, 2.0]), [0.3, 0.2, 0.1])
    exact = np.pi * 2.0 * (0.3**2 + 0.3 * 0.1 + 0.1**2) / 3  # frustum
    assert rod.volume() == pytest.approx(exact, rel=1e-12)
    assert rod.mass() == pytest.approx(2.0 * exact, rel=1e-12)


def test_radius_points_as_in_a_scenario_file():
    """Rod(radius=[(s, r), ...]) (a scenario file's points) is the rod of their linear interpolant."""
    mat = rodmol.Material(E=1e5, nu=0.5, rho=1000.0)
    points = [(0.0, 0.012), (0.1, 0.01), (0.3, 0.005)]
    rod = rodmol.Rod(0.3, points, mat)
    profile = rodmol.Rod(0.3, lambda s: np.interp(s, (0.0, 0.1, 0.3), (0.012, 0.01, 0.005)), mat)
    s = np.linspace(0.0, 0.3, 31)
    np.testing.assert_array_equal(rod.radius_at(s), profile.radius_at(s))
    np.testing.assert_allclose(rod.radius_at([0.05, 0.2]), [0.011, 0.0075])
    # two points are a linear taper, the same as a (base, tip) pair
    np.testing.assert_allclose(rodmol.Rod(0.3, [(0.0, 0.012), (0.3, 0.005)], mat).radius_at(s),
                               rodmol.Rod(0.3, (0.012, 0.005), mat).radius_at(s))
    for bad, says in (([(0.0, 0.01), (0.2, 0.005)], "span s = 0 to the length 0.3"),
                      ([(0.0, 0.01), (0.2, 0.01), (0.1, 0.01), (0.3, 0.01)], "increasing s"),
                      ([(0.0, 0.01), (0.3, -0.005)], "finite and > 0")):
        with pytest.raises(rodmol.ParameterError, match=says):
            rodmol.Rod(0.3, bad, mat)


def test_shear_modulus_instead_of_poisson_ratio():
    mat = rodmol.Material(E=1e6, G=1e4, rho=5000.0)
    assert mat.G == 1e4 and mat.nu == pytest.approx(49.0)
    kl, _ = rodmol.Rod(3.0, 0.25, mat).stiffness(np.array([0.0]))
    assert kl[0, 1] == pytest.approx(1e4 * np.pi * 0.25**2)
    shear = rodmol.Material(E=1e6, nu=0.5, rho=1.0).G
    assert shear == pytest.approx(1e6 / 3)


@pytest.mark.parametrize("kwargs, words", [
    (dict(E=1e6, rho=1.0), "missing `nu`"),
    (dict(E=1e6, nu=0.3, G=1e5, rho=1.0), "not both"),
    (dict(E=1e6, G=-1.0, rho=1.0), "`G` must be > 0"),
    (dict(E=True, nu=0.3, rho=1.0), "`E` must be a number, got True"),
    (dict(E=1e6, nu=0.3), "`rho`"),
])
def test_bad_material_names_the_parameter(kwargs, words):
    with pytest.raises(rodmol.ParameterError, match=words):
        rodmol.Material(**kwargs)


def test_model_arrays_are_read_only():
    """The compiled system copies the sampled coefficients once: changing them
    afterwards would make it stale, so they cannot be changed."""
    model = rodmol.paper_arm(6)
    sampled = rodmol.SemiDiscrete(model).sampled
    for array in (sampled.kth, sampled.kl, sampled.mass, sampled.cable_weights, model.s_nodes):
        with pytest.raises(ValueError, match="read-only"):
            array[:] *= 2.0


def test_rest_strains_given_as_constant_points_or_callable():
    """The three forms of a rest strain sample alike (points linear between them), the
    default is the straight rod, and bad input is refused naming the parameter."""
    mat = rodmol.Material(E=1e5, nu=0.5, rho=1000.0)
    s = np.linspace(0.0, 0.3, 13)
    straight = rodmol.Rod(0.3, 0.01, mat)
    assert straight.straight
    q, k = straight.rest_strains_at(s)
    np.testing.assert_array_equal(q, np.tile([1.0, 0.0, 0.0], (13, 1)))
    np.testing.assert_array_equal(k, np.zeros((13, 3)))
    points = rodmol.Rod(0.3, 0.01, mat, rest_curvature=[(0.0, 1.0, 0.0, 2.0), (0.3, 1.0, 3.0, -1.0)],
                        rest_stretch=[(0.0, 1.1, 0.0, 0.0), (0.1, 0.9, 0.0, 0.0), (0.3, 1.0, 0.05, 0.0)])
    function = rodmol.Rod(0.3, 0.01, mat, rest_curvature=lambda s: np.stack([1 + 0 * s, 10 * s, 2 - 10 * s], -1),
                          rest_stretch=lambda s: np.stack([np.interp(s, [0, 0.1, 0.3], [1.1, 0.9, 1.0]),
                                                           np.interp(s, [0, 0.1, 0.3], [0, 0, 0.05]), 0 * s], -1))
    assert not points.straight and not function.straight
    for a, b in zip(points.rest_strains_at(s), function.rest_strains_at(s)):
        np.testing.assert_allclose(a, b, atol=1e-15)
    constant = rodmol.Rod(0.3, 0.01, mat, rest_curvature=[0, 0, 5])
    assert constant.rest_curvature == (0.0, 0.0, 5.0)
    np.testing.assert_array_equal(constant.rest_strains_at(s)[1], np.tile([0.0, 0.0, 5.0], (13, 1)))
    for kwargs, says in ((dict(rest_curvature=(1.0, 2.0)), "`rest_curvature` must be a 3-vector"),
                         (dict(rest_stretch="straight"), "`rest_stretch` must be a 3-vector"),
                         (dict(rest_curvature=(0.0, np.nan, 1.0)), "`rest_curvature` must be finite"),
                         (dict(rest_stretch=(-1.0, 0.0, 0.0)), r"`rest_stretch` must have q\*_x > 0"),
                         (dict(rest_curvature=[(0.0, 0, 0, 1), (0.2, 0, 0, 1)]), "span s = 0 to the length"),
                         (dict(rest_curvature=lambda s: s), "`rest_curvature` callable failed")):
        with pytest.raises(rodmol.ParameterError, match=says):
            rodmol.Rod(0.3, 0.01, mat, **kwargs)
