"""Precurved, pretwisted and prestretched rods (``Rod(rest_curvature=, rest_stretch=)``):
statics against an independent boundary-value solution of the Cosserat rod
equations with rest strains, the observed spatial order, the rest state of
the dynamics, and backends agreeing on a motion."""

import numpy as np
import pytest
from scipy.integrate import solve_bvp, solve_ivp

import rodmol

E, NU, RHO, RADIUS = 2e6, 0.4, 1100.0, 0.01
MATERIAL = rodmol.Material(E=E, nu=NU, mu=0.0, rho=RHO)
#: Quarter circle of radius 0.2 m in the x-y plane.
BEND_RADIUS = 0.2
QUARTER = 0.5 * np.pi * BEND_RADIUS
TIP_FORCE = np.array([0.0, -0.3, 0.2])  # [N], global: in and out of the rest plane


def _wavy_curvature(s):
    """A smooth, non-constant rest curvature with twist [1/m], local frame."""
    s = np.asarray(s, dtype=float)
    return np.stack([3.0 + 0.0 * s, -2.0 + 8.0 * s, 1.0 / BEND_RADIUS + 10.0 * s], axis=-1)


def _wavy_stretch(s):
    """A smooth rest stretch and shear [-], local frame."""
    s = np.asarray(s, dtype=float)
    return np.stack([1.0 + 0.05 * np.sin(5.0 * s), 0.01 * s, -0.02 + 0.0 * s], axis=-1)


def _constant(value):
    return lambda s: np.broadcast_to(np.asarray(value, dtype=float), np.shape(s) + (3,))


def _hat(k):
    """[k]x for columns k (3, m): (3, 3, m)."""
    z = np.zeros_like(k[0])
    return np.array([[z, -k[2], k[1]], [k[2], z, -k[0]], [-k[1], k[0], z]])


def cosserat_bvp(length, rest_stretch, rest_curvature, tip_force, tol=1e-10):
    """Tip position [m], global, of a uniform shearable, extensible Cosserat
    rod (E, NU, RADIUS) clamped at the origin along +x, with rest strains
    ``rest_stretch(s)``, ``rest_curvature(s)`` (local) and a global force
    ``tip_force`` [N] at the tip, without gravity.

    Unknowns p (global), R (row major), n, m (global internal force and
    moment): p' = R q, R' = R [k]x, n' = 0, m' = -p' x n, with
    R^T n = Kl (q - q*), R^T m = Kth (k - k*); p(0) = 0, R(0) = I,
    n(L) = F, m(L) = 0. Written here from the equations, for the tests.
    """
    area, second = np.pi * RADIUS**2, np.pi * RADIUS**4 / 4
    shear = E / (2 * (1 + NU))
    kl = np.array([E * area, shear * area, shear * area])[:, None]
    kth = np.array([2 * shear * second, E * second, E * second])[:, None]
    force = np.asarray(tip_force, dtype=float)

    def fun(s, y):
        rot = y[3:12].reshape(3, 3, -1)
        n, m = y[12:15], y[15:18]
        q = rest_stretch(s).T + np.einsum("jis,js->is", rot, n) / kl
        k = rest_curvature(s).T + np.einsum("jis,js->is", rot, m) / kth
        dp = np.einsum("ijs,js->is", rot, q)
        drot = np.einsum("ils,ljs->ijs", rot, _hat(k))
        return np.vstack([dp, drot.reshape(9, -1), np.zeros_like(n), -np.cross(dp, n, axis=0)])

    def bc(y0, y1):
        return np.concatenate([y0[:3], y0[3:12] - np.eye(3).ravel(), y1[12:15] - force, y1[15:18]])

    # Initial guess: the rest shape carrying the tip force.
    def rest(s, y):
        rot = y[3:12].reshape(3, 3)
        return np.concatenate([rot @ rest_stretch(s), (rot @ _hat(rest_curvature(s)[:, None])[..., 0]).ravel()])

    s = np.linspace(0.0, length, 201)
    shape = solve_ivp(rest, (0.0, length), np.concatenate([np.zeros(3), np.eye(3).ravel()]), t_eval=s,
                      rtol=1e-10, atol=1e-12).y
    guess = np.vstack([shape, np.tile(force[:, None], (1, s.size)),
                       np.cross(shape[:3, -1:] - shape[:3], force[:, None], axis=0)])
    sol = solve_bvp(fun, bc, s, guess, tol=tol, max_nodes=100000)
    assert sol.success, sol.message
    return sol.sol(length)[:3]


