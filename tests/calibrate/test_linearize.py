"""Linearisation: A and B against finite differences of the system; the
reduced and sampled forms against the full linear model."""

from dataclasses import replace

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import rodmol
from rodmol.calibrate import linearize
from rodmol.solve.tension_statics import tension_sensitivity


@pytest.fixture(scope="module")
def bent():
    """The paper's arm (N = 8) bent by cable 11 at 1.5 N and moving: its
    equilibrium with velocities added (so that drag, added mass and the
    gyroscopic terms are linearised too)."""
    model = rodmol.paper_arm(8, tensions={11: 1.5, 3: 0.0})
    system = rodmol.SemiDiscrete(model)
    y = rodmol.equilibrium(model).copy()
    rng = np.random.default_rng(0)
    system.layout.field(y, "v")[:] = 0.05 * rng.standard_normal((8, 3))
    system.layout.field(y, "w")[:] = 0.5 * rng.standard_normal((8, 3))
    return model, y


def central(f, x, h):
    cols = []
    for j in range(len(x)):
        e = np.zeros(len(x))
        e[j] = h[j]
        cols.append((f(x + e) - f(x - e)) / (2 * h[j]))
    return np.column_stack(cols)


@pytest.mark.parametrize("friction", [0.0, 0.3])
def test_state_jacobian_matches_central_differences(bent, friction):
    """With friction the tension along the cable depends on the sliding
    velocities, a coupling the linearisation must keep."""
    model, y = bent
    if friction:
        model = model.replace(cables=[replace(c, friction=friction, slip_speed=0.05) for c in model.cables])
    a, _ = linearize(model, y, 0.3)
    system = rodmol.SemiDiscrete(model)
    reference = central(lambda x: system(0.3, x), y, 1e-6 * system.atol_scale())
    scale = np.abs(reference).max()
    assert np.max(np.abs(a - reference)) < 1e-5 * scale


def test_input_jacobian_matches_models_with_other_tensions(bent):
    """Column j of B is d f / d T_j, found here from separate models whose cable j
    pulls 0.1 N more and less (cable 3 is slack in the model itself)."""
    model, y = bent
    _, b = linearize(model, y, 0.3)
    assert b.shape == (y.size, 12)
    for j in (2, 10):
        rates = []
        for dt in (0.1, -0.1):
            tensions = {11: 1.5 + (dt if j == 10 else 0.0), 3: 0.0 + (dt if j == 2 else 0.0)}
            if tensions[3] < 0:
                tensions[3] = 0.0
            rates.append(rodmol.SemiDiscrete(rodmol.paper_arm(8, tensions=tensions))(0.3, y))
        step = 0.2 if j == 10 else 0.1  # cable 3 cannot go below 0 N: forward difference
        reference = (rates[0] - rates[1]) / step
        assert np.max(np.abs(b[:, j] - reference)) < 1e-6 * np.abs(reference).max()
    assert np.max(np.abs(b[:, 2])) > 0.0  # a slack cable still has its input column


def test_tendon_stiffness_is_in_a_and_displacement_columns_match():
    """A displacement-controlled cable: A holds its actuator position, so it is
    the Jacobian of the model's own right-hand side (the tendon law reads the
    path length); its column is d f / d z, from models with the actuator moved."""
    def arm(z):
        cables = [replace(c, tension=None, displacement=z, compliance=2e-3) if c.name == "cable 12" else c
                  for c in rodmol.paper_arm(8).cables]
        return rodmol.paper_arm(8, tensions={11: 1.0}).replace(cables=cables)

    model = arm(-0.01)
    y = rodmol.equilibrium(model)
    system = rodmol.SemiDiscrete(model)
    assert system.tensions(0.0, y)[11] > 0.05  # the tendon is taut
    lin = linearize(model, y)
    assert lin.inputs[-1] == "cable 12 displacement [m]" and lin.B.shape == (y.size, 13)
    assert lin.u0[-1] == -0.01 and list(lin.bounds[-1]) == [-np.inf, np.inf]
    assert lin.u0[11] == pytest.approx(system.tensions(0.0, y)[11], rel=1e-12)  # the tendon's own pull
    reference = central(lambda x: system(0.0, x), y, 1e-6 * system.atol_scale())
    assert np.max(np.abs(lin.A - reference)) < 1e-6 * np.abs(reference).max()
    dz = 1e-5
    column = (rodmol.SemiDiscrete(arm(-0.01 + dz))(0.0, y) - rodmol.SemiDiscrete(arm(-0.01 - dz))(0.0, y)) / (2 * dz)
    assert np.max(np.abs(lin.B[:, -1] - column)) < 1e-6 * np.abs(column).max()


