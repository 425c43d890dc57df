"""Friction between a cable and the body (``Cable(friction=mu)``): the
regularised capstan law T(s) = T(0) exp(-mu int sigma kappa ds)."""

import numpy as np
import pytest

import rodmol

L, RADIUS, OFFSET = 0.3, 0.01, 0.006
ROD = rodmol.Rod(L, RADIUS, rodmol.Material(E=1e6, nu=0.5, mu=3e3, rho=100.0))


def _model(friction, tension, n=10, slip_speed=2e-4):
    cable = rodmol.Cable((OFFSET, 0.0), L, tension, name="c", friction=friction, slip_speed=slip_speed)
    return rodmol.Model(ROD, n, gravity=(0.0, 0.0, 0.0), cables=[cable])


def _pull(t):
    return 5.0 * np.sin(np.pi * t / 16.0) ** 2  # N: load 0-8 s, unload 8-16 s, smooth


def test_zero_coefficient_is_todays_model_to_round_off():
    knots = [(0.0, 0.0), (0.5, 2.0), (1.0, 0.5)]
    plain = rodmol.Model(ROD, 10, gravity=(0.0, -9.81, 0.0),
                         cables=[rodmol.Cable((OFFSET, 0.0), L, knots, name="c")])
    zero = rodmol.Model(ROD, 10, gravity=(0.0, -9.81, 0.0),
                        cables=[rodmol.Cable((OFFSET, 0.0), L, knots, name="c", friction=0.0)])
    a, b = rodmol.simulate(plain, 1.0, output_dt=0.1), rodmol.simulate(zero, 1.0, output_dt=0.1)
    assert a.success and b.success
    np.testing.assert_array_equal(a.states, b.states)


@pytest.mark.parametrize("direction", [1.0, -1.0], ids=["loading", "unloading"])
def test_capstan_ratio_on_a_circular_arc(direction):
    """A circular arc of curvature kappa whose curvature grows (the cable's path
    shortens: it slides toward the base, tension falls toward the anchor) or
    shrinks: T(s) / T(0) = exp(-+ mu kappa s), s at the middle of each cell."""
    mu, kappa, n = 0.3, 5.0, 40
    model = _model(mu, 1.0, n=n, slip_speed=1e-9)
    system = rodmol.SemiDiscrete(model)
    lay = rodmol.StateLayout(n)
    y = rodmol.straight_state(model)
    lay.field(y, "k")[:, 2] = kappa
    # w_z = a s: the curvature changes at the uniform rate a, the shape stays a circle.
    lay.field(y, "w")[:, 2] = direction * 2.0 * model.s_nodes[1:]
    system.update_inputs(0.0, y)
    factors = system.friction_factors(y)[0]
    s_mid = model.s_nodes[:-1] + model.ds / 2
    expected = np.exp(-direction * mu * kappa * s_mid)
    np.testing.assert_allclose(factors, expected, rtol=1e-9)
    print(f"\nT(L)/T(0) = {factors[-1] * np.exp(-direction * mu * kappa * model.ds / 2):.6f}, "
          f"exp(-+mu theta) = {np.exp(-direction * mu * kappa * L):.6f}")


def _loop_width(friction):
    result = rodmol.simulate(_model(friction, _pull), 16.0, output_dt=0.05)
    assert result.success, result.message
    tension, tip = result.tensions[:, 0], result.tip[:, 1]
    up, down = result.t <= 8.0, result.t >= 8.0
    levels = np.linspace(0.5, 4.5, 9)
    loading = np.interp(levels, tension[up], tip[up])
    unloading = np.interp(levels, tension[down][::-1], tip[down][::-1])
    return float(np.max(np.abs(unloading - loading))), float(np.max(tip))


def test_load_unload_cycle_hysteresis_grows_with_friction():
    widths = {mu: _loop_width(mu) for mu in (0.0, 0.05, 0.1)}
    print("\n" + ", ".join(f"mu = {mu}: loop width {1e3 * w:.3f} mm (tip up to {1e3 * top:.1f} mm)"
                            for mu, (w, top) in widths.items()))
    w0, w1, w2 = (widths[mu][0] for mu in (0.0, 0.05, 0.1))
    # mu = 0: only the viscous lag of the 16 s cycle (0.6 mm) ...
    assert w0 < 0.2 * w1
    # ... and the friction's share of the loop is proportional to mu.
    assert (w2 - w0) / (w1 - w0) == pytest.approx(2.0, rel=0.2)


def test_friction_at_rest_is_zero():
    """Regularised friction needs sliding: the static equilibrium is the frictionless one."""
    y = rodmol.equilibrium(rodmol.Model(ROD, 10, cables=[rodmol.Cable((OFFSET, 0.0), L, 2.0, friction=0.5)]))
    y0 = rodmol.equilibrium(rodmol.Model(ROD, 10, cables=[rodmol.Cable((OFFSET, 0.0), L, 2.0)]))
    np.testing.assert_allclose(y, y0, atol=1e-12)
