"""gymnasium environments of the paper's arm (``pip install rodmol[rl]``).

Importing this module registers ``"rodmol/Reach-v0"`` (:class:`ReachEnv`)::

    import gymnasium
    import rodmol.control.envs  # noqa: F401  (registers the environments)

    env = gymnasium.make("rodmol/Reach-v0")
    envs = rodmol.control.envs.vector_env(4)  # in parallel processes

``gymnasium.make("rodmol.control.envs:rodmol/Reach-v0")`` imports it too.
rodmol itself never imports this module, so it works without gymnasium.
"""

import contextlib
import functools
from pathlib import Path

import gymnasium
import numpy as np
from gymnasium import spaces

from ..arm import CABLE_OFFSETS, paper_arm
from ..errors import IntegrationError
from .simulator import Simulator

REACH_ID = "rodmol/Reach-v0"
#: Distance of the targets from the base [fraction of L], and largest angle [rad] from the base axis.
TARGET_REACH = (0.8, 0.97)
TARGET_CONE = np.radians(45.0)


class ReachEnv(gymnasium.Env):
    """Reach a target with the tip of the paper's arm in water, pulling its 12 cables.

    Every ``period`` seconds the agent sets the 12 tensions (held over the
    period, :class:`rodmol.Simulator`). An episode starts from the arm at
    rest without tension and lasts ``episode_steps`` periods (truncated
    then); it ends early (terminated) only if a step fails (blow-up, see
    ``info["failure"]``).

    Spaces
    ------
    action : Box(0, max_tension, (12,)) [N], the tensions of cables 1-12
        (Table II's numbering).
    observation : Box (21,) float32, global frame [m, m/s]: the tip position
        (3), the tip velocity (3), the paper's markers at L1, L2, L3 (9) and
        the target (3), and the target minus the tip (3).

    Reward
    ------
    ``-|tip - target| - effort_weight * |T|^2`` per step [m], with T the
    action [N] (``effort_weight`` in m/N^2).

    Targets: points at ``TARGET_REACH`` (0.8-0.97) L from the base within
    ``TARGET_CONE`` (45 degrees) of the base axis, uniform in solid angle
    (the tip at rest, 22 degrees below the axis in water, lies inside; that
    every target is reachable exactly is not checked: the reward is the
    distance). They come from the environment's seeded generator
    (``reset(seed=...)``), and a reset restores the start state bitwise, so
    episodes are reproducible.

    Parameters
    ----------
    n_elements : int
        Elements N of the arm (30: faster than real time on one core).
    period : float
        Control period [s].
    episode_steps : int
        Periods per episode.
    max_tension : float
        Upper bound of each tension [N].
    effort_weight : float
        Weight of the effort in the reward [m/N^2].
    record : path, optional
        Stream every episode into ``record/episode_NNNN`` (``result.h5`` and
        ParaView's ``rod.xdmf``), through the Simulator's ``out``.
    overwrite : bool
        With ``record``: replace the episodes recorded there earlier, all of them (otherwise
        refused when the environment is made).
    """

    metadata = {"render_modes": []}

    def __init__(self, n_elements=30, period=0.02, episode_steps=100, max_tension=4.0,
                 effort_weight=1e-3, record=None, overwrite=False):
        self.period, self.episode_steps = float(period), int(episode_steps)
        self.max_tension, self.effort_weight = float(max_tension), float(effort_weight)
        if record is not None:  # before any work: the episodes recorded there earlier
            _claim_record(Path(record), overwrite)
        self.model = paper_arm(n_elements, medium="water")
        self.sim = Simulator(self.model)
        self._start, self._y0 = self.sim.copy(), self.sim.y
        self.record, self._episodes = (None if record is None else Path(record)), 0
        self._overwrite = bool(overwrite)
        self.action_space = spaces.Box(0.0, self.max_tension, (len(CABLE_OFFSETS),), np.float32)
        self.observation_space = spaces.Box(-np.inf, np.inf, (21,), np.float32)
        self.target, self._steps = self.sim.state.tip.copy(), 0

    # ----------------------------------------------------------------- gymnasium's API

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        self.target = self._draw_target()
        if self.record is not None:
            self.sim.close()
            self._episodes += 1
            self.sim = Simulator(self.model, initial=self._y0,
                                 out=self.record / f"episode_{self._episodes:04d}",
                                 overwrite=self._overwrite)
        else:
            self.sim.reset(self._start)
        self._steps = 0
        return self._observation(self.sim.state), {"target": self.target.copy()}

    def step(self, action):
        tensions = np.clip(np.asarray(action, dtype=float), 0.0, self.max_tension)
        self._steps += 1
        info, terminated = {}, False
        try:
            self.sim.step(self.period, tensions)
        except IntegrationError as exc:
            terminated, info["failure"] = True, str(exc)
        state = self.sim.state  # one view: its positions are rebuilt once
        distance = float(np.linalg.norm(state.tip - self.target))
        reward = -distance - self.effort_weight * float(tensions @ tensions)
        info["distance"] = distance
        truncated = self._steps >= self.episode_steps and not terminated
        return self._observation(state), reward, terminated, truncated, info

    def close(self):
        self.sim.close()

    # ----------------------------------------------------------------- internals

    def _observation(self, state):
        tip_velocity = state.rotations[-1] @ state.v[-1]  # local to global
        return np.concatenate([state.tip, tip_velocity, state.markers[:3].ravel(), self.target,
                               self.target - state.tip]).astype(np.float32)

    def _draw_target(self):
        """A target [m], global: at a distance ``TARGET_REACH`` x L from the base, within
        ``TARGET_CONE`` of the base axis (x), uniform in solid angle."""
        rng = self.np_random
        cos_cone = np.cos(TARGET_CONE)
        cos_theta = rng.uniform(cos_cone, 1.0)
        phi = rng.uniform(0.0, 2.0 * np.pi)
        sin_theta = np.sqrt(1.0 - cos_theta**2)
        direction = np.array([cos_theta, sin_theta * np.cos(phi), sin_theta * np.sin(phi)])
        return rng.uniform(*TARGET_REACH) * self.model.rod.length * direction


def vector_env(num_envs, **kwargs):
    """``num_envs`` :class:`ReachEnv` (keyword arguments ``kwargs``), each in its own process
    (``gymnasium.vector.AsyncVectorEnv``)."""
    return gymnasium.vector.AsyncVectorEnv([functools.partial(ReachEnv, **kwargs)] * int(num_envs))


if REACH_ID not in gymnasium.registry:
    gymnasium.register(REACH_ID, entry_point=ReachEnv)


def _claim_record(record, overwrite):
    """Refuse the episodes recorded in ``record`` earlier unless ``overwrite``, which removes them
    all (a shorter recording would leave the later ones): :func:`rodmol.output.run_files.claim`."""
    from ..output import run_files

    episodes = sorted(record.glob("episode_[0-9][0-9][0-9][0-9]*")) if record.is_dir() else []
    for folder in episodes:
        run_files.refuse_replacing(folder, overwrite)
    for folder in episodes:
        run_files.claim(folder, True)
        with contextlib.suppress(OSError):  # holds files not rodmol's
            folder.rmdir()