def test_point_load_columns_match_models_with_other_loads(bent):
    """One column per component of each point load, in the load's frame: a dead
    force at the tip and a follower moment at L2, against models whose load
    component is 0.1 N (N m) larger and smaller."""
    _, y = bent

    def arm(force, moment):
        return rodmol.paper_arm(8, tensions={11: 1.5}, loads=[
            rodmol.PointForce(0.418, force, name="tip force"),
            rodmol.PointMoment(0.203, moment, frame="local", name="twist")])

    force, moment = np.array([0.0, 0.02, 0.01]), np.array([0.001, 0.0, 0.002])
    lin = linearize(arm(force, moment), y, 0.3)
    assert lin.inputs[12:] == ("tip force x [N]", "tip force y [N]", "tip force z [N]",
                               "twist x [N m]", "twist y [N m]", "twist z [N m]")
    np.testing.assert_array_equal(lin.u0[12:], np.concatenate([force, moment]))  # in each load's frame
    for j, (f, mo) in enumerate([(e, 0 * e) for e in np.eye(3)] + [(0 * e, e) for e in np.eye(3)]):
        up = rodmol.SemiDiscrete(arm(force + 0.1 * f, moment + 0.1 * mo))(0.3, y)
        down = rodmol.SemiDiscrete(arm(force - 0.1 * f, moment - 0.1 * mo))(0.3, y)
        reference = (up - down) / 0.2
        assert np.max(np.abs(lin.B[:, 12 + j] - reference)) < 1e-6 * np.abs(reference).max()


@pytest.fixture(scope="module")
def hanging():
    """The linearisation of the paper's arm (N = 8) at rest, pulled by cable 11."""
    model = rodmol.paper_arm(8, tensions={11: 1.0})
    return model, linearize(model, "equilibrium")


def test_zero_order_hold_matches_the_linear_ode_over_one_period(hanging):
    """x(dt) of dx/dt = A x + B u with u held against A_d x0 + B_d u: for the
    reduced tip model integrated by BDF, and for the whole state (stiff: rates
    up to 6e4 1/s) from its modes, x(dt) = V (e^(L dt) W x0 + (e^(L dt) - 1) / L W B u)."""
    _, lin = hanging
    dt = 0.02
    rng = np.random.default_rng(1)
    reduced = lin.reduced(output="tip", order=16)
    x0 = 1e-3 * rng.standard_normal(reduced.A.shape[0])
    u = rng.standard_normal(lin.B.shape[1])
    exact = solve_ivp(lambda _, x: reduced.A @ x + reduced.B @ u, (0.0, dt), x0, method="BDF", jac=reduced.A,
                      rtol=1e-10, atol=1e-14).y[:, -1]
    sampled = reduced.discretize(dt)
    assert sampled.dt == dt
    assert np.max(np.abs(sampled.A @ x0 + sampled.B @ u - exact)) < 1e-8 * np.abs(exact).max()

    x0 = 1e-3 * rng.standard_normal(lin.A.shape[0])
    lam, right, left = lin.modes()
    held = np.where(np.abs(lam) * dt > 1e-12, np.expm1(lam * dt) / np.where(lam == 0, 1, lam), dt)
    exact = (right @ (np.exp(lam * dt) * (left @ x0) + held * (left @ (lin.B @ u)))).real
    sampled = lin.discretize(dt)
    assert np.max(np.abs(sampled.A @ x0 + sampled.B @ u - exact)) < 1e-8 * np.abs(exact).max()


