"""The fixed-step generalized-alpha backend: agreement with CVODE on a damped
rod, second order in time, energy kept at rho_inf = 1 and removed below, the
steel cantilever's first period against Euler-Bernoulli, failures and bad
options."""

import warnings

import numpy as np
import pytest

import rodmol
from rodmol.solve.galpha import coefficients

# A soft damped rod (first bending period about 0.9 s), small enough for tight references.
SOFT = dict(length=0.2, radius=0.005, E=1e6, nu=0.5, rho=1000.0)
# Till's steel cantilever (JohnDTill/ContinuumRobotExamples, 02_Dynamics).
STEEL = dict(length=0.5, radius=1e-3, E=200e9, G=80e9, rho=8000.0)
TIP_FORCE = 0.196  # N, transverse: the weight of Till's 20 g tip mass


def soft_model(mu, n=10, gravity=(0.0, -9.81, 0.0), loads=()):
    p = SOFT
    rod = rodmol.Rod(p["length"], p["radius"], rodmol.Material(p["E"], p["nu"], mu=mu, rho=p["rho"]))
    return rodmol.Model(rod, n, gravity=gravity, loads=loads)


def steel_models(n=40, mu=0.0):
    p = STEEL
    rod = rodmol.Rod(p["length"], p["radius"], rodmol.Material(p["E"], G=p["G"], mu=mu, rho=p["rho"]))
    free = rodmol.Model(rod, n)
    loaded = rodmol.Model(rod, n, loads=[rodmol.PointForce(p["length"], (0.0, -TIP_FORCE, 0.0))])
    return free, loaded


def test_coefficients_second_order_and_limits():
    # Jansen, Whiting and Hulbert (2000), rho_inf = 0.5: alpha_m = 5/6, alpha_f = gamma = 2/3.
    assert coefficients(0.5) == pytest.approx((5 / 6, 2 / 3, 2 / 3))
    assert coefficients(1.0) == pytest.approx((0.5, 0.5, 0.5))  # implicit midpoint
    assert coefficients(0.0) == pytest.approx((1.5, 1.0, 1.0))  # BDF2-like


def test_agrees_with_cvode_on_a_damped_rod():
    model = soft_model(mu=200.0)
    times = np.arange(0.0137, 1.0, 0.0137)  # not on the step grid: the interpolant is used
    ref = rodmol.simulate(model, 1.0, initial="straight", rtol=1e-9, output_times=times)
    run = rodmol.simulate(model, 1.0, initial="straight", backend="galpha", dt=1e-3, rho_inf=0.8,
                          output_times=times)
    assert run.success and run.stats["steps"] == 1000
    # O(dt^2): 2.8e-5 m at dt = 1 ms (1.1e-4 m at 2 ms, 6.7e-6 m at 0.5 ms)
    error = np.max(np.linalg.norm(run.tip - ref.tip, axis=1))
    assert error < 2e-4 * SOFT["length"], error
    assert np.ptp(ref.tip[:, 1]) > 0.1 * SOFT["length"]  # it really moved


@pytest.mark.parametrize("rho_inf", [1.0, 0.5])
def test_second_order_in_time(rho_inf):
    model = soft_model(mu=200.0)
    ref = rodmol.simulate(model, 0.5, initial="straight", rtol=1e-10, output_dt=0.5)
    errors, steps = [], (0.01, 0.005, 0.0025)
    for dt in steps:
        run = rodmol.simulate(model, 0.5, initial="straight", backend="galpha", dt=dt,
                              rho_inf=rho_inf, rtol=1e-7, output_dt=0.5)
        errors.append(np.linalg.norm(run.tip[-1] - ref.tip[-1]))
    order = np.polyfit(np.log(steps), np.log(errors), 1)[0]  # the pairwise orders scatter by 0.2
    assert 1.85 < order < 2.15, (errors, order)


def _released_energy(rho_inf, dt, t_end=1.0):
    """Total energy of the steel cantilever (N = 10, mu = 0, no gravity)
    released from a tip-force deflection."""
    p = STEEL
    rod = rodmol.Rod(p["length"], p["radius"], rodmol.Material(p["E"], G=p["G"], rho=p["rho"]))
    free = rodmol.Model(rod, 10, gravity=(0.0, 0.0, 0.0))
    loaded = rodmol.Model(rod, 10, gravity=(0.0, 0.0, 0.0),
                          loads=[rodmol.PointForce(p["length"], (0.0, -0.1, 0.0))])
    # The energy is kept up to the Newton tolerance: a tight rtol shows the scheme's own behaviour.
    run = rodmol.simulate(free, t_end, initial=rodmol.equilibrium(loaded), backend="galpha", dt=dt,
                          rho_inf=rho_inf, rtol=1e-7, output_dt=dt)
    assert run.success
    return rodmol.energy(free, run)["total"]


