"""Cables with a routing p(s) (helical, converging) against the exact statics
of the continuum, and the checks of offsets outside the body.

With the cable anchored at the free tip and no other load, the total stress
(body plus cable) vanishes everywhere, so at each s the strains solve the
six algebraic equations

    Kl (q - e_x) + T tau = 0,   Kth k + p x T tau = 0,
    tau = c / |c|,  c = q + k x p + p',

solved here by ``fsolve`` point by point; the shape follows by integrating
u' = R q, R' = R [k] with ``solve_ivp``. A helical routing of constant
radius gives a helix: |k| and the torsion are constant along s.
"""

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.interpolate import CubicSpline
from scipy.optimize import fsolve

import rodmol
from rodmol.discretise import centreline

L, RADIUS, E, NU, RHO, T = 0.3, 0.01, 1e6, 0.5, 1000.0, 4.0
G = E / (2 * (1 + NU))
AREA, J = np.pi * RADIUS**2, np.pi * RADIUS**4 / 4
KL, KTH = np.array([E * AREA, G * AREA, G * AREA]), np.array([2 * G * J, E * J, E * J])
TURNS = 1.5 / L  # helix: 1.5 rad of routing turn per metre... times 2 pi below
HELIX_R = 0.006


def helix(s):
    return HELIX_R * np.cos(2 * np.pi * TURNS * s), HELIX_R * np.sin(2 * np.pi * TURNS * s)


def helix_slope(s):
    w = 2 * np.pi * TURNS
    return -HELIX_R * w * np.sin(w * s), HELIX_R * w * np.cos(w * s)


CONVERGING = [(0.0, 0.008, 0.0), (L, 0.002, 0.003)]


def converging(s):
    return 0.008 - 0.006 * s / L, 0.003 * s / L


def converging_slope(s):
    return -0.006 / L + 0 * s, 0.003 / L + 0 * s


def exact_strains(offset, slope, s_points):
    """q, k (n, 3) of the continuum at ``s_points`` (see the module docstring)."""
    out, guess = [], np.r_[1.0, 0, 0, 0, 0, 0]
    for s in s_points:
        p = np.r_[0.0, offset(s)]
        dp = np.r_[0.0, slope(s)]

        def residual(x, p=p, dp=dp):
            q, k = x[:3], x[3:]
            c = q + np.cross(k, p) + dp
            tau = c / np.linalg.norm(c)
            return np.r_[KL * (q - [1, 0, 0]) + T * tau, KTH * k + np.cross(p, T * tau)]

        guess = fsolve(residual, guess, xtol=1e-13)
        assert np.max(np.abs(residual(guess))) < 1e-9
        out.append(guess.copy())
    out = np.array(out)
    return out[:, :3], out[:, 3:]


def exact_tip(offset, slope):
    s = np.linspace(0.0, L, 801)
    q, k = exact_strains(offset, slope, s)
    qs, ks = CubicSpline(s, q), CubicSpline(s, k)

    def rhs(si, z):
        rot = z[3:].reshape(3, 3)
        kx = np.array([[0, -ks(si)[2], ks(si)[1]], [ks(si)[2], 0, -ks(si)[0]], [-ks(si)[1], ks(si)[0], 0]])
        return np.r_[rot @ qs(si), (rot @ kx).ravel()]

    sol = solve_ivp(rhs, (0.0, L), np.r_[0, 0, 0, np.eye(3).ravel()], rtol=1e-11, atol=1e-13)
    return sol.y[:3, -1], (s, q, k)


def _model(offset, n, **cable):
    rod = rodmol.Rod(L, RADIUS, rodmol.Material(E=E, nu=NU, rho=RHO))
    return rodmol.Model(rod, n, gravity=(0.0, 0.0, 0.0), cables=[rodmol.Cable(offset, L, T, **cable)])


ROUTINGS = {"helical": (helix, helix, helix_slope), "converging": (CONVERGING, converging, converging_slope)}


@pytest.mark.parametrize("name", ROUTINGS)
def test_routed_cable_statics_match_the_continuum(name):
    given, offset, slope = ROUTINGS[name]
    tip, (s, q, k) = exact_tip(offset, slope)
    if name == "helical":  # a helix: constant curvature and torsion
        bend = np.hypot(k[:, 1], k[:, 2])
        assert np.ptp(bend) < 1e-9 * np.max(bend) and np.ptp(k[:, 0]) < 1e-9 * np.max(bend)
    errors = []
    for n in (20, 40):
        model = _model(given, n)
        y = rodmol.equilibrium(model)
        lay = rodmol.StateLayout(n)
        positions = centreline.positions(lay.base_position(y), lay.quaternions(y), lay.field(y, "q"),
                                                lay.field(y, "k"), model.ds)
        errors.append(np.linalg.norm(positions[-1] - tip))
        mid = 0.5 * (model.s_nodes[:-1] + model.s_nodes[1:])  # the centred scheme's cells
        k_exact = exact_strains(offset, slope, mid)[1]
        curvature_error = np.max(np.abs(lay.field(y, "k") - k_exact))
    order = np.log2(errors[0] / errors[1])
    print(f"\n{name}: tip {tip}, |tip error| N=20: {errors[0]:.3e} m, N=40: {errors[1]:.3e} m, "
          f"order {order:.2f}; max curvature error at N=40 {curvature_error:.2e} 1/m (|k| ~ {np.max(np.abs(k)):.3f})")
    assert errors[1] < 5e-4 * L
    assert order > 1.8
    assert curvature_error < 1e-3 * np.max(np.abs(k))


def test_offsets_beyond_the_body_need_outside_body():
    with pytest.raises(rodmol.ParameterError, match=r"cable 'c'.*0\.015.*outside_body=True"):
        _model((0.015, 0.0), 4, name="c")
    with pytest.raises(rodmol.ParameterError, match=r"cable 'c'.*s = 0\.2"):
        _model([(0.0, 0.0, 0.0), (0.2, 0.0, 0.01), (L, 0.0, 0.02)], 4, name="c")
    model = _model((0.015, 0.0), 4, name="c", outside_body=True)
    assert model.cables[0].outside_body


@pytest.mark.parametrize("offset, match", [
    ([(0.0, 0.0, 0.0), (0.0, 0.001, 0.0)], "increasing s"),
    (lambda s: (s, s, s), "offset"),
    (lambda s: 1 / 0, "`offset` function failed"),
    ("abc", "offset"),
])
def test_bad_routings_are_refused(offset, match):
    with pytest.raises(rodmol.ParameterError, match=match):
        rodmol.Cable(offset, L, 1.0, name="c")


def test_routing_drawn_in_paraview_output():
    model = _model(helix, 10)
    result = rodmol.simulate(model, 0.01, output_dt=0.01)
    from rodmol.output.writers import cable_paths

    s, points = cable_paths(result, 0)[0]
    rot, u = result.rotations[0], result.positions[0]
    p = np.column_stack([np.zeros(len(s)), *helix(s)])
    np.testing.assert_allclose(points[:-1], u[:-1] + np.einsum("nij,nj->ni", rot[:-1], p[:-1]), atol=1e-12)
    np.testing.assert_allclose(points[-1], u[-1] + rot[-1] @ p[-1], atol=1e-12)
