"""Inverse statics: tensions recovered from the equilibria they produce."""

import sys
from dataclasses import replace

import numpy as np
import pytest

import rodmol
from rodmol.control import inverse_statics, inverse_statics_path
from rodmol.solve.tension_statics import tension_sensitivity

N = 8
PULLED = {11: 1.0, 12: 0.5, 3: 0.4}


def rest_pose(model):
    """The equilibrium's tip [m] and tip tangent, global."""
    y = rodmol.equilibrium(model)
    view = rodmol.SemiDiscrete(model).state_view(0.0, y)
    return view.tip, view.rotations[-1][:, 0]


@pytest.fixture(scope="module")
def arm():
    return rodmol.paper_arm(N)


@pytest.fixture(scope="module")
def pulled():
    """The tip and tangent of the arm with cables 11, 12 and 3 pulled."""
    return rest_pose(rodmol.paper_arm(N, tensions=PULLED))


def test_two_cables_recover_their_tensions(arm):
    """Two cables, three coordinates: the tensions are unique, and found from slack."""
    tip, _ = rest_pose(rodmol.paper_arm(N, tensions={11: 1.0, 12: 0.5}))
    fit = inverse_statics(arm, tip, cables=["cable 11", "cable 12"], bounds=(0.0, 5.0))
    assert fit.reachable and fit.tip_error < 1e-7
    assert fit.tensions["cable 11"] == pytest.approx(1.0, abs=1e-6)
    assert fit.tensions["cable 12"] == pytest.approx(0.5, abs=1e-6)
    assert fit.tensions["cable 1"] == 0.0  # not actuated: its own (slack) tension
    assert np.allclose(fit.tip, tip, atol=1e-7)


def test_position_and_direction_recover_four_tensions(arm, pulled):
    """Tip and tangent (five conditions) fix four cables, one of them slack in the
    reference; the fit's model has the tip where the fit says."""
    tip, tangent = pulled
    fit = inverse_statics(arm, tip, direction=tangent, cables=["cable 11", "cable 12", "cable 3", "cable 7"],
                          bounds=(0.0, 5.0))
    assert fit.reachable and fit.residual < 1e-7 and fit.direction_error < 1e-6
    for number, tension in {**PULLED, 7: 0.0}.items():
        assert fit.tensions[f"cable {number}"] == pytest.approx(tension, abs=1e-5)
    assert np.allclose(rest_pose(fit.apply(arm))[0], tip, atol=1e-7)


def test_markers_alone_recover_the_tensions(arm):
    """Three markers on the surface (no tip target) fix four cables; their errors
    are reported by name."""
    loaded = rodmol.paper_arm(N, tensions=PULLED)
    run = rodmol.simulate(loaded, 1e-4, initial="equilibrium", output_dt=1e-4)  # a Result's markers, as measured
    aims = dict(zip(("L1", "L2", "L3"), run.markers[0, :3]))
    fit = inverse_statics(arm, markers=aims, cables=["cable 11", "cable 12", "cable 3", "cable 7"],
                          bounds=(0.0, 5.0))
    assert fit.reachable and fit.tip_error is None and set(fit.marker_errors) == {"L1", "L2", "L3"}
    assert max(fit.marker_errors.values()) < 1e-7
    for number, tension in {**PULLED, 7: 0.0}.items():
        assert fit.tensions[f"cable {number}"] == pytest.approx(tension, abs=1e-5)


def test_all_cables_meet_the_tip(arm, pulled):
    """Twelve cables for three coordinates: many solutions, the tip met by one."""
    fit = inverse_statics(arm, pulled[0], bounds=(0.0, 5.0))
    assert fit.reachable and fit.tip_error < 1e-4
    assert all(0.0 <= value <= 5.0 for value in fit.tensions.values())
    assert np.allclose(rest_pose(fit.apply(arm))[0], pulled[0], atol=1e-4)


def test_displacement_controlled_cables_get_their_positions(arm):
    """Actuator positions that hold the found tensions put the tip on the target
    when the model is run forward with them."""
    tip, _ = rest_pose(rodmol.paper_arm(N, tensions={11: 1.0, 12: 0.5}))
    cables = [replace(c, tension=None, displacement=0.0, compliance=2e-3) if c.name in ("cable 11", "cable 12")
              else c for c in arm.cables]
    model = arm.replace(cables=cables)
    fit = inverse_statics(model, tip, cables=["cable 11", "cable 12"], bounds=(0.0, 5.0))
    assert fit.reachable and set(fit.displacements) == {"cable 11", "cable 12"}
    assert all(z < 0.0 for z in fit.displacements.values())  # reeled in
    assert np.allclose(rest_pose(fit.apply(model))[0], tip, atol=1e-7)


