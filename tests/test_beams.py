"""Classical beams: a steel cantilever under its weight and a tip force
(static deflection, then the free vibration after release, against
Euler-Bernoulli) and a shear-soft Timoshenko beam.

rodmol's shear stiffness is G A with no shear-correction factor, so the
Timoshenko reference uses kappa = 1.
"""

import numpy as np
import pytest

import rodmol
from rodmol.discretise.system import SemiDiscrete
from rodmol.result import from_states


def tip_of(model, y):
    return from_states(SemiDiscrete(model), np.array([0.0]), y[None], True, "", {}).tip[0]


# Steel cantilever, 0.5 m x 1 mm radius, in air (no fluid loads).
E, G, RADIUS, LENGTH, RHO = 200e9, 80e9, 1e-3, 0.5, 8000.0
J = np.pi * RADIUS**4 / 4.0
A = np.pi * RADIUS**2
WEIGHT = RHO * A * 9.81  # [N/m]
TIP_FORCE = 0.196


def steel(n, *loads, mu=0.0):
    rod = rodmol.Rod(LENGTH, RADIUS, rodmol.Material(E, rho=RHO, G=G, mu=mu))
    return rodmol.Model(rod, n, loads=list(loads))


@pytest.mark.parametrize("scheme", ["upwind", "centred"])
def test_steel_cantilever_static_deflection(elastica, observed_orders, scheme):
    euler_bernoulli = TIP_FORCE * LENGTH**3 / (3 * E * J) + WEIGHT * LENGTH**4 / (8 * E * J)
    # The tip deflects by 13% of L: the elastica is 1.6% below the linear theory.
    (_, y_ref), _ = elastica(LENGTH, E * J, E * A, G * A, TIP_FORCE, weight=WEIGHT)
    nonlinear = -y_ref
    assert abs(nonlinear / euler_bernoulli - 1.0) < 0.02
    force = rodmol.PointForce(LENGTH, (0.0, -TIP_FORCE, 0.0))
    deflection = {n: -tip_of(m, rodmol.equilibrium(m, scheme=scheme))[1] for n in (15, 30, 60)
                  for m in [steel(n, force)]}
    errors = [abs(deflection[n] / nonlinear - 1.0) for n in (15, 30, 60)]
    orders = observed_orders(errors)
    if scheme == "upwind":
        assert np.all((orders > 0.7) & (orders < 1.5)), (errors, orders)
        assert errors[-1] < 0.015  # measured 4.2%, 2.0%, 1.0%
        assert abs(deflection[60] / euler_bernoulli - 1.0) < 0.035  # measured 2.6%
        richardson = 2.0 * deflection[60] - deflection[30]
    else:
        assert np.all((orders > 1.8) & (orders < 2.3)), (errors, orders)
        assert errors[-1] < 1e-4  # measured 0.088%, 0.022%, 0.0055%
        richardson = (4.0 * deflection[60] - deflection[30]) / 3.0
    # measured 0.03% (upwind), 4e-10 (centred)
    assert abs(richardson / nonlinear - 1.0) < (0.003 if scheme == "upwind" else 1e-6)
    assert abs(richardson / euler_bernoulli - 1.0) < 0.02  # measured 1.5%


def test_steel_cantilever_released_vibrates_at_first_bending_frequency():
    """Static under weight + tip force, then the force is removed: the tip
    oscillates about the weight-only equilibrium at the first bending mode,
    f1 = 1.875^2 / (2 pi) sqrt(EI / (rho A L^4)) = 5.595 Hz."""
    n = 30
    loaded = steel(n, rodmol.PointForce(LENGTH, (0.0, -TIP_FORCE, 0.0)), mu=1e4)
    released = steel(n, mu=1e4)
    y0 = rodmol.equilibrium(loaded)
    rest = tip_of(released, rodmol.equilibrium(released))[1]
    res = rodmol.simulate(released, 0.5, initial=y0, output_dt=1e-3, rtol=1e-4, max_order=2)
    assert res.success, res.message
    y = res.tip[:, 1] - rest
    t = res.t
    i = np.flatnonzero(np.sign(y[:-1]) != np.sign(y[1:]))
    crossings = t[i] - y[i] * (t[i + 1] - t[i]) / (y[i + 1] - y[i])
    assert len(crossings) >= 5
    # Least-squares slope of crossing times = half the period.
    period = 2.0 * np.polyfit(np.arange(len(crossings)), crossings, 1)[0]
    f1 = 1.875**2 / (2 * np.pi) * np.sqrt(E * J / (RHO * A * LENGTH**4))
    assert abs(period * f1 - 1.0) < 0.02, (period, 1.0 / f1)  # measured -0.04%
    # The amplitude is the static tip deflection due to the tip force.
    assert abs(np.max(np.abs(y)) / abs(tip_of(loaded, y0)[1] - rest) - 1.0) < 0.05


def test_timoshenko_beam_tip_deflection(observed_orders):
    """L = 3 m, r = 0.25 m, E = 1 MPa, G = 10 kPa (G = E / 100): shear gives a
    third of the deflection. Linear Timoshenko, kappa = 1 (rodmol's G A)."""
    length, radius, e, g, force = 3.0, 0.25, 1e6, 1e4, 15.0
    i, a = np.pi * radius**4 / 4.0, np.pi * radius**2
    bending = force * length**3 / (3 * e * i)
    reference = bending + force * length / (g * a)
    assert reference > 1.5 * bending
    rod = rodmol.Rod(length, radius, rodmol.Material(e, rho=5000.0, G=g))
    errors = []
    for n in (10, 20, 40):
        model = rodmol.Model(rod, n, gravity=(0.0, 0.0, 0.0),
                             loads=[rodmol.PointForce(length, (0.0, -force, 0.0))])
        errors.append(abs(-tip_of(model, rodmol.equilibrium(model))[1] / reference - 1.0))
    orders = observed_orders(errors)
    assert np.all((orders > 0.7) & (orders < 1.5)), (errors, orders)
    assert errors[-1] < 0.02, errors  # measured 5.1%, 2.5%, 1.3%
