"""The gymnasium environment rodmol/OctopusCrawl-v0: gymnasium's checks, determinism, reward,
the option checks, vectorised form."""

import warnings

import numpy as np
import pytest

gymnasium = pytest.importorskip("gymnasium")
crawl = pytest.importorskip("rodmol.control.crawl")

import rodmol  # noqa: E402, F401 (registers the environments)
from rodmol.errors import ParameterError  # noqa: E402

SMALL = dict(n_elements=3, settle=0.05, episode_steps=3)  # the tests check the interface, not the physics


@pytest.fixture(scope="module")
def env():
    made = gymnasium.make("rodmol/OctopusCrawl-v0", **SMALL)
    yield made
    made.close()


def test_passes_gymnasiums_checker(env):
    from gymnasium.utils.env_checker import check_env

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)  # its advice (bounded boxes) is not an error
        check_env(env.unwrapped, skip_render_check=True)


def rollout(env, seed, steps=3):
    obs, _ = env.reset(seed=seed)
    actions = np.random.default_rng(seed).uniform(0.0, 1.0, (steps, 16)).astype(np.float32)
    trace = [obs]
    for action in actions:
        obs, reward, terminated, truncated, info = env.step(action)
        trace.append(np.append(obs, [reward, terminated, truncated]))
    return trace, actions, info


def test_same_seed_same_trajectory_and_reward_as_documented(env):
    first, actions, info = rollout(env, seed=3)
    rollout(env, seed=4)
    again, _, _ = rollout(env, seed=3)
    for a, b in zip(first, again):
        np.testing.assert_array_equal(a, b)
    assert first[-1][-1] == 1.0  # truncated after episode_steps
    sim = env.unwrapped.sim
    head = sim.result["head"].position
    effort = env.unwrapped.effort_weight * float(actions[-1].astype(float) @ actions[-1].astype(float))
    speed = (head[-1, 0] - head[-2, 0]) / env.unwrapped.period
    assert info["speed"] == pytest.approx(speed, rel=1e-12)
    assert first[-1][crawl.OBSERVATION_SIZE] == pytest.approx(speed - effort, rel=1e-6)
    # the observation: the head's pose, then the tips relative to it
    np.testing.assert_allclose(first[-1][:3], head[-1], rtol=1e-6)
    tip = sim.state["arm3"].tip - sim.state["head"].position
    np.testing.assert_allclose(first[-1][13 + 6:13 + 9], tip, rtol=1e-5, atol=1e-7)
    # the actions reached the cables: arm 1's cables 2 and 4 held as the last action asked
    held = sim.held["arm1"]["tensions"]
    assert (held["cable 2"], held["cable 4"]) == pytest.approx(tuple(actions[-1][:2].astype(float)))


@pytest.mark.parametrize("option, value", [
    ("n_elements", 1), ("n_elements", 2.5), ("period", 0.0), ("period", float("nan")), ("episode_steps", 0),
    ("max_tension", -1.0), ("max_tension", float("inf")), ("effort_weight", -1.0), ("settle", 0.0),
    ("record", 3), ("record", " "), ("overwrite", "yes"), ("rtol", 0.0), ("rtol", 1.0),
])
def test_every_option_is_checked_at_construction_naming_it(monkeypatch, option, value):
    def no_work(*args, **kwargs):
        raise AssertionError("the octopus was built before the options were checked")

    monkeypatch.setattr(crawl, "octopus", no_work)
    with pytest.raises(ParameterError, match=f"`{option}`") as info:
        crawl.OctopusCrawlEnv(**{option: value})
    assert repr(value) in str(info.value) or str(value) in str(info.value)


def test_non_finite_actions_and_steps_after_the_end(env):
    env.reset(seed=0)
    action = np.full(16, np.nan, dtype=np.float32)
    action[0] = np.inf
    _, _, _, _, info = env.step(action)
    assert info["non_finite"] == 16
    held = env.unwrapped.sim.held["arm1"]["tensions"]
    assert held["cable 2"] == env.unwrapped.max_tension and held["cable 4"] == 0.0
    with pytest.raises(ParameterError, match="`action` must be 16 numbers"):
        env.step(np.zeros(12, dtype=np.float32))
    env.step(np.zeros(16, dtype=np.float32))
    env.step(np.zeros(16, dtype=np.float32))
    with pytest.raises(crawl.ResetNeeded, match="truncated at step 3"):
        env.step(np.zeros(16, dtype=np.float32))