def test_sensitivity_matches_differences_of_whole_equilibria(arm):
    """d y / d T by the implicit-function theorem against central differences of
    equilibria solved from scratch."""
    tensions = np.zeros(12)
    tensions[[10, 11, 2]] = 1.0, 0.5, 0.4
    system = rodmol.SemiDiscrete(rodmol.discretise.hand_tensions.tensions_by_hand(arm))
    y = rodmol.equilibrium(rodmol.paper_arm(N, tensions=PULLED))
    exact = tension_sensitivity(system, y, tensions)
    tip = system.layout.tip_slice("u")
    for j in (10, 2, 4):  # cable 5 is slack: its column is the one-sided limit
        h = 1e-3
        sides = []
        for sign in (1.0, -1.0):
            changed = {i + 1: v for i, v in enumerate(tensions) if v}
            changed[j + 1] = max(tensions[j] + sign * h, 0.0)
            sides.append(rest_pose(rodmol.paper_arm(N, tensions=changed))[0])
        reference = (sides[0] - sides[1]) / (h if tensions[j] == 0.0 else 2 * h)
        assert np.allclose(exact[tip, j], reference, rtol=1e-3, atol=1e-4 * np.abs(reference).max())


def test_an_unreachable_target_says_so(arm):
    """Far above the arm with little tension: the best fit saturates the cables that lift."""
    fit = inverse_statics(arm, (0.0, 0.5, 0.0), cables=["cable 9", "cable 10", "cable 11", "cable 12"],
                          bounds=(0.0, 0.5))
    assert not fit.reachable
    assert fit.residual > 0.1
    assert fit.active.get("cable 11") == "upper"
    assert "not reached" in fit.message and "cable 11" in fit.message


def test_a_target_beyond_the_rods_length_is_said_out_of_reach(arm):
    """Farther from the base than the arm is long: the message says so, not a local minimum."""
    fit = inverse_statics(arm, (0.3, 0.4, 0.0), cables=["cable 11", "cable 12"], bounds=(0.0, 5.0), max_iter=5)
    assert not fit.reachable
    assert "out of reach: the tip is aimed 0.5 m from its base, farther than the rod's length" in fit.message
    assert "local minimum" not in fit.message


def test_no_step_is_the_forward_statics(arm):
    """max_iter=0: the equilibrium under ``start``, measured against the target."""
    tip, _ = rest_pose(rodmol.paper_arm(N, tensions={11: 1.0, 12: 0.5}))
    fit = inverse_statics(arm, (0.0, 0.0, 0.0), cables=["cable 11", "cable 12"], start=[1.0, 0.5], max_iter=0)
    assert fit.iterations == 0 and fit.equilibria == 1 and not fit.reachable
    assert np.allclose(fit.tip, tip, atol=1e-9) and fit.tip_error == pytest.approx(np.linalg.norm(tip))


def test_a_path_reuses_the_previous_solution(arm):
    """Targets along the tips of a tension ramp: each met, and each after the
    first needs fewer equilibria than the first."""
    tips = np.array([rest_pose(rodmol.paper_arm(N, tensions={11: 1.0 + 0.05 * k, 12: 0.5}))[0] for k in range(4)])
    fits = inverse_statics_path(arm, tips, cables=["cable 11", "cable 12"], bounds=(0.0, 5.0))
    assert all(f.reachable for f in fits)
    assert [round(f.tensions["cable 11"], 6) for f in fits] == [1.0, 1.05, 1.1, 1.15]
    assert max(f.equilibria for f in fits[1:]) < fits[0].equilibria


@pytest.mark.parametrize("kwargs, named", [
    (dict(tip=(0.1, 0.2)), "`tip`"),
    (dict(tip=(0.1, np.nan, 0.0)), "`tip`"),
    (dict(tip=(0.1, 0.2, 0.0), bounds=(2.0, 1.0)), "`bounds`"),
    (dict(tip=(0.1, 0.2, 0.0), bounds=(-1.0, 1.0)), "`bounds`"),
    (dict(tip=(0.1, 0.2, 0.0), bounds=(0.0, np.nan)), "`bounds`"),
    (dict(tip=(0.1, 0.2, 0.0), bounds=(0.0, [1.0, 2.0])), "`bounds`"),
    (dict(tip=(0.1, 0.2, 0.0), cables=["cable 13"]), "`cables`"),
    (dict(tip=(0.1, 0.2, 0.0), direction=(0.0, 0.0, 0.0)), "`direction`"),
    (dict(tip=(0.1, 0.2, 0.0), tol=0.0), "`tol`"),
    (dict(markers={"L4": (0.1, 0.2, 0.0)}), "`markers`"),
    (dict(markers={"L2": (0.1, 0.2)}), "markers"),
    (dict(), "give a target"),
])
def test_bad_input_is_named_before_any_equilibrium(arm, monkeypatch, kwargs, named):
    def no_work(*args, **kwargs):
        raise AssertionError("an equilibrium was solved")

    monkeypatch.setattr(sys.modules["rodmol.control.inverse_statics"], "rest_state", no_work)
    with pytest.raises(rodmol.ParameterError, match=named):
        inverse_statics(arm, **kwargs)


def test_a_path_checks_its_targets(arm):
    with pytest.raises(rodmol.ParameterError, match="`tips`"):
        inverse_statics_path(arm, [0.1, 0.2, 0.0])
