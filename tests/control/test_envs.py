"""The gymnasium environment rodmol/Reach-v0: gymnasium's checks, determinism, reward, vectorised form."""

import subprocess
import sys
import warnings

import numpy as np
import pytest

gymnasium = pytest.importorskip("gymnasium")
envs = pytest.importorskip("rodmol.control.envs")

import rodmol  # noqa: E402

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
def test_rodmol_imports_without_gymnasium():
    code = ("import sys; sys.modules['gymnasium'] = None; import rodmol, rodmol.control; "
            "print(rodmol.Simulator.__name__)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert out.returncode == 0 and "Simulator" in out.stdout, out.stderr
