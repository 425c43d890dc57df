"""Loss records (rodmol.losses): their values as the run reads them, their gradients through
rodmol.gradient against central differences of simulate, sums, and what they refuse."""

import numpy as np
import pytest
from gradient_cases import KNOTS, REFERENCE_RTOL, REFERENCE_STEP, RTOL, TARGETS, TIMES, _arm, _system, agree

import rodmol
from rodmol import named_parameters
from rodmol.calibrate import MarkerTracks
from rodmol.errors import ParameterError, UserFunctionError


def _difference(key, component, loss_of_run, t_end=0.5, extra=lambda model: 0.0):
    """Central difference of loss_of_run(simulate) + extra(model) in one parameter component."""
    arm = _arm()
    p = named_parameters.parameter(arm, key)
    h = REFERENCE_STEP * p.scale
    values = []
    for sign in (1, -1):
        model = p.at(arm, p.value + sign * h * (np.arange(p.size) == component))
        run = rodmol.simulate(model, t_end, initial="straight", rtol=REFERENCE_RTOL, output_times=TIMES)
        values.append(loss_of_run(run) + extra(model))
    return (values[0] - values[1]) / (2 * h)


def test_the_effort_is_the_integral_of_the_squared_tensions():
    # Piecewise linear: the integral of T^2 over a segment from a to b of length d is d (a^2 + ab + b^2) / 3;
    # after the last knot the tension holds 1 N.
    exact = 0.2 * 4.0 / 3.0 + 0.3 * (4.0 + 2.0 + 1.0) / 3.0 + 0.2 * 1.0
    assert rodmol.Effort(2.0).direct(_arm(), 0.0, 0.7) == pytest.approx(2.0 * exact, rel=1e-12)


def test_tracking_plus_effort_gradient_is_the_central_difference():
    weight = 1e-2
    loss = rodmol.TipTracking(TIMES, TARGETS) + rodmol.Effort(weight)
    value, grads = rodmol.gradient(_arm(), 0.5, loss, ["tension.11", "material.E"], initial="straight", rtol=RTOL)

    def tracking(run):
        return float(np.sum((run.tip[np.searchsorted(run.t, TIMES)] - TARGETS) ** 2))

    def effort(model):
        return rodmol.Effort(weight).direct(model, 0.0, 0.5)

    for component in (1, 2):
        expected = _difference("tension.11", component, tracking, extra=effort)
        agree(grads["tension.11"][component], expected, np.max(np.abs(grads["tension.11"])))
    # E moves the tip, not the tensions: the effort adds nothing to its derivative.
    agree(grads["material.E"][0], _difference("material.E", 0, tracking), grads["material.E"][0])


def test_an_effort_alone_has_the_analytic_gradient_and_no_adjoint():
    value, grads = rodmol.gradient(_arm(), 0.5, rodmol.Effort(1.0), ["tension.11"], initial="straight")
    # d/dv_k of the integral of T^2 = 2 * integral of T b_k (b_k the hat of knot k).
    t = np.linspace(0.0, 0.5, 200001)
    tension = np.interp(t, *zip(*KNOTS))
    expected = [2.0 * np.trapezoid(tension * np.interp(t, [0.0, 0.2, 0.5], np.eye(3)[k]), t) for k in range(3)]
    np.testing.assert_allclose(grads["tension.11"], expected, rtol=1e-7)


def test_marker_tracking_reads_the_seen_markers_and_its_gradient_is_the_central_difference():
    recording = rodmol.simulate(_arm(), 0.5, initial="straight", output_times=TIMES)
    rows = np.searchsorted(recording.t, TIMES)
    xyz = recording.markers[rows] + 0.01  # a measurement off the run by 1 cm
    xyz[1, 2] = np.nan  # marker 2 not seen in frame 1
    tracks = MarkerTracks(TIMES, xyz, tuple(f"m{i}" for i in range(xyz.shape[1])))
    value, grads = rodmol.gradient(_arm(), 0.5, rodmol.MarkerTracking(tracks), ["material.E", "tension.11"],
                                   initial="straight", rtol=RTOL)

    def measured(run):
        moved = run.markers[np.searchsorted(run.t, TIMES)] - xyz
        return float(np.nansum(moved ** 2))

    plain = rodmol.simulate(_arm(), 0.5, initial="straight", rtol=RTOL, output_times=TIMES)
    assert value == pytest.approx(measured(plain), rel=1e-6)
    agree(grads["material.E"][0], _difference("material.E", 0, measured), grads["material.E"][0])
    agree(grads["tension.11"][1], _difference("tension.11", 1, measured), np.max(np.abs(grads["tension.11"])))


