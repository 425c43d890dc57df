"""The stepping simulator on a System: equal to simulate on the same held inputs, per part
views, rollouts, the checks of the parts' names, streaming."""

from bisect import bisect_left

import numpy as np
import pytest

import rodmol
from rodmol.control import Simulator
from rodmol.system_result import SystemResult

N = 6
DT = 0.02  # control period [s]
STEPS = 8
MATERIAL = rodmol.Material(E=1e5, nu=0.5, mu=300.0, rho=1080.0)


def arm(tension=None):
    """A 0.2 m arm with a cable "pull" on its local +y side (tension: its input, default slack)."""
    rod = rodmol.Rod(0.2, radius=0.01, material=MATERIAL)
    return rodmol.Model(rod, N, cables=[rodmol.Cable((0.005, 0.0), 0.2, name="pull",
                                                     tension=0.0 if tension is None else tension)])


def still(t):
    return np.zeros(3)


def small_system(tensions=None, platform_velocity=still):
    """Arms "a" and "b" on a free head, arm "c" on a driven platform (velocity: its input)."""
    tensions = tensions or {}
    head = rodmol.RigidBody(0.05, (2e-5,) * 3, volume=4e-5)
    platform = rodmol.RigidBody(0.1, (1e-4,) * 3, motion=rodmol.BaseMotion(platform_velocity, None, (0.0, 0.1, 0.0)))
    turn = np.diag([-1.0, -1.0, 1.0])  # arm b leaves the head along -x
    rods = {name: arm(tensions.get(name)) for name in ("a", "b", "c")}
    joints = [rodmol.Joint(("head", (0.02, 0.0, 0.0)), ("a", "base")),
              rodmol.Joint(("head", (-0.02, 0.0, 0.0), turn), ("b", "base")),
              rodmol.Joint(("platform", (0.0, 0.0, 0.0)), ("c", "base"))]
    return rodmol.System(rods, {"head": head, "platform": platform}, joints, medium="water")


def commands(k):
    """The inputs of step k: tensions by rod (cables by name and by index), the platform's velocity."""
    return dict(tensions={"a": {"pull": 0.2 * (k % 3)}, "c": {0: 0.1 * k}},
                motions={"platform": {"velocity": (0.0, 0.0, 0.05 if k >= 4 else 0.0)}})


def replay_knots(t, values, ramp=1e-9):
    """Knots of a piecewise-constant input: ``values[k]`` over (t[k-1], t[k]]."""
    knots = [(t[0], values[0])]
    for k in range(1, len(t)):
        knots += [(t[k - 1] + ramp, values[k]), (t[k], values[k])]
    return knots


@pytest.fixture(scope="module")
def stepped():
    sim = Simulator(small_system())
    for k in range(STEPS):
        sim.step(DT, **commands(k))
    return sim


def test_stepping_a_system_equals_simulate_on_the_same_input_table(stepped):
    result = stepped.result
    assert isinstance(result, SystemResult) and np.allclose(result.t, DT * np.arange(STEPS + 1))
    tensions = {name: replay_knots(result.t, result[name].tensions[:, 0]) for name in ("a", "c")}
    velocity = result["platform"].velocity

    def platform_velocity(t):  # the zero-order hold of the record: the value over (t[k-1], t[k]]
        return velocity[min(bisect_left(result.t, t), len(result.t) - 1)]

    replay = rodmol.simulate(small_system(tensions, platform_velocity), result.t[-1], output_times=result.t)
    assert np.ptp(result["a"].tensions) > 0.3 and np.ptp(velocity[:, 2]) == 0.05  # the inputs did act
    for name in ("a", "b", "c"):
        np.testing.assert_array_equal(replay[name].tensions, result[name].tensions)
        assert np.max(np.abs(replay[name].tip - result[name].tip)) < 1e-5
    for name in ("head", "platform"):
        assert np.max(np.abs(replay[name].position - result[name].position)) < 1e-5
    # the views handed to the controller are the result's last frame
    np.testing.assert_allclose(stepped.state["a"].tip, result["a"].tip[-1], rtol=0, atol=1e-15)
    np.testing.assert_array_equal(stepped.state["head"].position, result["head"].position[-1])
    np.testing.assert_array_equal(stepped.state["platform"].velocity, (0.0, 0.0, 0.05))
    assert stepped.held["c"]["tensions"]["pull"] == pytest.approx(0.1 * (STEPS - 1))


