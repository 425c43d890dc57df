"""Feedback tensions T(t, state): a proportional controller on the tip height.

Cable 11 (p_y = +3 mm) lifts the arm. The controller pulls with
T = Kp (y_target - tip_y), clipped at 0. Proportional control leaves a
steady-state error: the arm ends below the target, and on average it sits
where the static model puts it under the average tension. (Quadratic drag
does not damp small motions, so in water the arm keeps ringing at a few
mm/s for a long time: only averages settle.)
"""

import numpy as np
import pytest

import rodmol

N = 12
TARGET = -0.08  # m, tip height to reach (the arm sags to about -0.12 m at N = 12)
GAIN = 10.0  # N/m


def controller(t, state):
    return max(0.0, GAIN * (TARGET - state.tip[1]))


@pytest.fixture(scope="module")
def controlled():
    model = rodmol.paper_arm(N, tensions={11: controller})
    sagging = rodmol.equilibrium(rodmol.paper_arm(N))  # the controller is switched on at t = 0
    return model, rodmol.simulate(model, 15.0, output_dt=0.05, initial=sagging)


def test_equilibrium_of_a_feedback_law_is_the_closed_loop_rest_state():
    # The law reads the equilibrium's iterates (never state=None): the rest
    # state found satisfies it, T = Kp (target - tip_y) at the rod's own tip.
    seen = []

    def law(t, state):
        seen.append(state)
        return controller(t, state)

    model = rodmol.paper_arm(N, tensions={11: law})
    y = rodmol.equilibrium(model)
    assert seen and all(isinstance(s, rodmol.StateView) for s in seen)
    tip_y = rodmol.StateLayout(N).field(y, "u")[-1, 1]
    tension = GAIN * (TARGET - tip_y)
    assert tension > 0.0
    open_loop = rodmol.equilibrium(rodmol.paper_arm(N, tensions={11: tension}))
    assert np.allclose(open_loop, y, atol=1e-6)


def test_controller_lifts_the_tip_toward_the_target(controlled):
    model, result = controlled
    assert result.success, result.message
    start, end = result.tip[0, 1], result.tip[-1, 1]
    assert start < -0.1  # sagging under its net weight
    assert abs(end - TARGET) < 0.5 * abs(start - TARGET)
    assert end < TARGET  # P control undershoots


def test_recorded_tension_is_the_control_law_of_the_recorded_state(controlled):
    _, result = controlled
    expected = np.maximum(0.0, GAIN * (TARGET - result.tip[:, 1]))
    np.testing.assert_allclose(result.tensions[:, 10], expected, atol=1e-9)


def test_average_state_is_the_static_equilibrium_under_the_average_tension(controlled):
    model, result = controlled
    late = result.t >= 10.0
    mean_tension = float(result.tensions[late, 10].mean())
    static = rodmol.equilibrium(rodmol.paper_arm(N, tensions={11: mean_tension}))
    static_tip = rodmol.StateLayout(N).field(static, "u")[-1]
    mean_tip = result.tip[late].mean(axis=0)
    assert np.linalg.norm(mean_tip - static_tip) < 0.005  # m
    # and the controller's steady state: T = Kp (target - y) on the static arm
    assert mean_tension == pytest.approx(GAIN * (TARGET - static_tip[1]), abs=0.01)