def test_a_users_state_loss_with_its_gradient():
    entry = 40  # a strain of the state

    def value(t, states):
        return float(np.sum(t * states[:, entry] ** 2))

    def gradient(t, states):
        out = np.zeros_like(states)
        out[:, entry] = 2.0 * t * states[:, entry]
        return out

    loss = rodmol.StateLoss(TIMES, value, gradient)
    result, grads = rodmol.gradient(_arm(), 0.5, loss, ["material.E"], initial="straight", rtol=RTOL)

    def measured(run):
        rows = np.searchsorted(run.t, TIMES)
        return value(TIMES, run.states[rows])

    agree(grads["material.E"][0], _difference("material.E", 0, measured), grads["material.E"][0])


def test_a_terminal_target_reads_the_runs_end():
    run = rodmol.simulate(_arm(), 0.3, initial="straight", rtol=RTOL)
    value, _ = rodmol.gradient(_arm(), 0.3, rodmol.TerminalTarget([0.0, 0.0, 0.0]), ["material.E"],
                               initial="straight", rtol=RTOL)
    assert value == pytest.approx(float(np.sum(run.tip[-1] ** 2)), rel=1e-6)


def test_losses_add_up():
    a, b = rodmol.TipTracking(TIMES, TARGETS), rodmol.TerminalTarget([0.0, 0.2, 0.0], t=0.3)
    total, _ = rodmol.gradient(_arm(), 0.5, sum([a, b]), ["material.E"], initial="straight", rtol=RTOL)
    parts = [rodmol.gradient(_arm(), 0.5, loss, ["material.E"], initial="straight", rtol=RTOL)[0] for loss in (a, b)]
    assert total == pytest.approx(sum(parts), rel=1e-9)


def test_a_loss_until_a_time_keeps_its_terms_up_to_it():
    tracking = rodmol.TipTracking(TIMES, TARGETS)
    early = tracking.until(0.3)
    np.testing.assert_array_equal(early.times(0.0, 0.3), TIMES[:2])
    np.testing.assert_array_equal(early.targets, TARGETS[:2])
    assert tracking.until(0.05) is None
    assert rodmol.TerminalTarget([0, 0, 0]).until(0.3) is None  # the run's end is not in a shorter run
    both = (tracking + rodmol.Effort(1.0) + rodmol.TerminalTarget([0, 0, 0], t=0.4)).until(0.3)
    assert [type(p).__name__ for p in both.parts] == ["TipTracking", "Effort"]
    tracks = MarkerTracks(TIMES, np.zeros((4, 4, 3)), ("a", "b", "c", "d"))
    np.testing.assert_array_equal(rodmol.MarkerTracking(tracks).until(0.3).times(0, 0.3), TIMES[:2])
    # The value of the shorter run's loss is the full loss's terms up to then.
    value, _ = rodmol.gradient(_arm(), 0.3, early, ["material.E"], initial="straight", rtol=RTOL)
    run = rodmol.simulate(_arm(), 0.5, initial="straight", rtol=RTOL, output_times=TIMES)
    assert value == pytest.approx(float(np.sum((run.tip[1:3] - TARGETS[:2]) ** 2)), rel=1e-6)


def test_a_users_loss_that_raises_is_named():
    def broken(t, states):
        raise KeyError("oops")

    loss = rodmol.StateLoss(TIMES, broken, broken)
    with pytest.raises(UserFunctionError, match="StateLoss"):
        rodmol.gradient(_arm(), 0.5, loss, ["material.E"], initial="straight")


@pytest.mark.parametrize("make, words", [
    (lambda: rodmol.TipTracking([0.2, 0.1], [[0, 0, 0]] * 2), "increasing"),
    (lambda: rodmol.TipTracking([0.1, 0.2], [[0, 0, 0]]), "targets"),
    (lambda: rodmol.TipTracking([0.1], [[0, 0, 0]], weights=[-1.0]), "weights"),
    (lambda: rodmol.TipTracking([np.nan], [[0, 0, 0]]), "times"),
    (lambda: rodmol.Effort(-1.0), "weight"),
    (lambda: rodmol.StateLoss([0.1], 3.0, 4.0), "function"),
    (lambda: rodmol.TerminalTarget([0, 0]), "target"),
    (lambda: rodmol.BodyTarget("head", [0, 0]), "target"),
    (lambda: rodmol.BodyTarget(3, [0, 0, 0]), "body"),
    (lambda: rodmol.BodyAdvance("head", [0, 0, 0]), "direction"),
    (lambda: rodmol.BodyAdvance("head", [1, 0, 0], weight=-1.0), "weight"),
])
def test_what_the_losses_refuse(make, words):
    with pytest.raises(ParameterError, match=words):
        make()


@pytest.mark.parametrize("model, body", [(_arm, "head"), (_system, "tail")])
def test_a_body_loss_needs_a_body_of_the_system(model, body):
    with pytest.raises(ParameterError, match=repr(body)):
        rodmol.gradient(model(), 0.2, rodmol.BodyAdvance(body, [1, 0, 0]), ["material.E"]
                        if model is _arm else ["rods.arm.material.E"])