def test_a_system_starts_from_rest_as_simulate_does():
    sim = Simulator(small_system())
    np.testing.assert_array_equal(sim.y, rodmol.discretise.assembly.Assembly(small_system()).undeformed_state())


def test_copy_and_reset_continue_bitwise():
    sim = Simulator(small_system())
    for k in range(2):
        sim.step(DT, **commands(k))
    saved = sim.copy()

    def rollout():
        states = []
        for k in range(2, 6):
            sim.step(DT, **(commands(k) if k != 3 else {}))  # k = 3: inputs unchanged
            states.append(sim.y)
        return np.array(states)

    first = rollout()
    sim.step(DT, tensions={"b": {"pull": 1.0}})  # elsewhere
    sim.reset(saved)
    assert sim.t == saved.t and len(sim.result.t) == 3
    np.testing.assert_array_equal(rollout(), first)


@pytest.mark.parametrize("kwargs, names", [
    (dict(tensions={"arm": {"pull": 1.0}}), ["unknown rod 'arm'", "valid: 'a', 'b', 'c'"]),
    (dict(tensions={"head": {"pull": 1.0}}), ["unknown rod 'head'", "valid: 'a', 'b', 'c'"]),
    (dict(tensions={"a": {"push": 1.0}}), ["rod 'a'", "unknown cable 'push'", "valid: 'pull'"]),
    (dict(tensions={"a": {3: 1.0}}), ["rod 'a'", "index 3 is out of range"]),
    (dict(tensions={"a": {"pull": -1.0}}), ["rod 'a'", "tensions['pull']"]),
    (dict(tensions=[1.0, 2.0, 3.0]), ["`tensions` of a System must be a dict"]),
    (dict(motions={"head": {"velocity": (0, 0, 1)}}), ["unknown driven body 'head'", "not driven",
                                                       "valid: 'platform'"]),
    (dict(motions={"platform": {"speed": (0, 0, 1)}}), ["unknown key 'speed'", "'velocity', 'angular_velocity'"]),
    (dict(motions={"platform": {"velocity": (0, 0)}}), ["motions['platform']['velocity']"]),
])
def test_bad_part_and_cable_names_are_refused_naming_them_and_the_valid_ones(stepped, kwargs, names):
    t = stepped.t
    with pytest.raises(rodmol.ParameterError) as error:
        stepped.step(DT, **kwargs)
    for name in names:
        assert name in str(error.value)
    assert stepped.t == t


def test_a_rods_simulator_refuses_motions():
    with pytest.raises(rodmol.ParameterError, match="`motions`.*a Model has none"):
        Simulator(arm()).step(DT, motions={"platform": {}})


def test_a_system_with_a_feedback_tension_is_refused_naming_the_rod():
    with pytest.raises(rodmol.ParameterError, match="rod 'b': cable 'pull' has a feedback tension"):
        Simulator(small_system({"b": lambda t, state: 0.0}))


def test_streamed_system_run_is_the_stepped_one(tmp_path):
    in_memory = Simulator(small_system())
    with Simulator(small_system(), out=tmp_path / "run") as sim:
        for k in range(3):
            sim.step(DT, **commands(k))
            in_memory.step(DT, **commands(k))
    stored = rodmol.load_result(tmp_path / "run")
    assert isinstance(stored, SystemResult) and stored.success and len(stored.t) == 4
    np.testing.assert_array_equal(stored.states, in_memory.result.states)
    np.testing.assert_array_equal(stored["a"].tensions[:, 0], [0.0, 0.0, 0.2, 0.4])
    assert (tmp_path / "run" / "system.h5").is_file()
