"""Statics: the discrete equilibrium of the paper's tapered arm against an
independent continuum solution of the static Cosserat rod equations.

The reference is written here from scratch (it shares no code with rodmol):
the planar static rod, clamped at the origin along +x, free at s = L, loaded by
its weight minus buoyancy, with the same extensible and shearable linear law
N = Kl (q - q*), M = Kth k, solved by ``scipy.integrate.solve_bvp``.
The paper's upwind scheme (section IV-C) is first order in ds, so its tip
must approach the reference like C ds (observed order close to 1); the
centred scheme's like C ds^2 (close to 2). ``solvers/continuum.py`` is a
second, 3-D reference with cables that reads the model's own parameters
(``tests/solve/test_continuum_reference.py``); this one restates the paper's
numbers so that it shares nothing with rodmol.
"""

import numpy as np
import pytest
from scipy.integrate import solve_bvp

import rodmol
from rodmol.discretise.load_entries import load_scale
from rodmol.discretise.sampling import Sampled
from rodmol.solve.rest_equations import RestEquations

# Table I of the paper (the same numbers rodmol.arm.paper_rod() uses; restated
# here so that the reference does not read them from rodmol).
L = 0.418  # m
R_BASE, R_TIP = 0.015, 0.004  # m, linear taper
E, NU, RHO = 110e3, 0.5, 1080.0  # Pa, -, kg/m^3
RHO_WATER = 1022.0  # kg/m^3 (Table III)
G_ACC = 9.81  # m/s^2, acting along -y


def tapered(s):
    return R_BASE + (R_TIP - R_BASE) * s / L


def continuum_equilibrium(radius, net_density, g=G_ACC, length=L, young=E, nu=NU,
                          steps=4, tol=1e-8):
    """Planar static Cosserat rod under a distributed load -net_density*A(s)*g*e_y.

    Unknowns (all global except the strains): x, y, theta (section angle),
    the internal force (Fx, Fy) and the bending moment M about z.

        x' = cos(th) q1 - sin(th) q2      (u' = R q)
        y' = sin(th) q1 + cos(th) q2
        th' = M / (E Jz)                  (R' = R k~, M = E Jz k)
        F' = -f                           (N' + k x N + n = 0, written globally)
        M' = -(x' Fy - y' Fx)             (M' + k x M + q x N = 0)

    with the local force N = R^T F, q1 = 1 + N1 / (E A), q2 = N2 / (G A).
    Boundary conditions: clamped base (x = y = th = 0 at s = 0), free tip
    (F = 0, M = 0 at s = L). The load is ramped from zero (continuation), each
    step starting from the previous solution; the first guess is the straight rod.
    Returns the scipy solution object of the full load.
    """
    shear = young / (2.0 * (1.0 + nu))

    def rhs_for(load):
        def rhs(s, z):
            _, _, th, fx, fy, m = z
            r = radius(s)
            area, inertia = np.pi * r**2, np.pi * r**4 / 4.0
            c, sn = np.cos(th), np.sin(th)
            n1, n2 = c * fx + sn * fy, -sn * fx + c * fy
            q1, q2 = 1.0 + n1 / (young * area), n2 / (shear * area)
            dx, dy = c * q1 - sn * q2, sn * q1 + c * q2
            fy_load = -load * area  # N/m along y (weight minus buoyancy)
            return np.vstack([dx, dy, m / (young * inertia), 0.0 * s, -fy_load,
                              -(dx * fy - dy * fx)])
        return rhs

    def bc(a, b):
        return np.array([a[0], a[1], a[2], b[3], b[4], b[5]])

    mesh = np.linspace(0.0, length, 101)
    guess = np.zeros((6, mesh.size))
    guess[0] = mesh  # straight, unloaded
    for lam in np.linspace(0.0, 1.0, steps + 1)[1:]:
        sol = solve_bvp(rhs_for(lam * net_density * g), bc, mesh, guess, tol=tol,
                        max_nodes=200_000)
        assert sol.success, f"reference BVP failed at load factor {lam}: {sol.message}"
        guess = sol.sol(mesh)
    return sol


@pytest.fixture(scope="module")
def references():
    """Continuum tip position and base curvature, in air and in water."""
    out = {}
    for medium, rho_w in (("air", 0.0), ("water", RHO_WATER)):
        sol = continuum_equilibrium(tapered, RHO - rho_w)
        tip = sol.y[:2, -1]
        base_curvature = sol.y[5, 0] / (E * np.pi * R_BASE**4 / 4.0)
        out[medium] = dict(tip=tip, base_curvature=base_curvature)
    return out


def test_reference_solver_matches_linear_cantilever():
    """Check the reference itself: a uniform rod under a tiny load must give the
    small-deflection (Timoshenko, shear factor 1) cantilever result
    delta = w L^4 / (8 E J) + w L^2 / (2 G A)."""
    r = 0.01
    net = 1e-3  # kg/m^3: deflection ~ 1e-5 L, so geometric nonlinearity ~ 1e-10
    sol = continuum_equilibrium(lambda s: np.full_like(s, r), net, steps=1, tol=1e-10)
    area, inertia = np.pi * r**2, np.pi * r**4 / 4.0
    w = net * G_ACC * area
    delta = w * L**4 / (8 * E * inertia) + w * L**2 / (2 * E / (2 * (1 + NU)) * area)
    assert sol.y[1, -1] == pytest.approx(-delta, rel=1e-6)