def test_midpoint_keeps_the_energy_without_drift():
    # The implicit midpoint rule keeps quadratic invariants exactly; the rod's
    # energy is nearly quadratic at this deflection: far below O(dt^2).
    for dt in (2e-3, 1e-3):
        energy = _released_energy(1.0, dt)
        deviation = np.abs(energy / energy[0] - 1.0)
        assert deviation.max() < 1e-5, (dt, deviation.max())
        tenth = len(energy) // 10  # no drift: the last tenth departs no more than 1e-5 either
        assert abs(np.mean(energy[-tenth:]) / energy[0] - 1.0) < 1e-5


def test_numerical_damping_removes_energy_monotonically():
    energy = _released_energy(0.5, 2e-3)
    assert np.all(np.diff(energy) <= 1e-7 * energy[0])
    assert energy[-1] < 0.995 * energy[0]  # 1.1% in 1 s
    # ... and more damping removes more
    assert _released_energy(0.0, 2e-3)[-1] < energy[-1]


def test_steel_cantilever_first_period_matches_euler_bernoulli():
    free, loaded = steel_models()
    p = STEEL
    ei, rho_a = p["E"] * np.pi * p["radius"]**4 / 4, p["rho"] * np.pi * p["radius"]**2
    period = 2 * np.pi / (1.8751**2 * np.sqrt(ei / rho_a) / p["length"]**2)  # 0.1787 s
    run = rodmol.simulate(free, 2.0, initial=rodmol.equilibrium(loaded), backend="galpha",
                          dt=2e-3, rho_inf=0.9, output_dt=2e-3)
    assert run.success
    assert rodmol.oscillation_period(run.t, run.tip[:, 1]) == pytest.approx(period, rel=5e-3)
    # the tip swings about the gravity equilibrium with the release amplitude: the
    # tip force's static deflection F L^3 / (3 EI) = 52 mm (measured 51 mm)
    amplitude = np.ptp(run.tip[:, 1]) / 2
    assert amplitude == pytest.approx(TIP_FORCE * p["length"]**3 / (3 * ei), rel=0.05)


def test_compiled_and_python_newton_loops_agree():
    free, loaded = steel_models(n=12)
    y0 = rodmol.equilibrium(loaded)
    a = rodmol.simulate(free, 0.2, initial=y0, backend="galpha", dt=2e-3)
    b = rodmol.simulate(free, 0.2, initial=y0, backend="galpha", dt=2e-3, python_loop=True)
    assert a.stats["newton_iters"] == b.stats["newton_iters"]
    np.testing.assert_allclose(a.states, b.states, rtol=0, atol=1e-9)


def test_a_failing_input_ends_the_run_with_its_message():
    def force(t):
        if t > 0.05:
            raise RuntimeError("sensor lost")
        return (0.0, -0.01, 0.0)

    model = soft_model(mu=200.0, loads=[rodmol.PointForce(SOFT["length"], force)])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        run = rodmol.simulate(model, 0.2, initial="straight", backend="galpha", dt=0.01)
    assert not run.success
    assert "generalized-alpha stopped" in run.message and "sensor lost" in run.message
    assert run.t[-1] == pytest.approx(0.05)
    assert isinstance(run.error, rodmol.UserFunctionError)


@pytest.mark.parametrize("option, value, words", [
    ("dt", 0.0, "`dt` must be > 0"),
    ("dt", "fast", "`dt` must be a number"),
    ("rho_inf", 1.5, "`rho_inf` must lie in [0, 1], got 1.5"),
    ("rho_inf", float("nan"), "`rho_inf` must be finite"),
    ("rhoinf", 0.5, "did you mean 'rho_inf'"),
    ("dt", 1e-9, "asks for 1e+09 steps"),
])
def test_bad_options_are_refused(option, value, words):
    model = soft_model(mu=200.0, n=4)
    with pytest.raises(rodmol.ParameterError) as info:
        rodmol.simulate(model, 1.0, initial="straight", backend="galpha", **{option: value})
    assert words in str(info.value)


def test_cvode_at_high_order_stalls_on_the_steel_rod_and_points_to_galpha():
    free, loaded = steel_models(n=20)
    with pytest.warns(RuntimeWarning, match="stalled"):
        run = rodmol.simulate(free, 1.0, initial=rodmol.equilibrium(loaded), max_order=5)
    assert not run.success and run.t[-1] < 0.05
    assert "backend='galpha'" in run.message and "stiff and lightly damped" in run.message


def test_a_step_whose_newton_iterations_fail_is_halved():
    # The paper's arm released from straight in water: the first 40 ms steps
    # (dt="auto", a hundredth of its first period) do not converge while the
    # drag switches on; they are halved, and the full step resumes after.
    model = rodmol.paper_arm(10, tensions={11: 0.5})
    run = rodmol.simulate(model, 0.2, initial="straight", backend="galpha")
    ref = rodmol.simulate(model, 0.2, initial="straight", rtol=1e-8)
    assert run.success and run.stats["halved_steps"] >= 1
    assert run.stats["h_min"] == pytest.approx(run.stats["dt"] / 2)
    assert run.stats["h_max"] == pytest.approx(run.stats["dt"])
    assert np.max(np.linalg.norm(run.tip - ref.tip, axis=1)) < 5e-3  # 1.2 mm at 40 ms steps