def test_reduced_model_keeps_the_tips_step_response_and_static_gain(hanging):
    """16 states: the tip's response to a step of cable 11 within 5% of the full
    model's largest excursion over 4 s (measured 2-3%); its static gain that of
    all the modes the inputs drive (the static correction), and within 1% of
    the static sensitivity of the equilibrium (implicit-function theorem, an
    independent path). Not closer: the dynamics integrate the orientations,
    and their rest states keep the scheme's O(ds^2) drift from the static
    compatibility (0.46%, 0.14%, 0.036% at N = 8, 16, 32)."""
    model, lin = hanging
    reduced = lin.reduced(output="tip", order=16)
    assert reduced.A.shape[0] in (16, 17) and reduced.outputs == ("tip x [m]", "tip y [m]", "tip z [m]")
    full = lin.output("tip")
    responses = []
    for sampled in (full.discretize(0.01), reduced.discretize(0.01)):
        x, u, out = np.zeros(sampled.A.shape[0]), np.eye(sampled.B.shape[1])[10], []
        for _ in range(400):
            x = sampled.A @ x + sampled.B @ u
            out.append(sampled.C @ x + sampled.D @ u)
        responses.append(np.array(out))
    assert np.max(np.abs(responses[1] - responses[0])) < 0.05 * np.abs(responses[0]).max()
    system = rodmol.SemiDiscrete(rodmol.discretise.hand_tensions.tensions_by_hand(model))
    exact = tension_sensitivity(system, lin.state, model.tensions(0.0))[system.layout.tip_slice("u")]
    scale = np.abs(exact).max()
    assert np.allclose(reduced.static_gain(), lin.reduced(output="tip").static_gain(), atol=1e-9 * scale)
    assert np.allclose(reduced.static_gain(), exact, atol=1e-2 * scale)


def test_linear_model_inputs_are_checked(hanging):
    _, lin = hanging
    with pytest.raises(rodmol.ParameterError, match="`order`"):
        lin.reduced(output="tip", order=0)
    with pytest.raises(rodmol.ParameterError, match="did you mean 'tip'"):
        lin.output("tipp")
    with pytest.raises(rodmol.ParameterError, match="`dt`"):
        lin.discretize(-0.01)
    with pytest.raises(rodmol.ParameterError, match="already sampled"):
        lin.discretize(0.01).discretize(0.01)


def test_linear_step_response_is_the_nonlinear_one_to_first_order(hanging):
    """Cable 11 stepped by du from the equilibrium, simulated for 1 s, against the
    sampled linear model's tip: the difference is second order in du (observed
    order 1.85 between du = 0.01 and 0.04 N; quadratic drag has no linear part
    at rest, so it is all in the difference)."""
    model, lin = hanging
    sampled = lin.output("tip").discretize(0.01)
    errors = []
    for du in (0.01, 0.04):
        run = rodmol.simulate(rodmol.paper_arm(8, tensions={11: 1.0 + du}), 1.0, initial=lin.state, output_dt=0.01,
                              rtol=1e-8)
        x, u, linear = np.zeros(sampled.A.shape[0]), du * np.eye(12)[10], [np.zeros(3)]
        for _ in range(len(run.t) - 1):
            x = sampled.A @ x + sampled.B @ u
            linear.append(sampled.C @ x)
        errors.append(np.max(np.abs(run.tip - run.tip[0] - np.array(linear))))
    assert 1.6 < np.log(errors[1] / errors[0]) / np.log(4.0) < 2.4


@pytest.fixture(scope="module")
def swinging():
    """The paper's arm (N = 8) 0.1 s after cable 11 pulled 1 N from rest without tension: a
    state in motion (not an equilibrium), and its linearisation there."""
    model = rodmol.paper_arm(8, tensions={11: 1.0})
    rest = rodmol.equilibrium(rodmol.paper_arm(8))
    y = rodmol.simulate(model, 0.1, initial=rest, output_dt=0.05).states[-1]
    return model, y, linearize(model, y, 0.1)


