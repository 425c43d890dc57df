"""The gymnasium environment rodmol/Reach-v0: gymnasium's checks, determinism, reward, vectorised form."""

import subprocess
import sys
import warnings

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

gymnasium = pytest.importorskip("gymnasium")
envs = pytest.importorskip("rodmol.control.envs")

import rodmol  # noqa: E402
from rodmol.errors import IntegrationError, ParameterError, RodmolError  # noqa: E402

N = 8  # elements: the tests check the interface, not the physics


@pytest.fixture(scope="module")
def env():
    made = gymnasium.make("rodmol/Reach-v0", n_elements=N, episode_steps=5)
    yield made
    made.close()


def test_passes_gymnasiums_checker(env):
    from gymnasium.utils.env_checker import check_env

    with warnings.catch_warnings():
        # Its advice (a symmetric action box, bounded observations) is not an error.
        warnings.simplefilter("ignore", UserWarning)
        check_env(env.unwrapped, skip_render_check=True)


def rollout(env, seed, steps=4):
    obs, info = env.reset(seed=seed)
    actions = np.random.default_rng(seed).uniform(0.0, 2.0, (steps, 12)).astype(np.float32)
    trace = [obs]
    for action in actions:
        obs, reward, terminated, truncated, info = env.step(action)
        trace.append(np.append(obs, [reward, terminated, truncated]))
    return trace, actions, info


def test_same_seed_same_trajectory_and_reward_as_documented(env):
    first, actions, info = rollout(env, seed=7)
    rollout(env, seed=8)  # another episode in between
    again, _, _ = rollout(env, seed=7)
    for a, b in zip(first, again):
        np.testing.assert_array_equal(a, b)
    assert not np.array_equal(first[0], rollout(env, seed=8)[0][0])  # the target moved
    # reward = -|tip - target| - effort_weight |T|^2; the observation ends with target - tip.
    obs, reward = first[-1][:21], first[-1][21]
    effort = env.unwrapped.effort_weight * float(actions[-1].astype(float) @ actions[-1].astype(float))
    assert reward == pytest.approx(-np.linalg.norm(obs[18:21]) - effort, rel=1e-6)
    assert info["distance"] == pytest.approx(np.linalg.norm(obs[18:21]), rel=1e-6)
    assert first[-1][-1] == 0.0 and rollout(env, seed=7, steps=5)[0][-1][-1] == 1.0  # truncated at 5


def test_observation_is_the_simulators_state(env):
    obs, info = env.reset(seed=1)
    state = env.unwrapped.sim.state
    np.testing.assert_allclose(obs[:3], state.tip, rtol=1e-6)
    np.testing.assert_allclose(obs[6:15], state.markers[:3].ravel(), rtol=1e-6)
    np.testing.assert_allclose(obs[15:18], info["target"], rtol=1e-6)
    reach = np.linalg.norm(info["target"]) / rodmol.arm.LENGTH
    assert envs.TARGET_REACH[0] <= reach <= envs.TARGET_REACH[1]


def test_records_an_episode_for_paraview(tmp_path):
    env = envs.ReachEnv(n_elements=N, record=tmp_path)
    env.reset(seed=0)
    for _ in range(3):
        env.step(np.full(12, 0.5, dtype=np.float32))
    env.close()
    result = rodmol.load_result(tmp_path / "episode_0001")
    assert len(result.t) == 4 and result.success
    np.testing.assert_array_equal(result.tensions[1:], 0.5)
    assert (tmp_path / "episode_0001" / "rod.xdmf").is_file()


@pytest.mark.parametrize("option, value", [
    ("period", -0.02), ("period", float("nan")), ("period", 0.0), ("period", "0.02"),
    ("episode_steps", 0), ("episode_steps", 2.5), ("episode_steps", "10"),
    ("max_tension", -1.0), ("max_tension", float("inf")), ("max_tension", float("nan")), ("max_tension", 1e300),
    ("effort_weight", -1e-3), ("effort_weight", float("nan")),
    ("record", 3), ("record", " "), ("overwrite", "yes"),
])
def test_every_option_is_checked_at_construction_naming_it(monkeypatch, option, value):
    def no_work(*args, **kwargs):
        raise AssertionError("the arm was built before the options were checked")

    monkeypatch.setattr(envs, "paper_arm", no_work)
    with pytest.raises(ParameterError, match=f"`{option}`") as info:
        envs.ReachEnv(**{option: value})
    assert repr(value) in str(info.value) or str(value) in str(info.value)


def test_gymnasium_make_refuses_a_bad_option_naming_it():
    with pytest.raises(ParameterError, match="`episode_steps` must be >= 1, got 0"):
        gymnasium.make("rodmol/Reach-v0", n_elements=N, episode_steps=0)


def test_a_step_before_reset_or_after_the_episode_ended_raises_until_reset():
    env = envs.ReachEnv(n_elements=N, episode_steps=2)
    action = np.ones(12, dtype=np.float32)
    with pytest.raises(envs.ResetNeeded, match="before the first reset"):
        env.step(action)
    env.reset(seed=0)
    assert not env.step(action)[3] and env.step(action)[3]  # truncated at the second step
    with pytest.raises(gymnasium.error.ResetNeeded, match="truncated at step 2") as info:
        env.step(action)
    assert isinstance(info.value, RodmolError)
    env.reset(seed=0)
    env.step(action)

    def fails(*args, **kwargs):
        raise IntegrationError("the step failed")

    env.sim.step = fails  # a blow-up: the episode terminates
    assert env.step(action)[2]
    with pytest.raises(envs.ResetNeeded, match="terminated at step 2"):
        env.step(action)


