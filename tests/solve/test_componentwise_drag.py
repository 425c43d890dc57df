"""The componentwise drag law -C v|v| (``Model(drag_law="componentwise")``):
a cantilever towed sideways at constant speed bends under the uniform drag
C V^2 as a beam under a uniform load."""

import numpy as np
import pytest

import rodmol
from rodmol.discretise import physics

L, RADIUS, E, RHO, MU = 0.2, 0.005, 1e6, 1000.0, 5e4
C = (0.1, 0.5, 0.2)  # kg/m^2
SPEED = 0.1  # m/s, global y, the base's and the rod's at the start


def test_compiled_law_is_c_v_abs_v():
    v = (0.3, -2.0, 0.01)
    got = physics.componentwise_drag(C, v, 0.0)
    np.testing.assert_allclose(got, np.array(C) * np.array(v) * np.abs(v), rtol=1e-15)


def test_towed_cantilever_bends_as_a_beam_under_uniform_drag():
    rod = rodmol.Rod(L, RADIUS, rodmol.Material(E=E, nu=0.5, mu=MU, rho=RHO))
    base = rodmol.BaseMotion(velocity=lambda t: np.array([0.0, SPEED, 0.0]))
    model = rodmol.Model(rod, 20, gravity=(0.0, 0.0, 0.0), base=base, drag_law="componentwise",
                         drag_coefficients=C)
    y0 = rodmol.straight_state(model)
    rodmol.StateLayout(20).field(y0, "v")[:, 1] = SPEED
    res = rodmol.simulate(model, 5.0, initial=y0, output_dt=0.5)
    assert res.success, res.message
    deflection = res.tip[-1] - res.positions[-1, 0]
    load = C[1] * SPEED**2  # N/m, against the motion
    expected = -load * L**4 / (8 * E * np.pi * RADIUS**4 / 4)
    print(f"\ntip deflection {deflection[1]:.6e} m, beam {expected:.6e} m")
    assert deflection[1] == pytest.approx(expected, rel=0.01)  # small deflection, N = 20
    assert abs(deflection[2]) < 1e-12


@pytest.mark.parametrize("options, match", [
    (dict(drag_law="quadratic"), "drag_law"),
    (dict(drag_law="componentwise"), "drag_coefficients"),
    (dict(drag_law="componentwise", drag_coefficients=(1.0, -1.0, 0.0)), "drag_coefficients"),
    (dict(drag_coefficients=(1.0, 1.0, 1.0)), "drag_coefficients"),
])
def test_bad_drag_law_is_refused(options, match):
    rod = rodmol.Rod(L, RADIUS, rodmol.Material(E=E, nu=0.5, rho=RHO))
    with pytest.raises(rodmol.ParameterError, match=match):
        rodmol.Model(rod, 4, **options)
