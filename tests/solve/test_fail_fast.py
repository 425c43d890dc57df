"""Runs that cannot succeed end at once with success=False, the frames so far
and a message naming the time reached, the step count, the last step and the
cause (rodmol.solve.watch); the equilibrium and initial states are checked
the same way."""

import re
import warnings

import numpy as np
import pytest

import rodmol
from rodmol.discretise.layout import StateLayout
from rodmol.solve import watch

WATER_ARM = dict(nu=0.5, mu=300.0, rho=1080.0)


def thin_rod(peak_tension):
    """A 5 mm rod in water with a cable at 4 mm ramped to ``peak_tension`` [N] over
    0.1 s: far beyond what it can carry (it would coil into a few-mm radius)."""
    rod = rodmol.Rod(0.3, 0.005, rodmol.Material(E=110e3, **WATER_ARM))
    cable = rodmol.Cable((0.004, 0.0), 0.3, tension=[(0.0, 0.0), (0.1, peak_tension)])
    return rodmol.Model(rod, 20, medium="water", cables=[cable])


def run(model, t_end, **options):
    with pytest.warns(RuntimeWarning) as record:
        result = rodmol.simulate(model, t_end, **options)
    assert not result.success
    assert any(result.message == str(w.message) for w in record)
    return result


def assert_stopped_well(result, cause):
    """Message: the last frame's time first, then how far the solver got, then the cause;
    the frames kept are finite and come before the stop."""
    message = result.message
    assert re.search(cause, message), message
    first = float(re.search(r"t = ([-+0-9.e]+) s", message).group(1))
    assert first == pytest.approx(result.t[-1], abs=1e-12)
    reached = float(re.search(r"reached t = ([-+0-9.e]+) s", message).group(1))
    steps = int(re.search(r"in (\d+) steps", message).group(1))
    assert result.t[-1] <= reached and steps == result.stats["steps"]
    assert re.search(r"last step [0-9.e+-]+ s", message)
    assert np.all(np.isfinite(result.positions)) and len(result.positions) == len(result.t)


@pytest.mark.parametrize("peak", [1e4, 5.0])
@pytest.mark.parametrize("backend", ["cvode", "rk23", "galpha"])
def test_overloaded_thin_rod_stops_when_an_element_turns_too_far(peak, backend):
    # Before: CVODE crept on at 1e-8 s steps for ever. Now it stops within a
    # few hundred steps: half a turn over one 15 mm element is unresolvable.
    result = run(thin_rod(peak), 1.0, initial="straight", backend=backend)
    # At 1e4 N the tip-anchored pull outgrows the tip's axial stiffness first.
    assert_stopped_well(result, r"element \d+ turns by [0-9.]+ rad over its length ds = 0.015 m.*too "
                                r"coarse|the tip section is crushed")
    assert result.stats["steps"] < 5000
    # The kept frames are below the limit.
    assert np.max(np.linalg.norm(result.curvature[:, :-1], axis=-1)) * 0.015 <= watch.MAX_TURN


def test_soft_paper_arm_stalls_and_says_so():
    # E = 10 kPa under the bending test's pull: the arm collapses near the
    # anchor and the steps shrink to 1e-8 s at t = 0.36 s.
    bending = rodmol.scenarios.get("bending")
    paper = bending.model(100)
    soft = rodmol.Rod(0.418, (0.015, 0.004), rodmol.Material(E=10e3, **WATER_ARM))
    model = rodmol.Model(soft, 100, medium="water", cables=paper.cables, markers=paper.markers)
    result = run(model, bending.t_end)
    assert_stopped_well(result, r"stalled at t = 0\.3\d+ s: the last \d+ steps covered only")
    assert "Most compressed element" in result.message
    assert result.stats["steps"] <= 3 * watch.STALL_WINDOW + 5000


def test_rod_without_stiffness_is_not_returned_as_a_success():
    # E = 1 Pa, no damping, in air: it falls and stretches without bound.
    rod = rodmol.Rod(0.3, (0.012, 0.005), rodmol.Material(E=1.0, nu=0.5, rho=1080.0))
    result = run(rodmol.Model(rod, 20, medium="air"), 3.0, initial="straight")
    # (centred scheme: the clamped element collapses first; upwind: one stretches or turns)
    assert_stopped_well(result, r"element \d+ (stretched to [0-9.]+ times its length|turns by|collapsed)")
    assert np.all(result.linear_strain[:, :-1, 0] > watch.MIN_STRETCH)


def test_tip_section_crushed_by_its_cable():
    # E = 1 Pa with a tip cable: the Result's tip strain 1 - T / EA would turn
    # negative (it was -3000) while the solver went on.
    rod = rodmol.Rod(0.3, (0.012, 0.005), rodmol.Material(E=1.0, **WATER_ARM))
    cable = rodmol.Cable((0.004, 0.0), 0.3, tension=[(0.0, 0.0), (1.0, 1.5)])
    result = run(rodmol.Model(rod, 20, medium="water", cables=[cable]), 3.0, initial="straight")
    assert_stopped_well(result, r"the tip section is crushed at t = [0-9.e-]+ s: the cables anchored")
    assert np.all(result.linear_strain[:, -1, 0] > watch.MIN_STRETCH)