def tip_at_rest(rod, n, tip_force, scheme="centred"):
    """The tip [m], global, of rodmol's static equilibrium of ``rod`` clamped at the origin."""
    model = rodmol.Model(rod, n, gravity=(0.0, 0.0, 0.0), loads=[rodmol.PointForce(rod.length, tip_force)])
    y = rodmol.equilibrium(model, scheme=scheme)
    return rodmol.StateLayout(n).integrated_positions(y)[-1]


@pytest.mark.parametrize("plane", ["in-plane (k_z)", "out of plane (k_y)"])
def test_quarter_circle_under_a_tip_load_matches_the_cosserat_bvp(plane):
    """Quarter circle clamped at the origin, loaded at its tip: rodmol's
    equilibrium against solve_bvp of the Cosserat equations with the same
    rest curvature; the straight-rest answer is centimetres away."""
    curvature = (0.0, 0.0, 1.0 / BEND_RADIUS) if plane.startswith("in") else (0.0, 1.0 / BEND_RADIUS, 0.0)
    rod = rodmol.Rod(QUARTER, RADIUS, MATERIAL, rest_curvature=curvature)
    reference = cosserat_bvp(QUARTER, _constant((1.0, 0.0, 0.0)), _constant(curvature), TIP_FORCE)
    unloaded = cosserat_bvp(QUARTER, _constant((1.0, 0.0, 0.0)), _constant(curvature), np.zeros(3))
    np.testing.assert_allclose(unloaded, BEND_RADIUS * np.array(
        [1.0, *((1.0, 0.0) if plane.startswith("in") else (0.0, -1.0))]), atol=1e-9)  # the reference's rest
    assert np.linalg.norm(reference - unloaded) > 0.2 * BEND_RADIUS  # a large deflection
    tip = tip_at_rest(rod, 40, TIP_FORCE)
    assert np.linalg.norm(tip - reference) < 5e-4 * QUARTER  # 2.6e-4 L measured (in-plane)
    straight = tip_at_rest(rodmol.Rod(QUARTER, RADIUS, MATERIAL), 40, TIP_FORCE)
    assert np.linalg.norm(straight - reference) > 0.1 * QUARTER


def _observed_orders(scheme, sizes):
    rod = rodmol.Rod(QUARTER, RADIUS, MATERIAL, rest_curvature=_wavy_curvature, rest_stretch=_wavy_stretch)
    reference = cosserat_bvp(QUARTER, _wavy_stretch, _wavy_curvature, TIP_FORCE)
    errors = [np.linalg.norm(tip_at_rest(rod, n, TIP_FORCE, scheme) - reference) for n in sizes]
    return np.log2(np.array(errors[:-1]) / errors[1:]), errors


def test_second_order_for_smooth_rest_strains():
    """Centred scheme, rest curvature and twist and stretch varying along s:
    the tip error against the BVP halves twice per halving of ds."""
    orders, errors = _observed_orders("centred", (10, 20, 40))
    assert np.all(orders >= 1.8), (orders, errors)


def test_upwind_scheme_is_first_order_with_rest_strains():
    orders, errors = _observed_orders("upwind", (20, 40, 80))  # measured 0.84, 0.92
    assert np.all((orders > 0.75) & (orders < 1.3)), (orders, errors)


@pytest.mark.parametrize("scheme", list(rodmol.SCHEMES))
def test_precurved_rod_without_loads_stays_at_rest(scheme):
    """The undeformed state of a precurved, pretwisted, prestretched rod is a
    rest state of the dynamics: strain, velocity and position rates exactly
    zero (the quaternion rows only see |Q|^2 - 1 at round-off), and the
    equilibrium without loads is that state."""
    rod = rodmol.Rod(QUARTER, (0.012, 0.006), MATERIAL, rest_curvature=_wavy_curvature,
                     rest_stretch=_wavy_stretch)
    model = rodmol.Model(rod, 12, gravity=(0.0, 0.0, 0.0), medium="water")
    system = rodmol.SemiDiscrete(model, scheme)
    y = rodmol.undeformed_state(model, scheme)
    rates = system(0.0, y)
    lay = system.layout
    for name in ("u", "q", "k", "v", "w"):
        assert np.all(lay.field(rates, name) == 0.0), name
    assert np.max(np.abs(lay.field(rates, "Q"))) < 1e-15
    np.testing.assert_array_equal(rodmol.equilibrium(model, scheme=scheme), y)
    # the strains are the rest strains of the cells, and the shape is curved
    np.testing.assert_array_equal(lay.field(y, "k"), system.rest[1])
    positions = system.state_view(0.0, y).positions
    np.testing.assert_allclose(lay.integrated_positions(y), positions, atol=1e-15)
    assert abs(positions[-1, 0]) < 0.9 * QUARTER


