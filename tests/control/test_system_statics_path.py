"""Inverse statics of a System along a path of targets (rodmol.inverse_statics_path):
each target met by the inputs the path finds, as forward equilibria under those
inputs show, each fit started from the one before; bad paths refused before any work."""

import sys
from pathlib import Path

import numpy as np
import pytest
from example_modules import load_example
from test_system_statics import LEGS, forward, pulled, rest, two_arms

import rodmol

parallel_robot = load_example("parallel_robot.py")
REACH = 1e-4  # the targets are to be met to 0.1 mm


@pytest.fixture(scope="module")
def arms(tmp_path_factory):
    return two_arms(tmp_path_factory.mktemp("fixed"), 'motion = "fixed"')


def test_two_arms_follow_a_path_of_tips(arms):
    """Five pairs of tips, made by equilibria under tensions along a line (the right arm's
    cable pulled up as the left's is let go): the path's fits meet each, and each fit's
    tensions, run through rodmol.equilibrium, put both tips on their targets to 0.1 mm.
    Started from the last fit, a target costs fewer equilibria than the same target
    solved from the system's own tensions."""
    pairs = list(zip(np.linspace(0.1, 0.3, 5), np.linspace(0.25, 0.05, 5)))
    targets = [rest(pulled(arms, {"right": right, "left": left}))[0] for right, left in pairs]
    path = {name: np.array([target[name] for target in targets]) for name in ("right", "left")}
    assert np.linalg.norm(path["right"][-1] - path["right"][0]) > 0.01  # a path, not a point
    fits = rodmol.inverse_statics_path(arms, tips=path, bounds=(0.0, 2.0))
    assert len(fits) == len(targets)
    for fit, target, tensions in zip(fits, targets, pairs):
        assert fit.reachable and "target met" in fit.message
        tips, _ = rest(fit.apply(arms))
        for name in target:
            assert np.linalg.norm(tips[name] - target[name]) < REACH
        assert [fit.tensions["right"]["cable 1"], fit.tensions["left"]["cable 1"]] == pytest.approx(tensions, abs=1e-5)
    cold = rodmol.inverse_statics(arms, tip=targets[-1], bounds=(0.0, 2.0))
    assert fits[-1].equilibria < cold.equilibria


def test_the_platform_follows_a_path_of_poses():
    """The parallel robot's platform moved and tilted along a path (each pose the forward
    equilibrium of insertions along a line): the path finds insertions whose forward
    equilibrium puts the platform on each pose, to 0.1 mm and 0.1 mrad."""
    robot = parallel_robot.robot(8)
    made = [forward(robot, list(d)) for d in np.linspace([0.0, 0.0, 0.0], [0.01, -0.005, 0.003], 4)[1:]]
    poses = [m.poses["platform"] for m in made]
    fits = rodmol.inverse_statics_path(robot, poses={"platform": poses}, insertions=LEGS)
    for fit, (position, rotation) in zip(fits, poses):
        assert fit.reachable
        again = forward(robot, fit.values).poses["platform"]
        assert np.linalg.norm(again[0] - position) < REACH
        turn = again[1] @ rotation.T
        assert np.arccos(np.clip((np.trace(turn) - 1.0) / 2.0, -1.0, 1.0)) < 1e-4
    assert np.linalg.norm(poses[-1][0] - poses[0][0]) > 0.01


@pytest.mark.parametrize("model, kwargs, named", [
    ("arms", dict(tips=[(0.2, 0.0, 0.0)]), "`tips` must map rod names to (n, 3) arrays"),
    ("arms", dict(tips={"rigth": [(0.2, 0.0, 0.0)]}), "`tips`: no rod named 'rigth'"),
    ("arms", dict(tips={"right": [(0.2, 0.0)]}), "`tips['right']` must be an (n, 3) array"),
    ("arms", dict(tips={"right": [(0.2, 0.0, 0.0)] * 2, "left": [(-0.2, 0.0, 0.0)] * 3}), "has 2 targets, others 3"),
    ("arms", dict(poses={"head": [(0.0, 0.0, 0.0), ((0.0, 0.0, 0.0), np.ones((3, 3)))]}),
     "target 1 of the path: `pose['head'] rotation`"),
    ("arms", dict(poses={"head": 3.0}), "`poses['head']` must be a sequence of poses"),
    ("arms", dict(), "give a path"),
    ("arms", dict(tips={"right": [(0.2, 0.0, 0.0)]}, markers={}), "unknown options ['markers']"),
    ("arms", dict(tips={"right": [(0.2, 0.0, 0.0)]}, max_iter=0), "`max_iter`"),
    ("arms", dict(tips={"right": [(0.2, 0.0, 0.0)]}, start=[0.1]), "`start` must be 2"),
    ("rod", dict(tips=[(0.2, 0.0, 0.0)], poses={"head": [(0.0, 0.0, 0.0)]}), "`poses` is for a rodmol.System"),
    ("rod", dict(tips=[(0.2, 0.0, 0.0)], insertions=["leg0"]), "`insertions` is for a rodmol.System"),
])
def test_bad_paths_are_named_before_any_equilibrium(arms, monkeypatch, model, kwargs, named):
    def no_work(*args, **kwargs):
        raise AssertionError("an equilibrium was solved")

    for module in ("rodmol.control.system_statics", "rodmol.control.inverse_statics"):
        for name in ("continuation", "damped_newton", "rest_state"):
            if hasattr(sys.modules[module], name):
                monkeypatch.setattr(sys.modules[module], name, no_work)
    model = arms if model == "arms" else rodmol.paper_arm(4)
    with pytest.raises(rodmol.ParameterError) as caught:
        rodmol.inverse_statics_path(model, **kwargs)
    assert named in str(caught.value)


def test_a_floating_system_has_no_path(tmp_path):
    free = rodmol.load_scenario(Path(__file__).resolve().parents[2] / "examples" / "two_arms.toml").model
    with pytest.raises(rodmol.ParameterError, match="held by nothing"):
        rodmol.inverse_statics_path(free, tips={"right": [(0.2, 0.0, 0.0)]})