@pytest.mark.parametrize("backend", ["cvode", "rk23", "galpha"])
def test_wall_time_budget(backend):
    model = rodmol.paper_arm(10, tensions={11: [(0.0, 0.0), (0.5, 2.0)]})
    result = run(model, 5.0, initial="straight", backend=backend, max_wall_time=1e-6)
    assert_stopped_well(result, r"wall-time budget max_wall_time = 1e-06 s is used up")
    assert result.t[-1] < 5.0


def test_progress_is_reported_between_outputs_and_can_stop_the_run(monkeypatch):
    monkeypatch.setattr(watch, "PROGRESS_INTERVAL", 0.0)  # report every step
    seen = []

    def progress(t, t_end):
        seen.append(t)
        if len(seen) == 40:
            raise KeyboardInterrupt  # what Ctrl-C does inside a callback

    model = rodmol.paper_arm(10, tensions={11: [(0.0, 0.0), (0.5, 2.0)]})
    result = run(model, 1.0, initial="straight", output_dt=0.5, progress=progress)
    assert_stopped_well(result, "interrupted")
    assert any(t not in (0.5, 1.0) for t in seen)  # internal steps, not only outputs
    assert len(result.t) == 1


def test_user_function_error_keeps_its_traceback():
    def sensor(t):
        if t > 0.02:
            raise ZeroDivisionError("sensor divided by zero")
        return 0.5

    model = rodmol.paper_arm(6, tensions={11: sensor})
    result = run(model, 0.1, initial="straight", output_dt=0.01)
    assert "raised ZeroDivisionError: sensor divided by zero" in result.message
    assert isinstance(result.error, rodmol.UserFunctionError)
    cause = result.error.__cause__
    assert isinstance(cause, ZeroDivisionError) and cause.__traceback__ is not None
    # The innermost frame of the chained traceback is the user's function.
    tb = cause.__traceback__
    while tb.tb_next:
        tb = tb.tb_next
    assert tb.tb_frame.f_code.co_name == "sensor"


def test_user_function_error_in_the_equilibrium_is_chained():
    def broken(t):
        return 1.0 / 0.0

    with pytest.raises(rodmol.UserFunctionError, match="raised ZeroDivisionError") as info:
        rodmol.simulate(rodmol.paper_arm(6, tensions={11: broken}), 0.1)
    assert isinstance(info.value.__cause__, ZeroDivisionError)


def test_successful_runs_are_untouched():
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        result = rodmol.simulate(rodmol.scenarios.get("bending").model(20), 1.0)
    assert result.success and result.error is None


# ------------------------------------------------------------------ states


def _state(changes, n=6):
    model = rodmol.paper_arm(n)
    y = rodmol.straight_state(model)
    layout = StateLayout(n)
    for (name, element, component), value in changes.items():
        layout.field(y, name)[element, component] = value
    return model, y


@pytest.mark.parametrize("change, cause", [
    ({("q", 3, 0): -0.5}, r"element 3 inverted at t = 0 s \(axial stretch q1 = -0.5\)"),
    ({("q", 2, 0): 0.01}, r"element 2 collapsed"),
    ({("q", 1, 0): 30.0}, r"element 1 stretched to 30 times its length"),
    ({("k", 4, 1): 30.0}, r"element 4 turns by 2.09 rad over its length ds = 0.0697 m"),
    ({("Q", 0, 0): 3.0}, r"orientation of node 1 lost its unit norm"),
    ({("v", 5, 2): np.nan}, r"non-finite at t = 0 s \(v\[2\] of element 5 = nan\)"),
])
def test_state_problems_are_named(change, cause):
    model, y = _state(change)
    problem = watch.state_problem(StateLayout(6), model.ds, 0.0, y)
    assert problem and re.search(cause, problem), problem
    # The same problem refuses a user's initial state, before any work.
    with pytest.raises(rodmol.ParameterError, match="`initial`"):
        rodmol.simulate(model, 0.1, initial=y)
    assert watch.state_problem(StateLayout(6), model.ds, 0.0, rodmol.straight_state(model)) is None


def test_all_zero_initial_state_is_refused_at_the_call():
    model = rodmol.paper_arm(6)
    with pytest.raises(rodmol.ParameterError, match="element 0 inverted"):
        rodmol.simulate(model, 0.1, initial=np.zeros(StateLayout(6).size))


def test_degenerate_equilibrium_is_an_error():
    # E = 1 Pa hanging in air: the linear law has a rest state, stretched
    # thousands of times its length; it is refused, not returned.
    rod = rodmol.Rod(0.3, 0.01, rodmol.Material(E=1.0, nu=0.5, rho=1080.0))
    with pytest.raises(rodmol.EquilibriumError, match="not a valid state of the rod|no static"):
        rodmol.equilibrium(rodmol.Model(rod, 10, gravity=(-9.81, 0.0, 0.0)))


def test_the_tip_crushed_is_seen_whatever_the_round_off_of_the_anchors_cell_share():
    """L = 0.2 m on N = 4: the tip cable's share of the last cell is 1 - 1e-16, and the tip
    check, which looked for exactly 1, never ran: the run crept on until an element turned."""
    rod = rodmol.Rod(0.2, 0.01, rodmol.Material(E=1e5, **WATER_ARM))
    cable = rodmol.Cable((0.005, 0.0), 0.2, tension=[(0.0, 0.0), (0.1, 1e4)])
    result = run(rodmol.Model(rod, 4, cables=[cable]), 0.2, initial="straight")
    assert_stopped_well(result, r"the tip section is crushed at t = [0-9.e-]+ s: the cables anchored")
