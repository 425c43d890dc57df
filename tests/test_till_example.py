"""Till's tendon robot example (examples/till_tendon_robot.py) against an
independent solution of the same continuum model, and against Till's C++.

The robot bends in the global x-y plane of rodmol (Till's x-z plane). With
the tendon terminated at the tip, the total stress (backbone plus tendon)
balances gravity alone: the total force is n(s) = rho A g (L - s) and the
total moment obeys m' = -u' x n with m(L) = 0. At each s the backbone's
strains (q1, q2, kappa) then solve three algebraic equations

    EA (q1 - 1) + T c1 / |c| = n1,  GA q2 + T c2 / |c| = n2,
    EI kappa - p T c1 / |c| = m,    c = (q1 - kappa p, q2),

with n, m in the section's frame and p the tendon offset; the shape follows
from u' = R q, theta' = kappa. Shooting on (m(0), T) meets m(L) = 0 and the
tendon law (path + base_to_motor - l) = l C T, l = L + base_to_motor + z.
Integrated accurately this is the continuum; with forward Euler on Till's 200
points it reproduces his static tip.
"""

import importlib.util
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.optimize import fsolve

import rodmol

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "till_tendon_robot.py"
E, G, RADIUS, L, MASS = 207e9, 207e9 / 2.6, 0.00135 / 2, 0.7144, 0.034
AREA, J = np.pi * RADIUS**2, np.pi * RADIUS**4 / 4
WEIGHT = MASS / L * 9.81  # N/m, along -y
P, BASE_TO_MOTOR, COMPLIANCE = 0.01506, 0.0518, 1e-4
TILL_STATIC, HELD_Z = -0.1493, -0.01619


def _example():
    spec = importlib.util.spec_from_file_location("till_tendon_robot", EXAMPLE)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _strains(n, m, tension, guess):
    def residual(x):
        q1, q2, kappa = x
        c1, c2 = q1 - kappa * P, q2
        norm = np.hypot(c1, c2)
        return [(E * AREA * (q1 - 1) + tension * c1 / norm - n[0]) / (E * AREA),
                (G * AREA * q2 + tension * c2 / norm - n[1]) / (E * AREA),
                (E * J * kappa - P * tension * c1 / norm - m) / (E * J)]
    with warnings.catch_warnings():  # "no further improvement": converged to round-off
        warnings.simplefilter("ignore", RuntimeWarning)
        return fsolve(residual, guess, xtol=1e-12)


def _shoot(m0, tension, euler_points=None):
    """(u (2,), m(L), path length) of the shape with base moment m0 [N m]."""
    guess = [np.array([1.0, 0.0, 0.0])]

    def rhs(s, y):
        theta, m = y[2], y[3]
        c, sn = np.cos(theta), np.sin(theta)
        n_global = np.array([0.0, -WEIGHT * (L - s)])
        n_local = np.array([c * n_global[0] + sn * n_global[1], -sn * n_global[0] + c * n_global[1]])
        q1, q2, kappa = guess[0] = _strains(n_local, m, tension, guess[0])
        du = np.array([c * q1 - sn * q2, sn * q1 + c * q2])
        return np.array([du[0], du[1], kappa, -(du[0] * n_global[1] - du[1] * n_global[0]),
                         np.hypot(q1 - kappa * P, q2)])

    y = np.array([0.0, 0.0, 0.0, m0, 0.0])
    if euler_points is None:
        y = solve_ivp(rhs, (0.0, L), y, rtol=1e-10, atol=1e-13).y[:, -1]
    else:
        ds = L / (euler_points - 1)
        for j in range(euler_points - 1):
            y = y + ds * rhs(j * ds, y)
    return y[:2], y[3], y[4]


def reference_tip(z, euler_points=None):
    """Tip (x, y) [m] and tension [N] of the tendon robot with the motor at z [m]."""
    free = L + BASE_TO_MOTOR + z

    def residual(x):
        _, m_tip, length = _shoot(x[0], x[1], euler_points)
        return [m_tip * 1e3, (length + BASE_TO_MOTOR - free - free * COMPLIANCE * x[1]) * 1e3]

    m0, tension = fsolve(residual, [0.02, 3.0], xtol=1e-12)
    return _shoot(m0, tension, euler_points)[0], tension


@pytest.fixture(scope="module")
def robot():
    return _example().model(50)


def test_statics_match_the_continuum_and_explain_tills_number(robot):
    system = rodmol.SemiDiscrete(robot)
    for t, z in ((0.0, 0.0), (10.0, HELD_Z)):
        y = rodmol.equilibrium(system, t)
        tip = system.state_view(t, y).tip
        exact, tension = reference_tip(z)
        print(f"\nz = {1e3 * z:.2f} mm: rodmol N=50 tip {tip[:2]}, T = {system.tensions(t, y)[0]:.5f} N; "
              f"continuum {exact}, T = {tension:.5f} N; difference {1e3 * np.linalg.norm(tip[:2] - exact):.3f} mm")
        assert np.linalg.norm(tip[:2] - exact) < 1e-4  # 0.05-0.07 mm at N = 50 (second order)
        assert abs(tip[2]) < 1e-12
        if z == 0.0:
            assert abs(tip[1] - TILL_STATIC) < 2e-3  # the target (1.5 mm)
    # Till's C++ integrates the same equations by forward Euler on 200 points:
    # that first-order error is the whole 1.5 mm.
    euler, _ = reference_tip(0.0, euler_points=200)
    print(f"forward Euler on 200 points: static tip y {euler[1]:.5f} m (Till's C++ {TILL_STATIC} m)")
    assert abs(euler[1] - TILL_STATIC) < 2e-4


def test_example_runs_and_matches_till(tmp_path, monkeypatch, capsys):
    """The example's ``main`` in this process, with the command line it reads (the
    examples that run as commands are in tests/test_examples.py)."""
    monkeypatch.setattr(sys, "argv", [EXAMPLE.name, "--t-end", "10.5", "--plot", str(tmp_path / "f.png")])
    _example().main()
    stdout = capsys.readouterr().out
    static = float(stdout.split("static tip x:")[1].split("difference")[1].split("mm")[0])
    held = float(stdout.split("tip x at t = 10 s:")[1].split("difference")[1].split("mm")[0])
    print(stdout)
    assert abs(static) < 2.0
    # 2.7 mm: Till's BDF2 step (dt = 0.05 s) and his Euler grid move his
    # t = 10 s value by +5.8 and -2.9 mm (tests/test_till_reference.py,
    # solvers/results/till_reference.md).
    assert abs(held) < 3.0
    assert (tmp_path / "f.png").stat().st_size > 10_000


def test_cvode_stops_at_the_motor_knots_of_a_resting_robot():
    """The robot rests until the motor moves at 3.65 s; with outputs far
    apart CVODE's steps grow long and, without stopping at the inputs' knots,
    strode over the 0.3 s ramp (3 steps for 25 s: the motor never acted)."""
    robot = _example().model(20)
    result = rodmol.simulate(robot, 25.0, output_times=[0.0, 10.0, 25.0])
    assert result.success, result.message
    assert result.stats["steps"] > 100
    assert result.actuator_positions[1, 0] == HELD_Z
    # Held at z = -16.19 mm by t = 10 s: the tip has swung up from the static
    # -0.148 m to about 0.206 m (the example's trajectory), and is back down at 25 s.
    assert abs(result.tip[1, 1] - 0.2086) < 0.01  # Till's held tip x
    assert abs(result.tip[2, 1] - result.tip[0, 1]) < 0.01