def test_reset_refuses_options_it_would_ignore(env):
    env.reset(seed=0, options={})
    for options in ({"target": (0.2, 0.0, 0.0)}, np.zeros(3), "target"):
        with pytest.raises(ParameterError, match="`options`"):
            env.unwrapped.reset(seed=0, options=options)


@pytest.mark.parametrize("action", [np.ones(11), "pull", np.ones((2, 12)), None])
def test_an_action_of_another_shape_is_refused_naming_it(env, action):
    env.reset(seed=0)
    with pytest.raises(ParameterError, match="`action` must be 12 numbers"):
        env.step(action)


def first_step(env, action):
    env.reset(seed=3)
    return env.step(action)


@settings(max_examples=25, deadline=None, derandomize=True,
          suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture])
@given(action=st.lists(st.one_of(st.floats(-10.0, 10.0), st.sampled_from([np.nan, np.inf, -np.inf])),
                       min_size=12, max_size=12))
def test_a_non_finite_action_never_raises_and_acts_as_documented(env, action):
    action = np.array(action, dtype=np.float32)
    obs, reward, terminated, truncated, info = first_step(env, action)
    assert np.all(np.isfinite(obs)) and np.isfinite(reward) and not terminated
    assert info["non_finite"] == np.count_nonzero(~np.isfinite(action))
    # NaN pulls with 0 N, +-inf with the bound it points to, the rest clipped to [0, max_tension]
    high = env.unwrapped.max_tension
    meant = np.clip(np.nan_to_num(action, nan=0.0, posinf=high, neginf=0.0), 0.0, high)
    again = first_step(env, meant)
    np.testing.assert_array_equal(obs, again[0])
    assert reward == again[1]


@pytest.mark.subprocess
def test_vectorised_in_parallel_processes():
    vec = gymnasium.make_vec("rodmol/Reach-v0", num_envs=2, vectorization_mode="async",
                             n_elements=N, episode_steps=3)
    try:
        obs, _ = vec.reset(seed=[0, 1])
        assert obs.shape == (2, 21) and not np.array_equal(obs[0], obs[1])
        for _ in range(3):
            obs, reward, terminated, truncated, _ = vec.step(np.ones((2, 12), dtype=np.float32))
        assert reward.shape == (2,) and np.all(np.isfinite(reward)) and truncated.all()
    finally:
        vec.close()
    single = envs.ReachEnv(n_elements=N, episode_steps=3)
    single.reset(seed=1)
    for _ in range(3):
        last = single.step(np.ones(12, dtype=np.float32))[0]
    np.testing.assert_array_equal(obs[1], last)  # a worker process steps as this one does


@pytest.mark.subprocess
def test_import_rodmol_alone_registers_the_environments():
    """In a fresh interpreter: ``import rodmol`` registers rodmol/Reach-v0, and its module is
    imported by gymnasium.make only."""
    code = ("import sys, rodmol, gymnasium; assert 'rodmol.control.envs' not in sys.modules; "
            "env = gymnasium.make('rodmol/Reach-v0', n_elements=4, episode_steps=2); "
            "observation, _ = env.reset(seed=0); print(type(env.unwrapped).__name__, observation.shape)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300)
    assert out.returncode == 0 and "ReachEnv (21,)" in out.stdout, out.stderr[-2000:]


@pytest.mark.subprocess
def test_rodmol_imports_without_gymnasium():
    code = ("import sys; sys.modules['gymnasium'] = None; import rodmol, rodmol.control; "
            "assert not rodmol.control.register_environments(); print(rodmol.Simulator.__name__)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert out.returncode == 0 and "Simulator" in out.stdout, out.stderr


def test_state_and_held_inputs_give_a_linear_model_that_predicts_the_next_tip():
    """A model-based controller reads the whole state, the time and the held tensions: the
    linear model taken there (drift included: the arm is moving) predicts the tip of the next
    observation under a new action, much closer than the tip's own motion over the step."""
    env = envs.ReachEnv(n_elements=N, episode_steps=10)
    env.reset(seed=4)
    rng = np.random.default_rng(4)
    for _ in range(2):
        env.step(rng.uniform(0.0, 1.0, 12).astype(np.float32))
    assert "failure" not in env.step(rng.uniform(0.0, 1.0, 12).astype(np.float32))[-1]
    np.testing.assert_array_equal(env.held, env.sim.result.tensions[-1])
    assert env.t == pytest.approx(3 * env.period)
    lin = rodmol.linearize(env.held_model(), env.state, env.t).output("tip").discretize(env.period)
    np.testing.assert_array_equal(lin.u0, env.held)
    action = rng.uniform(0.0, 1.0, 12).astype(np.float32)
    u = action.astype(float) - lin.u0
    predicted = lin.y0 + lin.C @ (lin.B @ u + lin.f0) + lin.D @ u
    without_drift = lin.y0 + lin.C @ (lin.B @ u) + lin.D @ u
    tip = env.step(action)[0][:3]
    moved, error = np.linalg.norm(tip - lin.y0), np.linalg.norm(predicted - tip)
    assert moved > 5e-3  # it moved 5 mm or more
    # measured 1.1 mm off a 17.6 mm move (tensions changed by up to 1 N: second order); 13 mm without the drift
    assert error < 0.1 * moved and error < 0.5 * np.linalg.norm(without_drift - tip)
    env.close()
