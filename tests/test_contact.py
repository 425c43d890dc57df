"""Contact physics: a cantilever resting on a floor, stick and slip on a tilted
plane, and the static equilibrium with a floor against the dynamics' rest.

A uniform rod (L = 0.3 m, r = 1 cm, E = 10 MPa, rho = 1000 kg/m^3, in air)
clamped horizontally at the origin: its free tip deflection under its own
weight would be rho A g L^4 / (8 E I) = 4 cm, so a floor 1 cm below the
rod's underside stops it. The contact law sees the *time-integrated*
positions (``Result.integrated_positions``); the positions rebuilt from the
strains (``Result.positions``) drift from them by O(ds) during a transient,
which the tests measure and print.
"""

import numpy as np
import pytest

import rodmol

L, R = 0.3, 0.01
E, RHO = 1e7, 1000.0
EI = E * np.pi * R**4 / 4
WEIGHT = RHO * np.pi * R**2 * 9.81  # rho A g [N/m]
FLOOR_Y = -0.02
LAW = dict(stiffness=1e6, damping=200.0, smoothing_depth=2e-5)


def _rod(mu=3e4):
    return rodmol.Rod(L, R, rodmol.Material(E=E, nu=0.5, mu=mu, rho=RHO))


def floor_model(n=20):
    floor = rodmol.PlaneContact((0.0, FLOOR_Y, 0.0), (0.0, 1.0, 0.0), **LAW)
    return rodmol.Model(_rod(), n, medium="air", loads=[floor])


def penetration(positions):
    """Depth [m] of each section's surface below the floor (negative: above)."""
    return R - (positions[..., 1] - FLOOR_Y)


_RUNS = {}


def floor_run(n=20):
    if n not in _RUNS:
        model = floor_model(n)
        _RUNS[n] = model, rodmol.simulate(model, 3.0, initial="straight", output_dt=0.01)
    return _RUNS[n]


def test_cantilever_comes_to_rest_on_the_floor():
    model, result = floor_run()
    assert result.success, result.message
    depth = penetration(result.integrated_positions)
    touch = int(np.argmax(depth.max(axis=1) > 0.0))
    assert touch > 0  # it starts straight, above the floor, and falls onto it
    # At rest: no velocity left, the tip props on the floor (a propped
    # cantilever: the rest of the rod stays above it).
    assert np.max(np.abs(result.velocity[-1])) < 1e-5
    resting = depth[-1] > 0.0
    assert resting[-1]
    # The floor carries the reaction of a propped cantilever whose tip sits
    # 1 cm below the clamp: P = (q L^4 / (8 EI) - 1 cm) 3 EI / L^3 (beam theory).
    reaction = np.sum(result.external_force[-1, :, 1] * result.node_length)
    expected = (WEIGHT * L**4 / (8 * EI) - (-FLOOR_Y - R)) * 3 * EI / L**3
    print(f"floor reaction {reaction:.4f} N, beam theory {expected:.4f} N")
    assert abs(reaction - expected) < 0.1 * expected
    # Penetration, as the contact law sees it: below 1% of the radius at rest;
    # the impact briefly goes deeper (2% of r measured).
    worst = np.max(depth[touch:])
    rebuilt = np.max(penetration(result.positions[-1]))
    print(f"penetration: integrated {np.max(depth[-1]):.2e} m at rest, {worst:.2e} m worst after touch "
          f"({worst / R:.2%} of r); rebuilt positions at rest {rebuilt:.2e} m ({rebuilt / R:.2%} of r)")
    assert np.max(depth[-1]) < 0.01 * R
    assert worst < 0.05 * R
    # The rebuilt centreline drifts from the integrated one by O(ds^2) during the fall.
    assert rebuilt < 0.05 * R


def test_energy_never_increases_after_touch():
    model, result = floor_run()
    e = rodmol.energy(model, result)
    total = e["total"]
    depth = penetration(result.integrated_positions)
    touch = int(np.argmax(depth.max(axis=1) > 0.0))
    rise = np.max(np.diff(total[touch - 1:]))
    drop = total[0] - total[-1]
    print(f"energy: released {drop:.3e} J, largest rise after touch {rise:.1e} J "
          f"({rise / drop:.1e} of it); contact energy at rest {e['contact'][-1]:.2e} J")
    assert drop > 0 and e["contact"][-1] > 0
    assert rise < 1e-7 * drop  # measured 1.4e-8 at the default rtol


