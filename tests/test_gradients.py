"""Adjoint gradients (rodmol.gradient) against central differences of the public simulate and
the loss, at tight tolerances, for each kind of parameter on the paper's arm and on a System;
against the forward sensitivities; the bounded checkpoints; what it refuses before any work."""

import numpy as np
import pytest
from gradient_cases import REFERENCE_RTOL, REFERENCE_STEP, RTOL, TARGETS, TIMES, _arm, _system, agree

import rodmol
from rodmol import named_parameters
from rodmol.errors import ParameterError


def _tip_loss(result, rod=None):
    tip = (result if rod is None else result[rod]).tip[np.searchsorted(result.t, TIMES)]
    return float(np.sum((tip - TARGETS) ** 2))


def reference(model, key, component, t_end, loss, **options):
    """d loss(simulate) / d p[component] by central differences of two runs."""
    p = named_parameters.parameter(model, key)
    h = REFERENCE_STEP * p.scale
    up, down = p.value.copy(), p.value.copy()
    up[component] += h
    down[component] -= h
    runs = [rodmol.simulate(p.at(model, v), t_end, rtol=REFERENCE_RTOL, output_times=TIMES, **options)
            for v in (up, down)]
    return (loss(runs[0]) - loss(runs[1])) / (2.0 * h)


ROD_KEYS = ["material.E", "medium.Cy,Cz", "tension.11", "material.mu"]


@pytest.fixture(scope="module")
def rod_gradient():
    return rodmol.gradient(_arm(), 0.5, rodmol.TipTracking(TIMES, TARGETS), ROD_KEYS, initial="straight", rtol=RTOL)


@pytest.mark.parametrize("key, component", [("material.E", 0), ("medium.Cy,Cz", 0), ("tension.11", 1),
                                            ("tension.11", 2), ("material.mu", 0)])
def test_a_rods_gradient_is_the_central_difference_of_its_runs(rod_gradient, key, component):
    value, grads = rod_gradient
    expected = reference(_arm(), key, component, 0.5, _tip_loss, initial="straight")
    agree(grads[key][component], expected, np.max(np.abs(grads[key])) if key.startswith("tension") else expected)
    plain = rodmol.simulate(_arm(), 0.5, initial="straight", rtol=RTOL, output_times=TIMES)
    assert value == pytest.approx(_tip_loss(plain), rel=1e-6)


def test_the_equilibriums_dependence_on_the_parameters_is_in_the_gradient():
    # The run starts at the equilibrium under 1 N: y0 moves with E and the first knot's tension.
    arm = _arm([(0.0, 1.0), (0.3, 2.0)])
    keys = ["material.E", "tension.11"]
    value, grads = rodmol.gradient(arm, 0.5, rodmol.TipTracking(TIMES, TARGETS), keys, rtol=RTOL)
    for key, component in [("material.E", 0), ("tension.11", 0), ("tension.11", 1)]:
        expected = reference(arm, key, component, 0.5, _tip_loss)
        agree(grads[key][component], expected, np.max(np.abs(grads[key])))


def test_a_systems_gradient_by_a_body_a_rod_and_a_cable_is_the_central_difference():
    keys = ["bodies.head.mass", "rods.arm.material.E", "rods.arm.tension.c"]
    loss = rodmol.TipTracking(TIMES[:3] * 0.6, TARGETS[:3] * 0 + [0.0, -0.05, 0.2], rod="arm")
    value, grads = rodmol.gradient(_system(), 0.3, loss, keys, rtol=RTOL)

    def measured(result):
        tip = result["arm"].tip[np.searchsorted(result.t, TIMES[:3] * 0.6)]
        return float(np.sum((tip - [0.0, -0.05, 0.2]) ** 2))

    for key, component in [("bodies.head.mass", 0), ("rods.arm.material.E", 0), ("rods.arm.tension.c", 1)]:
        p = named_parameters.parameter(_system(), key)
        h = REFERENCE_STEP * p.scale
        runs = [rodmol.simulate(p.at(_system(), p.value + sign * h * (np.arange(p.size) == component)), 0.3,
                                rtol=REFERENCE_RTOL, output_times=TIMES[:3] * 0.6) for sign in (1, -1)]
        expected = (measured(runs[0]) - measured(runs[1])) / (2 * h)
        agree(grads[key][component], expected, np.max(np.abs(grads[key])))


def test_a_systems_gradient_of_a_bodys_position_is_the_central_difference():
    keys = ["bodies.head.mass", "rods.arm.material.E", "rods.arm.tension.c"]
    target = [0.01, -0.03, 0.005]
    loss = rodmol.BodyTarget("head", target, t=0.2) + rodmol.BodyAdvance("head", [1.0, 2.0, 0.0], weight=0.5)
    value, grads = rodmol.gradient(_system(), 0.3, loss, keys, rtol=RTOL)
    times = [0.2, 0.3]

    def measured(result):
        x = result["head"].position[np.searchsorted(result.t, times)]
        return float(np.sum((x[0] - target) ** 2) - 0.5 * x[1] @ [1.0, 2.0, 0.0] / np.sqrt(5.0))

    plain = rodmol.simulate(_system(), 0.3, rtol=RTOL, output_times=times)
    assert value == pytest.approx(measured(plain), rel=1e-6)
    for key, component in [("bodies.head.mass", 0), ("rods.arm.material.E", 0), ("rods.arm.tension.c", 1)]:
        p = named_parameters.parameter(_system(), key)
        h = REFERENCE_STEP * p.scale
        runs = [rodmol.simulate(p.at(_system(), p.value + sign * h * (np.arange(p.size) == component)), 0.3,
                                rtol=REFERENCE_RTOL, output_times=times) for sign in (1, -1)]
        expected = (measured(runs[0]) - measured(runs[1])) / (2 * h)
        agree(grads[key][component], expected, np.max(np.abs(grads[key])))