def test_records_each_episode_as_a_readable_series_of_its_states(tmp_path):
    """Every episode streamed into record/episode_NNNN: rodmol.load_result reads back the
    episode's states bitwise (the settled start, then one frame per step) and the tensions
    held; ParaView's series of each part is written; the observations are those of an
    environment that does not record."""
    env = crawl.OctopusCrawlEnv(**SMALL, record=tmp_path)
    plain = crawl.OctopusCrawlEnv(**SMALL)
    states, actions = {}, {}
    for episode in (1, 2):
        actions[episode] = np.array([[0.2 * k + 0.1 * episode] * 16 for k in range(3)], dtype=np.float32)
        observations = []
        for made in (plain, env):  # env last: its states are the episode's
            observations.append([made.reset(seed=episode)[0]])
            states[episode] = [made.sim.y]
            for action in actions[episode]:
                observations[-1].append(made.step(action)[0])
                states[episode].append(made.sim.y)
        np.testing.assert_array_equal(observations[0], observations[1])
    env.close()
    for episode in (1, 2):
        folder = tmp_path / f"episode_{episode:04d}"
        stored = rodmol.load_result(folder)
        assert stored.success and np.allclose(stored.t, [0.0, 0.05, 0.1, 0.15])
        np.testing.assert_array_equal(stored.states, states[episode])
        np.testing.assert_array_equal(stored["arm1"].tensions[1:, 1], actions[episode][:, 0])  # cable 2
        assert (folder / "system.h5").is_file()
        assert list(folder.glob("*.xdmf"))


def test_a_record_holding_episodes_is_refused_before_any_work_unless_overwritten(tmp_path, monkeypatch):
    env = crawl.OctopusCrawlEnv(**SMALL, record=tmp_path)
    env.reset(seed=0)
    env.step(np.zeros(16, dtype=np.float32))
    env.close()

    def no_work(*args, **kwargs):
        raise AssertionError("the octopus was built before the record was claimed")

    with monkeypatch.context() as patched:
        patched.setattr(crawl, "octopus", no_work)
        with pytest.raises(ParameterError, match="episode_0001.*overwrite=True"):
            crawl.OctopusCrawlEnv(**SMALL, record=tmp_path)
    again = crawl.OctopusCrawlEnv(**SMALL, record=tmp_path, overwrite=True)
    assert not (tmp_path / "episode_0001").exists()  # the earlier episodes went at construction
    again.reset(seed=0)
    again.close()
    assert rodmol.load_result(tmp_path / "episode_0001").success


@pytest.mark.subprocess
def test_vectorised_in_parallel_processes():
    vec = crawl.vector_env(2, **SMALL)
    try:
        obs, _ = vec.reset(seed=[0, 1])
        assert obs.shape == (2, crawl.OBSERVATION_SIZE)
        np.testing.assert_array_equal(obs[0], obs[1])  # one settled start
        for _ in range(3):
            obs, reward, terminated, truncated, _ = vec.step(np.full((2, 16), 0.5, dtype=np.float32))
        assert np.all(np.isfinite(reward)) and truncated.all()
    finally:
        vec.close()


def test_rtol_is_the_episodes_tolerance():
    """The env's rtol reaches the integrator (a tighter one changes the trajectory, by less than
    the looser one's error) and not the settled start state (the same for both)."""
    traces = {}
    for rtol in (crawl.RTOL, 1e-7):
        made = crawl.OctopusCrawlEnv(rtol=rtol, **SMALL)
        traces[rtol], _, _ = rollout(made, seed=5)
    loose, tight = traces[crawl.RTOL], traces[1e-7]
    np.testing.assert_array_equal(loose[0], tight[0])
    assert not np.array_equal(loose[-1][:3], tight[-1][:3])
    np.testing.assert_allclose(loose[-1][:3], tight[-1][:3], rtol=0.0, atol=1e-5)