def _rodmol_equilibrium(medium, n, scheme="centred"):
    model = rodmol.Model(rodmol.arm.paper_rod(), n, medium=medium)
    y = rodmol.equilibrium(model, scheme=scheme)
    lay = rodmol.StateLayout(n)
    return model, y, lay.field(y, "u")[-1], lay.field(y, "k")[0]


def _observed_order(ns, errors):
    """Slope of log(error) against log(ds) by least squares."""
    ds = L / np.asarray(ns, dtype=float)
    return np.polyfit(np.log(ds), np.log(errors), 1)[0]


@pytest.mark.parametrize("scheme, order", [("upwind", 1), ("centred", 2)])
@pytest.mark.parametrize("medium", ["air", "water"])
def test_tip_converges_to_continuum_at_the_schemes_order(medium, scheme, order, references):
    ref = references[medium]["tip"]
    # The cases are what they claim to be: in air the arm droops to nearly
    # vertical (tip below -0.9 L), in water (net density 58 kg/m^3) it bends moderately.
    if medium == "air":
        assert ref[1] < -0.9 * L
    else:
        assert -0.5 * L < ref[1] < -0.2 * L

    ns = (25, 50, 100, 200)
    tips = {}
    for n in ns:
        _, _, tip, _ = _rodmol_equilibrium(medium, n, scheme)
        assert tip[2] == pytest.approx(0.0, abs=1e-12)  # planar load, planar shape
        tips[n] = tip[:2]
    errors = np.array([np.linalg.norm(tips[n] - ref) for n in ns])
    observed = _observed_order(ns, errors)
    print(f"\n{medium}, {scheme}: reference tip {ref}, errors/L {errors / L}, observed order {observed:.3f}")

    assert order - 0.2 <= observed <= order + 0.3
    # First order: about 1/2 % of L at N = 200; second order: 1e-5 of L.
    assert errors[-1] < (0.01 if order == 1 else 2e-5) * L
    # The error is a clean C ds^p leading term: Richardson extrapolation
    # removes it and lands much closer to the continuum.
    extrapolated = tips[200] + (tips[200] - tips[100]) / (2**order - 1)
    print(f"Richardson-extrapolated error/L {np.linalg.norm(extrapolated - ref) / L:.2e}")
    assert np.linalg.norm(extrapolated - ref) < 0.1 * errors[-1]


@pytest.mark.parametrize("medium", ["air", "water"])
def test_base_curvature_converges_first_order(medium, references):
    """The clamp moment (curvature at s = 0) also converges at first order."""
    ref = references[medium]["base_curvature"]
    ns = (25, 50, 100, 200)
    errors = np.array([abs(_rodmol_equilibrium(medium, n)[3][2] - ref) for n in ns])
    order = _observed_order(ns, errors)
    print(f"\n{medium}: reference base curvature {ref:.6g} 1/m, relative errors "
          f"{errors / abs(ref)}, order {order:.3f}")
    assert 0.8 <= order <= 1.3
    assert errors[-1] < 0.05 * abs(ref)


@pytest.mark.parametrize("medium", ["air", "water"])
def test_equilibrium_is_rest_state(medium):
    """At the equilibrium the dynamic right-hand side vanishes: no motion, and
    net force and torque densities tiny relative to the load scale (1e-8 of the
    net weight per unit length, as the docstring of ``equilibrium`` promises
    1e-10 on its own residual)."""
    n = 50
    model, y, _, _ = _rodmol_equilibrium(medium, n)
    lay = rodmol.StateLayout(n)
    assert np.all(lay.field(y, "v") == 0.0) and np.all(lay.field(y, "w") == 0.0)

    rate = rodmol.SemiDiscrete(model)(0.0, y)
    weight = load_scale(model)  # net weight [N] (no cables here)
    # Kinematic rates: zero velocities give zero pose and strain rates (the
    # quaternion rate only sees round-off of |Q| - 1).
    for name in ("u", "Q", "q", "k"):
        assert np.max(np.abs(lay.field(rate, name))) < 1e-12, name
    assert np.max(np.abs(rate[:7])) < 1e-12
    # Accelerations back to force and torque densities per unit length.
    force = lay.field(rate, "v") * Sampled(model).mass
    torque = lay.field(rate, "w") * Sampled(model).inertia
    print(f"\n{medium}: max |force| / (W/L) = {np.max(np.abs(force)) * L / weight:.2e}, "
          f"max |torque| / W = {np.max(np.abs(torque)) / weight:.2e}")
    assert np.max(np.abs(force)) < 1e-8 * weight / L
    assert np.max(np.abs(torque)) < 1e-8 * weight


def test_a_system_is_solved_with_its_own_scheme_and_keeps_its_structure():
    model = rodmol.scenarios.get("fetching").model(8)
    system = rodmol.SemiDiscrete(model, "upwind")
    with pytest.raises(rodmol.ParameterError, match=r"`scheme` 'centred': the system given is built with the 'upwind'"):
        rodmol.equilibrium(system, scheme="centred")
    np.testing.assert_array_equal(rodmol.equilibrium(system, scheme="upwind"), rodmol.equilibrium(system))
    # The static layout and the column groups are built once per system, whatever t and tensions.
    first, later = RestEquations(system, 0.0), RestEquations(system, 1.0, np.ones(len(model.cables)))
    assert first.static is later.static and first.differences is later.differences
    assert RestEquations(rodmol.SemiDiscrete(model, "upwind"), 0.0).differences is not first.differences