def test_the_adjoint_and_the_forward_sensitivities_agree(rod_gradient):
    _, grads = rod_gradient
    run = rodmol.simulate(_arm(), 0.5, initial="straight", rtol=RTOL, output_times=TIMES,
                          sensitivities=["material.E", "tension.11"])
    rows = np.searchsorted(run.t, TIMES)
    residual = run.tip[rows] - TARGETS
    by_e = 2.0 * np.sum(residual * run.sensitivity("material.E").tip[rows])
    by_knots = 2.0 * np.sum(residual * run.sensitivity("tension.11").tip[:, rows], axis=(1, 2))
    agree(grads["material.E"][0], by_e, by_e)
    for k in range(3):
        agree(grads["tension.11"][k], by_knots[k], np.max(np.abs(by_knots)))


def test_bounded_checkpoints_give_the_same_gradient(rod_gradient):
    _, whole = rod_gradient
    stats = {}
    _, bounded = rodmol.gradient(_arm(), 0.5, rodmol.TipTracking(TIMES, TARGETS), ROD_KEYS, initial="straight",
                                 rtol=RTOL, checkpoint_every=8, stats=stats)
    for key in ROD_KEYS:
        agree(bounded[key], whole[key], np.max(np.abs(whole[key])))
    assert stats["kept_steps"] * 4 < stats["forward_steps"]  # memory: every 8th step and one segment


def test_a_loss_time_a_rounding_error_off_a_knot_is_that_knots_time():
    # np.linspace's 3.5000000000000004 beside a knot at 3.5 s: the backward integration failed with
    # "the output and initial times are too close" (the solvers/optimal_tensions.py run).
    exact, rounded = ([t, 0.5] for t in (0.2, 0.2 + 2e-16))
    grads = [rodmol.gradient(_arm(), 0.5, rodmol.TipTracking(times, TARGETS[:2]), ["tension.11"],
                             initial="straight", rtol=1e-6)[1]["tension.11"] for times in (exact, rounded)]
    np.testing.assert_allclose(grads[1], grads[0], rtol=1e-6)


def test_a_loss_read_before_any_force_moves_nothing():
    # The arm starts straight and unloaded: a target at t0 is a constant.
    loss = rodmol.TerminalTarget([0.0, 0.2, 0.0], t=0.0)
    value, grads = rodmol.gradient(_arm(), 0.2, loss, ["material.E", "tension.11"], initial="straight")
    assert value > 0 and grads["material.E"][0] == 0.0 and np.all(grads["tension.11"] == 0.0)


@pytest.mark.parametrize("call, words", [
    (lambda: rodmol.gradient(_arm(), 0.5, rodmol.TipTracking(TIMES, TARGETS), ["material.E"], backend="rk23"),
     "backend"),
    (lambda: rodmol.gradient(_arm(), 0.5, "tip", ["material.E"]), "`loss`"),
    (lambda: rodmol.gradient(_arm(), 0.5, rodmol.TipTracking(TIMES, TARGETS), ["material.X"]), "material.X"),
    (lambda: rodmol.gradient(_arm(), 0.5, rodmol.TipTracking(TIMES, TARGETS), ["discretization.n_elements"]),
     "structure"),
    (lambda: rodmol.gradient(_arm(), 0.3, rodmol.TipTracking(TIMES, TARGETS), ["material.E"]), "must lie in"),
    (lambda: rodmol.gradient(_arm(), 0.5, rodmol.TipTracking(TIMES, TARGETS, rod="arm"), ["material.E"]), "rod"),
    (lambda: rodmol.gradient(_system(), 0.3, rodmol.TipTracking([0.1], [[0, 0, 0]], rod="leg"), ["rods.arm.material.E"]),
     "leg"),
    (lambda: rodmol.gradient(_arm(), 0.5, rodmol.TipTracking(TIMES, TARGETS), ["material.E"], checkpoint_every=1),
     "checkpoint_every"),
    (lambda: rodmol.gradient(_arm(), 0.5, rodmol.TipTracking(TIMES, TARGETS), ["material.E"],
                             adjoint_linsolver="lu"), "adjoint_linsolver"),
    (lambda: rodmol.gradient(rodmol.paper_arm(8, tensions={11: lambda t, state: 1.0}), 0.5,
                             rodmol.TipTracking(TIMES, TARGETS), ["material.E"]), "feedback"),
])
def test_what_the_gradient_refuses_before_any_work(call, words):
    with pytest.raises(ParameterError, match=words):
        call()