def test_drift_is_the_rates_at_the_operating_point_and_vanishes_at_an_equilibrium(swinging, hanging):
    model, y, lin = swinging
    rates = rodmol.SemiDiscrete(model)(0.1, y)
    np.testing.assert_array_equal(lin.f0, rates)
    scale = np.abs(rates).max()
    assert scale > 10.0  # in motion
    assert np.abs(hanging[1].f0).max() < 1e-12 * scale  # measured 2e-16
    # the operating point's inputs, their bounds and the tip there
    np.testing.assert_array_equal(lin.u0, np.eye(12)[10])
    np.testing.assert_array_equal(lin.bounds, np.tile([0.0, np.inf], (12, 1)))  # cables only pull
    tip = lin.output("tip")
    np.testing.assert_array_equal(tip.y0, rodmol.SemiDiscrete(model).state_view(0.1, y).tip)
    c = np.eye(y.size)[:2]
    np.testing.assert_array_equal(lin.output(c).y0, y[:2])
    reduced = lin.reduced(output="tip", order=16)
    np.testing.assert_allclose(reduced.f0, reduced.projection @ lin.f0)
    np.testing.assert_array_equal(reduced.y0, tip.y0)
    np.testing.assert_allclose(reduced.coordinates(y), 0.0, atol=0.0)


def test_affine_model_predicts_the_motion_about_a_state_in_motion(swinging):
    """From the moving state, cable 5 stepped to 0.2 N: the sampled affine model's tip over
    5 periods of 10 ms against simulate, and against the same model without its drift
    (the motion it is in): measured 30-50 times closer."""
    model, y, lin = swinging
    sampled = lin.output("tip").discretize(0.01)
    run = rodmol.simulate(rodmol.paper_arm(8, tensions={11: 1.0, 5: 0.2}), 0.15, initial=y, t0=0.1,
                          output_dt=0.01, rtol=1e-8)
    u = 0.2 * np.eye(12)[4]
    errors = []
    for drift in (sampled.f0, 0.0 * sampled.f0):
        x, tips = np.zeros(y.size), [sampled.y0]
        for _ in range(len(run.t) - 1):
            x = sampled.A @ x + sampled.B @ u + drift
            tips.append(sampled.y0 + sampled.C @ x + sampled.D @ u)
        errors.append(np.max(np.abs(np.array(tips) - run.tip)[1:], axis=1))
    assert np.max(np.abs(run.tip - run.tip[0])) > 0.005  # it moved 5 mm or more
    assert np.all(errors[0] < 0.1 * errors[1]), errors


def test_zero_order_hold_of_the_drift_matches_the_affine_ode(swinging):
    """x(dt) of dx/dt = A x + B u + f0 with u held, against the sampled A x0 + B u + f0:
    the reduced tip model by BDF (scipy's solve_ivp), the whole state from its modes."""
    _, _, lin = swinging
    dt = 0.02
    rng = np.random.default_rng(2)
    reduced = lin.reduced(output="tip", order=16)
    x0 = 1e-3 * rng.standard_normal(reduced.A.shape[0])
    u = rng.standard_normal(lin.B.shape[1])
    exact = solve_ivp(lambda _, x: reduced.A @ x + reduced.B @ u + reduced.f0, (0.0, dt), x0, method="BDF",
                      jac=reduced.A, rtol=1e-10, atol=1e-14).y[:, -1]
    sampled = reduced.discretize(dt)
    assert np.max(np.abs(sampled.A @ x0 + sampled.B @ u + sampled.f0 - exact)) < 1e-8 * np.abs(exact).max()

    x0 = 1e-3 * rng.standard_normal(lin.A.shape[0])
    lam, right, left = lin.modes()
    held = np.where(np.abs(lam) * dt > 1e-12, np.expm1(lam * dt) / np.where(lam == 0, 1, lam), dt)
    exact = (right @ (np.exp(lam * dt) * (left @ x0) + held * (left @ (lin.B @ u + lin.f0)))).real
    sampled = lin.discretize(dt)
    assert np.max(np.abs(sampled.A @ x0 + sampled.B @ u + sampled.f0 - exact)) < 1e-8 * np.abs(exact).max()