def test_equilibrium_on_the_floor_is_the_rest_of_the_dynamics():
    """The equilibrium is a rest state of the dynamics and agrees with the
    long-time rest reached from the straight rod, up to the drift of the
    integrated positions during the fall."""
    differences = []
    for n in (10, 20, 40):
        model, result = floor_run(n)
        assert result.success, result.message
        lay = rodmol.StateLayout(n)
        y_eq = rodmol.equilibrium(model)
        u_eq = lay.field(y_eq, "u")
        # The tip rests on the floor in both, at the same height.
        assert abs(u_eq[-1, 1] - result.integrated_positions[-1, -1, 1]) < 1e-6
        assert 0 < penetration(u_eq[-1]) < 0.01 * R
        differences.append(np.max(np.abs(u_eq - result.integrated_positions[-1, 1:])))
    print("max |u_equilibrium - u_rest| for N = 10, 20, 40:", ", ".join(f"{d:.2e}" for d in differences))
    # The centred scheme's drift is O(ds^2) and below the time error here:
    # measured 1.6e-7, 2.1e-7, 2.9e-8 m (the upwind scheme's: 1e-3 L, halving).
    assert max(differences) < 2e-6 * L

    # Started at the equilibrium, the dynamics stay there.
    model = floor_model(20)
    y_eq = rodmol.equilibrium(model)
    system = rodmol.SemiDiscrete(model)
    rates = system(0.0, y_eq)
    lay = rodmol.StateLayout(20)
    accel = np.max(np.abs(lay.field(rates, "v")))
    assert accel < 1e-6 * 9.81, accel
    still = rodmol.simulate(model, 0.5, initial=y_eq, output_dt=0.05)
    drift = np.max(np.abs(still.integrated_positions - still.integrated_positions[0]))
    print(f"from the equilibrium: acceleration {accel:.1e} m/s^2, drift {drift:.1e} m in 0.5 s")
    assert drift < 1e-7


SLIP_SPEED = 1e-5  # m/s


def tilted_plane_run(angle, friction=0.5, t_end=1.0):
    """The rod along x on a plane through the x axis tilted by ``angle`` about x
    (straight rod just touching); returns the lateral (downhill, in-plane)
    displacement of the tip over time."""
    normal = np.array([0.0, np.cos(angle), np.sin(angle)])
    downhill = np.array([0.0, -np.sin(angle), np.cos(angle)])
    plane = rodmol.PlaneContact(-R * normal, normal, friction=friction, slip_speed=SLIP_SPEED, **LAW)
    model = rodmol.Model(_rod(), 20, medium="air", loads=[plane])
    result = rodmol.simulate(model, t_end, initial="straight", output_dt=0.01)
    assert result.success, result.message
    u = result.integrated_positions
    # It stays on the plane, barely penetrating.
    assert np.max(-(u[-1, 1:] @ normal)) < 0.01 * R
    return u[:, -1] @ downhill


@pytest.mark.parametrize("friction", [0.5])
def test_tilted_plane_stick_and_slip(friction):
    stick_angle, slip_angle = np.arctan(0.6 * friction), np.arctan(2.0 * friction)
    stick = tilted_plane_run(stick_angle, friction)
    slip = tilted_plane_run(slip_angle, friction)
    # Cantilever deflection under the net lateral load while sliding, and
    # under the whole lateral weight (no friction).
    net = WEIGHT * (np.sin(slip_angle) - friction * np.cos(slip_angle)) * L**4 / (8 * EI)
    free_stick = WEIGHT * np.sin(stick_angle) * L**4 / (8 * EI)
    print(f"stick (tan a = {np.tan(stick_angle):.2f}): lateral tip displacement {stick[-1]:.2e} m "
          f"(frictionless: {free_stick:.2e} m); slip (tan a = {np.tan(slip_angle):.2f}): "
          f"{slip[-1]:.2e} m, net-load deflection {net:.2e} m")
    assert abs(stick[-1]) < 0.02 * free_stick
    # Stuck, the regularised law creeps at the speed where mu N v / sqrt(v^2 + v_s^2)
    # meets the demand tan(a) N: v = v_s d / sqrt(1 - d^2), d = tan(a) / mu = 0.6.
    demand = np.tan(stick_angle) / friction
    creep = (stick[-1] - stick[50]) / 0.5  # over the last half second
    expected = SLIP_SPEED * demand / np.sqrt(1.0 - demand**2)
    print(f"creep {creep:.2e} m/s, regularised law {expected:.2e} m/s")
    assert 0.8 * expected < creep < 1.25 * expected
    # Sliding from rest, the rod overshoots the net-load deflection (up to twice
    # it without viscosity) and sticks there: between the two.
    assert net < slip[-1] < 2.2 * net
    assert slip[-1] > 100 * abs(stick[-1])