def test_backends_agree_on_a_precurved_rod_released_under_gravity():
    """A quarter circle released from its rest shape falls under gravity: CVODE
    and the generalized-alpha integrator give the same tip motion."""
    rod = rodmol.Rod(QUARTER, RADIUS, rodmol.Material(E=2e5, nu=0.4, mu=200.0, rho=RHO),
                     rest_curvature=(0.5, 0.0, 1.0 / BEND_RADIUS))
    model = rodmol.Model(rod, 10, gravity=(0.0, 0.0, -9.81))
    runs = {backend: rodmol.simulate(model, 0.2, initial="straight", backend=backend, output_dt=0.05,
                                     rtol=1e-6, **options)
            for backend, options in (("cvode", {}), ("galpha", {"dt": 2e-4}))}
    for run in runs.values():
        assert run.success, run.message
    cvode, galpha = runs["cvode"].tip, runs["galpha"].tip
    np.testing.assert_allclose(cvode[0], rodmol.undeformed_state(model)[-19:-16], atol=1e-12)
    assert np.linalg.norm(cvode[-1] - cvode[0]) > 0.01  # it moved
    motion = np.max(np.linalg.norm(cvode - cvode[0], axis=-1))
    assert np.max(np.linalg.norm(cvode - galpha, axis=-1)) < 1e-4 * motion  # 3e-6 measured


def test_displacement_controlled_cable_follows_the_rest_shape():
    """A tendon without a given rest length is just taut on the precurved rod
    at rest: no tension there, the equilibrium is the undeformed rod; its rest
    length is the path on the curve (on the outside of the bend: longer than
    on the straight rod by the factor 1 + |p_y| / R)."""
    rod = rodmol.Rod(QUARTER, RADIUS, MATERIAL, rest_curvature=(0.0, 0.0, 1.0 / BEND_RADIUS))
    tendon = rodmol.Cable((-0.005, 0.0), QUARTER, displacement=0.0, compliance=1e-3, name="outer")
    model = rodmol.Model(rod, 10, gravity=(0.0, 0.0, 0.0), cables=[tendon])
    on_rod = model.cables[0]
    assert tendon.rest_length == pytest.approx(QUARTER, rel=1e-12)  # the straight rod's
    assert on_rod.rest_length == pytest.approx(QUARTER * (1.0 + 0.005 / BEND_RADIUS), rel=1e-12)
    y = rodmol.undeformed_state(model)
    system = rodmol.SemiDiscrete(model)
    assert system.tensions(0.0, y)[0] < 1e-9
    np.testing.assert_allclose(rodmol.equilibrium(model), y, atol=1e-12)
    # Back on a straight rod, the default is the straight path again.
    assert model.replace(rod=rodmol.Rod(QUARTER, RADIUS, MATERIAL)).cables[0].rest_length == tendon.rest_length


def test_energy_is_measured_from_the_rest_strains_and_conserved():
    """A precurved, pretwisted rod without damping, gravity or fluid, set moving
    from its rest shape: the strain energy starts at zero (it is measured from
    the rest strains) and kinetic plus strain energy is conserved."""
    rod = rodmol.Rod(QUARTER, RADIUS, MATERIAL, rest_curvature=_wavy_curvature, rest_stretch=_wavy_stretch)
    model = rodmol.Model(rod, 10, gravity=(0.0, 0.0, 0.0))
    y0 = rodmol.undeformed_state(model)
    lay = rodmol.StateLayout(10)
    lay.field(y0, "v")[:] = np.outer(np.linspace(0.1, 1.0, 10), [0.0, 0.02, 0.01])
    lay.field(y0, "w")[:] = np.outer(np.linspace(0.1, 1.0, 10), [0.3, 0.0, -0.2])
    run = rodmol.simulate(model, 0.1, initial=y0, rtol=1e-9, output_dt=0.02)
    assert run.success, run.message
    energy = rodmol.energy(model, run)
    assert energy["strain"][0] == 0.0 and energy["kinetic"][0] > 0.0
    assert np.max(energy["strain"]) > 0.3 * energy["kinetic"][0]  # energy went into the strains
    drift = np.max(np.abs(energy["total"] - energy["total"][0]))
    assert drift < 1e-5 * energy["total"][0], drift  # 3.2e-6 measured (the time error at rtol 1e-9)
