"""Inverse statics of a System: the inputs recovered from the equilibria they produce,
on the two arms of examples/two_arms.toml (its head fixed or driven) and on the
parallel robot of examples/parallel_robot.py (its legs inserted)."""

import sys
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from example_modules import load_example

import rodmol
from rodmol.discretise.assembly import Assembly

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
parallel_robot = load_example("parallel_robot.py")

LEGS = ["leg0", "leg1", "leg2"]


def two_arms(tmp_path, head):
    """examples/two_arms.toml with its head's motion given (a TOML line or table), loaded."""
    last = "drag = [0.5, 0.5, 0.5, 1e-3, 1e-3, 1e-3]\n"  # the head's table's last line
    text = (EXAMPLES / "two_arms.toml").read_text().replace(last, f"{last}{head}\n")
    path = tmp_path / "two_arms.toml"
    path.write_text(text)
    return rodmol.load_scenario(path).model


def pulled(system, tensions):
    """``system`` with each rod's cable pulling with tensions[rod] [N]."""
    rods = {name: model.replace(cables=[replace(c, tension=tensions[name]) for c in model.cables])
            for name, model in system.given_rods.items()}
    return system.replace(rods=rods)


def rest(system):
    """The rods' tips and the bodies' positions [m] at the system's equilibrium (rodmol.equilibrium)."""
    y, assembly = rodmol.equilibrium(system), Assembly(system)
    tips = {name: sd.state_view(0.0, y[assembly.parts[name]]).tip for name, sd in assembly.rods.items()}
    return tips, {name: y[part.fields["x"]] for name, part in assembly.bodies.items()}


@pytest.fixture(scope="module")
def arms(tmp_path_factory):
    return two_arms(tmp_path_factory.mktemp("fixed"), 'motion = "fixed"')


@pytest.fixture(scope="module")
def robot():
    return parallel_robot.robot(8)


def test_two_arms_recover_their_tensions(arms):
    """Both tips aimed at (six conditions, two cables): the tensions that put them there
    (by rodmol.equilibrium) are found from another start, the tips to 0.1 mm and better."""
    tips, _ = rest(pulled(arms, {"right": 0.2, "left": 0.15}))
    fit = rodmol.inverse_statics(arms, tip=tips, bounds=(0.0, 2.0), start=[0.05, 0.05])
    assert fit.reachable and "target met" in fit.message
    assert fit.inputs == ("right/cable 1 tension [N]", "left/cable 1 tension [N]")
    assert fit.tensions["right"]["cable 1"] == pytest.approx(0.2, abs=1e-5)
    assert fit.tensions["left"]["cable 1"] == pytest.approx(0.15, abs=1e-5)
    for name in tips:
        assert np.linalg.norm(fit.tips[name] - tips[name]) < 1e-6
        assert fit.tip_errors[name] < 1e-6
    again, _ = rest(fit.apply(arms))
    assert all(np.linalg.norm(again[name] - tips[name]) < 1e-6 for name in tips)


def test_one_arms_markers_fix_its_cable_the_other_holds(arms):
    """Markers of one arm as targets, its cable the only input: the other arm keeps its own."""
    marked = arms.replace(rods={"right": arms.given_rods["right"].replace(
        markers=[rodmol.Marker(0.1, name="mid"), rodmol.Marker(0.15, name="far")])})
    system = pulled(marked, {"right": 0.25, "left": 0.0})
    y, assembly = rodmol.equilibrium(system), Assembly(system)
    seen = dict(zip(("mid", "far"), assembly.rods["right"].state_view(0.0, y[assembly.parts["right"]]).markers))
    fit = rodmol.inverse_statics(marked, markers={"right": seen}, cables={"right": "cable 1"}, bounds=(0.0, 2.0))
    assert fit.reachable and fit.inputs == ("right/cable 1 tension [N]",)
    assert fit.tensions["right"]["cable 1"] == pytest.approx(0.25, abs=1e-5)
    assert max(fit.marker_errors["right"].values()) < 1e-6


def test_a_driven_heads_pose_is_an_input(tmp_path):
    """The head driven (at rest): its pose solves with the cables for a tip the cables
    alone cannot reach; the fit's system has the tip there."""
    arms = two_arms(tmp_path, "[body.motion]\nvelocity = [0.0, 0.0, 0.0]")
    target = np.array([0.25, 0.03, 0.02])
    alone = rodmol.inverse_statics(arms, tip={"right": target}, bounds=(0.0, 2.0))
    assert not alone.reachable
    fit = rodmol.inverse_statics(arms, tip={"right": target}, bounds=(0.0, 2.0), driven=["head"])
    assert fit.reachable and fit.tip_errors["right"] < 1e-4
    assert fit.inputs[-6:] == tuple(f"head {axis}" for axis in ("x [m]", "y [m]", "z [m]", "rx [rad]", "ry [rad]",
                                                                "rz [rad]"))
    tips, bodies = rest(fit.apply(arms))
    assert np.linalg.norm(tips["right"] - target) < 1e-4
    assert np.allclose(bodies["head"], fit.driven["head"][0], atol=1e-12)


