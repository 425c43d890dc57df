"""Point loads against independent solutions: cantilevers under dead and
follower tip forces (Euler-Bernoulli for small loads, a planar Reissner
elastica solved with ``scipy.integrate.solve_bvp`` for large ones) and the
pure tip moment that rolls a straight rod into a circle.

Both schemes are checked at their order: the errors of the paper's upwind
scheme halve as N doubles, those of the centred scheme quarter (observed
order over N = 10, 20, 40).

The reference solutions come from the ``elastica`` fixture (tests/conftest.py).
"""

import numpy as np
import pytest

import rodmol
from rodmol.discretise.system import SemiDiscrete
from rodmol.result import from_states

L, R, E, NU, RHO = 1.0, 0.01, 1.0e6, 0.5, 1000.0
EI = E * np.pi * R**4 / 4.0
EA = E * np.pi * R**2
GA = E / (2.0 * (1.0 + NU)) * np.pi * R**2
NS = (10, 20, 40)


SCHEMES = [("upwind", 1), ("centred", 2)]


def static_result(model, scheme="centred"):
    """The equilibrium of ``model`` as a one-frame Result."""
    system = SemiDiscrete(model, scheme)
    y = rodmol.equilibrium(system)
    return from_states(system, np.array([0.0]), y[None], True, "", {})


def assert_order(observed, order):
    assert np.all((observed > order - 0.3) & (observed < order + 0.5)), observed


def cantilever(n, *loads, gravity=(0.0, 0.0, 0.0)):
    rod = rodmol.Rod(L, R, rodmol.Material(E, NU, rho=RHO))
    return rodmol.Model(rod, n, gravity=gravity, loads=list(loads))


@pytest.mark.parametrize("scheme, order", SCHEMES)
def test_small_dead_tip_force_matches_euler_bernoulli_with_shear(observed_orders, scheme, order):
    force = 1e-3 * EI / L**2
    reference = force * L**3 / (3 * EI) + force * L / GA
    errors = []
    for n in NS:
        tip = static_result(cantilever(n, rodmol.PointForce(L, (0.0, -force, 0.0))), scheme).positions[0, -1]
        errors.append(abs(-tip[1] - reference) / reference)
    assert_order(observed_orders(errors), order)
    # measured at N = 40: 1.9% (upwind), 0.016% (centred)
    assert errors[-1] < (0.025 if order == 1 else 3e-4), errors


@pytest.mark.parametrize("scheme, order", SCHEMES)
@pytest.mark.parametrize("frame", ["global", "local"])
def test_large_tip_force_matches_elastica(frame, elastica, observed_orders, scheme, order):
    """F L^2 / EI = 2: the tip deflects by about half the length."""
    force = 2.0 * EI / L**2
    ref_tip, ref_angle = elastica(L, EI, EA, GA, force, follower=frame == "local")
    errors = []
    for n in NS:
        res = static_result(cantilever(n, rodmol.PointForce(L, (0.0, -force, 0.0), frame=frame)), scheme)
        errors.append(np.linalg.norm(res.positions[0, -1, :2] - ref_tip) / L)
    print(f"{scheme}, {frame}: errors/L {errors}")
    assert_order(observed_orders(errors), order)
    # measured at N = 40: 0.8% (dead), 0.6% (follower) upwind; 0.007%, 0.017% centred
    assert errors[-1] < (0.015 if order == 1 else 5e-4), errors
    assert abs(ref_tip[1]) > 0.3 * L
    # The rod lies in the x-y plane.
    assert np.max(np.abs(res.positions[0, :, 2])) < 1e-12
    # The applied force, as the result records it in the global frame.
    f_tip = res.external_force[0, -1] * res.node_length[-1]
    if frame == "global":
        np.testing.assert_allclose(f_tip, [0.0, -force, 0.0], atol=1e-12 * force)
    else:  # follower: perpendicular to the tip section's axis, along its -d2
        d1, d2 = res.rotations[0, -1][:, 0], res.rotations[0, -1][:, 1]
        assert abs(f_tip @ d1) < 1e-10 * force
        np.testing.assert_allclose(f_tip @ d2, -force, rtol=1e-10)
        assert abs(np.arctan2(d1[1], d1[0]) - ref_angle) < 0.02


def test_follower_and_dead_tip_forces_differ(elastica):
    force = 2.0 * EI / L**2
    dead_ref, _ = elastica(L, EI, EA, GA, force)
    follower_ref, _ = elastica(L, EI, EA, GA, force, follower=True)
    n = 40
    dead = static_result(cantilever(n, rodmol.PointForce(L, (0.0, -force, 0.0)))).positions[0, -1, :2]
    follower = static_result(cantilever(n, rodmol.PointForce(L, (0.0, -force, 0.0), frame="local")))
    follower = follower.positions[0, -1, :2]
    gap = np.linalg.norm(dead_ref - follower_ref)
    assert gap > 0.1 * L  # the references are 0.11 L apart
    # Each equilibrium is much closer to its own reference than to the other one.
    assert np.linalg.norm(dead - dead_ref) < 0.1 * gap
    assert np.linalg.norm(follower - follower_ref) < 0.1 * gap
    assert np.linalg.norm(dead - follower_ref) > 0.9 * gap


@pytest.mark.parametrize("frame", ["local", "global"])
@pytest.mark.parametrize("n", [20, 40])
def test_tip_moment_rolls_rod_into_circle(frame, n):
    """M = 2 pi EI / L about z: a closed circle of radius L / (2 pi)."""
    moment = 2.0 * np.pi * EI / L
    res = static_result(cantilever(n, rodmol.PointMoment(L, (0.0, 0.0, moment), frame=frame)))
    ds = L / n
    pos = res.positions[0]
    assert np.linalg.norm(pos[-1]) < ds  # measured: round-off (~1e-16 m)
    # Every strain node (0..N-1) carries the curvature M / EI about z.
    k = res.curvature[0, :-1]
    np.testing.assert_allclose(k[:, 2], moment / EI, rtol=1e-6)
    np.testing.assert_allclose(k[:, :2], 0.0, atol=1e-9 / L)
    # The nodes are the vertices of a regular N-gon of side ds (the chords of
    # the rebuilt centreline), inscribed in a circle through the base centred
    # on the y axis, whose radius tends to L / (2 pi) at second order in ds.
    polygon = ds / (2.0 * np.sin(np.pi / n))
    dist = np.linalg.norm(pos - [0.0, polygon, 0.0], axis=1)
    np.testing.assert_allclose(dist, polygon, rtol=1e-6)
    radius = L / (2.0 * np.pi)
    assert abs(polygon / radius - 1.0) < 0.2 * (np.pi / n) ** 2
