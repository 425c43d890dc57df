"""Kelvin-Voigt viscosity per strain component (``Material(viscosity=...)``):
with no extension-shear damping (Bse = 0) the axial mode rings undamped while
the bending mode decays at the Kelvin-Voigt rate of the bending viscosity."""

import numpy as np
import pytest
from vibration import measure_free_vibration

import rodmol
from rodmol.discretise.rod_scales import grid_damping_ratio
from rodmol.discretise.sampling import Sampled
from rodmol.discretise.system import SemiDiscrete

L, RADIUS, E, RHO = 0.3, 0.01, 1e5, 1000.0  # m, m, Pa, kg/m^3
ETA_BENDING = 600.0  # Pa s: relaxation time 6 ms
N = 20


def _model(viscosity, mu=0.0):
    material = rodmol.Material(E=E, nu=0.5, mu=mu, rho=RHO, viscosity=viscosity)
    return rodmol.Model(rodmol.Rod(L, RADIUS, material), N, medium="air", gravity=(0.0, 0.0, 0.0))


BSE_ZERO = dict(shear_extension=(0.0, 0.0, 0.0), bending_torsion=(ETA_BENDING,) * 3)


def test_per_component_viscosity_reaches_the_sections():
    model = _model(BSE_ZERO)
    area, inertia = np.pi * RADIUS**2, np.pi * RADIUS**4 / 4
    assert np.all(Sampled(model).vl == 0.0)
    np.testing.assert_allclose(Sampled(model).vth, np.tile(ETA_BENDING * inertia * np.array([2.0, 1.0, 1.0]), (N, 1)))
    # A key left out keeps the paper's ratios from mu.
    paper, partial = _model(None, mu=50.0), _model(dict(bending_torsion=(1.0, 2.0, 3.0)), mu=50.0)
    np.testing.assert_allclose(Sampled(partial).vl, Sampled(paper).vl, rtol=1e-15)
    np.testing.assert_allclose(Sampled(partial).vl[0], 50.0 * area * np.array([3.0, 1.0, 1.0]))
    # Bse = 0 leaves the axial and shear waves undamped: lightly damped (BDF order <= 2).
    assert grid_damping_ratio(model) == 0.0
    assert SemiDiscrete(model).lightly_damped
    assert not SemiDiscrete(_model(dict(shear_extension=(1e4,) * 3, bending_torsion=(1e4,) * 3))).lightly_damped


@pytest.mark.parametrize("bad", [dict(shear_extension=(1.0, -1.0, 0.0)), dict(bending=(1.0, 1.0, 1.0)),
                                 dict(shear_extension=(1.0, 2.0)), [1.0, 2.0]])
def test_bad_viscosity_is_refused(bad):
    with pytest.raises(rodmol.ParameterError, match="viscosity"):
        rodmol.Material(E=E, nu=0.5, rho=RHO, viscosity=bad)


def test_bse_zero_axial_mode_undamped_bending_decays_at_kelvin_voigt_rate():
    model = _model(BSE_ZERO)
    lay = rodmol.StateLayout(N)
    s = model.s_nodes[1:]

    # Axial: the first mode of a clamped-free bar, v_x = a omega sin(pi s / 2L).
    omega_axial = np.pi / (2 * L) * np.sqrt(E / RHO)
    y0 = rodmol.straight_state(model)
    lay.field(y0, "v")[:, 0] = 1e-3 * L * omega_axial * np.sin(np.pi * s / (2 * L))
    period = 2 * np.pi / omega_axial
    res = rodmol.simulate(model, 10 * period, initial=y0, rtol=1e-7, output_dt=period / 100)
    assert res.success, res.message
    stretch = res.tip[:, 0] - L
    first, last = np.max(np.abs(stretch[: 100])), np.max(np.abs(stretch[-100:]))
    print(f"\naxial amplitude over 10 periods: {first:.4e} -> {last:.4e} m")
    assert last == pytest.approx(first, rel=0.01)  # undamped (a damped mode would lose > 90 %)

    # Bending: the Euler-Bernoulli first mode shape (uniform cantilever).
    beta = 1.8751040687 / L
    sigma = (np.cosh(beta * L) + np.cos(beta * L)) / (np.sinh(beta * L) + np.sin(beta * L))
    shape = np.cosh(beta * s) - np.cos(beta * s) - sigma * (np.sinh(beta * s) - np.sin(beta * s))
    slope = beta * (np.sinh(beta * s) + np.sin(beta * s) - sigma * (np.cosh(beta * s) - np.cos(beta * s)))
    omega_b = (beta * L) ** 2 * np.sqrt(E * RADIUS**2 / (4 * RHO)) / L**2
    y0 = rodmol.straight_state(model)
    amplitude = 0.01 * L / shape[-1]
    lay.field(y0, "v")[:, 1] = amplitude * omega_b * shape
    lay.field(y0, "w")[:, 2] = amplitude * omega_b * slope
    period = 2 * np.pi / omega_b
    res = rodmol.simulate(model, 3 * period, initial=y0, rtol=1e-7, output_dt=period / 200)
    assert res.success, res.message
    keep = res.t > 0.5 * period
    omega, zeta = measure_free_vibration(res.t[keep], res.tip[keep, 1])
    expected = omega * (ETA_BENDING / E) / 2  # zeta = omega tau / 2, tau = eta / E
    print(f"bending: omega = {omega:.5f} rad/s (Euler-Bernoulli {omega_b:.5f}), zeta = {zeta:.5f}, "
          f"omega tau / 2 = {expected:.5f}")
    assert omega == pytest.approx(omega_b, rel=0.01)
    assert zeta == pytest.approx(expected, rel=0.02)