def test_equal_insertions_lift_the_platform_by_as_much(robot):
    """Lifting the three legs' bases by d lifts the whole robot by d (gravity is uniform):
    aiming the platform's pose there finds the insertions d from zero."""
    y, assembly = rodmol.equilibrium(robot), Assembly(robot)
    part = assembly.bodies["platform"]
    position = y[part.fields["x"]]
    rotation = rodmol.discretise.rotations.matrices(y[part.fields["Q"]])
    fit = rodmol.inverse_statics(robot, pose={"platform": (position + (0.0, 0.0, 0.004), rotation)}, insertions=LEGS)
    assert fit.reachable and fit.position_errors["platform"] < 1e-6 and fit.rotation_errors["platform"] < 1e-6
    assert fit.inputs == tuple(f"{leg} insertion [m]" for leg in LEGS)
    assert np.allclose(list(fit.insertions.values()), 0.004, atol=1e-7)
    assert fit.tensions == {leg: {} for leg in LEGS}


def forward(robot, insertions):
    """The fit of no step (``max_iter=0``): the equilibrium under ``insertions``."""
    fit = rodmol.inverse_statics(robot, pose={"platform": (0.0, 0.0, 0.2)}, insertions=LEGS, start=insertions,
                                 max_iter=0)
    assert fit.iterations == 0 and fit.equilibria == 1 and np.allclose(fit.values, insertions)
    return fit


def test_the_platform_finds_the_insertions_that_put_it_there(robot):
    """Different insertions tilt the platform; its position, or its pose, finds them
    again from zero, to 0.1 mm and better."""
    made = forward(robot, [0.01, -0.005, 0.003])
    position, rotation = made.poses["platform"]
    for pose in (position, (position, rotation)):
        fit = rodmol.inverse_statics(robot, pose={"platform": pose}, insertions=LEGS)
        assert fit.reachable and fit.position_errors["platform"] < 1e-6
        assert np.allclose(fit.values, made.values, atol=1e-6)
        assert np.linalg.norm(fit.poses["platform"][0] - position) < 1e-6


def test_unreachable_targets_say_why(arms, robot):
    """Too far for the arm (beyond its length from its base), or beyond the legs' travel."""
    far = rodmol.inverse_statics(arms, tip={"right": (0.25, 0.2, 0.0)}, bounds=(0.0, 1.0))
    assert not far.reachable and far.residual > 0.1
    assert "out of reach" in far.message and "the tip of rod 'right' is aimed" in far.message
    high = rodmol.inverse_statics(robot, pose={"platform": (0.0, 0.0, 0.25)}, insertions=LEGS, travel=(-0.01, 0.01))
    assert not high.reachable and high.position_errors["platform"] > 0.02
    assert "upper" in high.active.values() and "insertion [m] (0.01 m)" in high.message


@pytest.mark.parametrize("kwargs, named", [
    (dict(tip={"rigth": (0.2, 0.0, 0.0)}), "did you mean 'right'"),
    (dict(tip=(0.2, 0.0, 0.0)), "`tip` must map rod names"),
    (dict(tip={"right": (0.2, 0.0)}), "rod 'right': `tip`"),
    (dict(pose={"hed": (0.0, 0.0, 0.0)}), "`pose`: no body named 'hed'"),
    (dict(pose={"head": ((0.0, 0.0, 0.0), np.ones((3, 3)))}), "`pose['head'] rotation`"),
    (dict(tip={"right": (0.2, 0.0, 0.0)}, cables={"right": ["cable 2"]}), "`cables`: no cable named 'cable 2'"),
    (dict(tip={"right": (0.2, 0.0, 0.0)}, insertions=["right"]), "rod 'right''s base is on body 'head'"),
    (dict(tip={"right": (0.2, 0.0, 0.0)}, driven=["head"]), "not driven"),
    (dict(tip={"right": (0.2, 0.0, 0.0)}, start=[0.1]), "`start` must be 2"),
    (dict(tip={"right": (0.2, 0.0, 0.0)}, bounds=(-1.0, 1.0)), "`bounds`"),
    (dict(tip={"right": (0.2, 0.0, 0.0)}, travel=(0.0, 1.0)), "`travel` bounds the insertions"),
    (dict(), "give a target"),
])
def test_bad_input_is_named_before_any_equilibrium(arms, monkeypatch, kwargs, named):
    def no_work(*args, **kwargs):
        raise AssertionError("an equilibrium was solved")

    for name in ("continuation", "damped_newton"):
        monkeypatch.setattr(sys.modules["rodmol.control.system_statics"], name, no_work)
    with pytest.raises(rodmol.ParameterError, match=named.replace("[", r"\[").replace("(", r"\(")):
        rodmol.inverse_statics(arms, **kwargs)


def test_a_floating_head_and_system_words_for_a_rod_are_refused(tmp_path):
    free = rodmol.load_scenario(EXAMPLES / "two_arms.toml").model
    with pytest.raises(rodmol.ParameterError, match="held by nothing"):
        rodmol.inverse_statics(free, tip={"right": (0.2, 0.0, 0.0)})
    with pytest.raises(rodmol.ParameterError, match="`insertions` is for a rodmol.System"):
        rodmol.inverse_statics(rodmol.paper_arm(4), tip=(0.2, 0.0, 0.0), insertions=["leg0"])


def test_the_inserted_robot_settles_where_the_statics_put_it(robot):
    """fit.apply slides the legs' bases in over a ramp; simulate settles the platform
    where the statics say (3 um of a 29 mm move: the integration's drift)."""
    made = forward(robot, [0.01, -0.005, 0.003])
    result = rodmol.simulate(made.apply(robot, ramp=0.3), 1.5, output_dt=0.1)
    assert result.success
    moved = made.poses["platform"][0] - (0.0, 0.0, 0.2)
    assert np.linalg.norm(moved) > 0.02
    assert np.linalg.norm(result["platform"].position[-1] - made.poses["platform"][0]) < 2e-5
    with pytest.raises(rodmol.ParameterError, match="give `ramp`"):
        made.apply(robot)
