"""``rodmol/OctopusCrawl-v0``: the octopus of ``examples/octopus.py`` crawling on the
sea floor (``pip install rodmol[rl]``). ``import rodmol`` registers it with gymnasium
(:mod:`rodmol.control.registration`), whose ``make`` imports this module::

    import gymnasium
    import rodmol

    env = gymnasium.make("rodmol/OctopusCrawl-v0")
    envs = rodmol.control.crawl.vector_env(4)  # in parallel processes (after importing it)
"""

import functools

import gymnasium
import numpy as np
from gymnasium import spaces

from .. import _checks
from ..errors import IntegrationError, ParameterError
from ..solve import options as solver_options
from . import envs
from .envs import ResetNeeded, action_tensions, episode_end
from .octopus import ARMS, octopus
from .simulator import Simulator

CRAWL_ID = "rodmol/OctopusCrawl-v0"  # registered by rodmol.control.registration
#: The cables each arm's actions pull: 2 (below the centreline: the arm curls down onto the
#: floor) and 4 (above it: the arm curls up), Table II's numbering.
CABLES = (2, 4)
ARM_NAMES = tuple(f"arm{i + 1}" for i in range(ARMS))
#: The integrator's relative tolerance over the episodes: 6.7 times the default scheme's, whose
#: time error is meant to be a tenth of its spatial error at the paper's N = 100 (at N = 6 that
#: is far larger). Over 2 s slack, of the example's gait or of random actions the head stays
#: within 2 um of a run at rtol = 3e-6 (the tips within 4 um), and the environment costs 0.67-0.78
#: times what it does at the scheme's 3e-5 (solvers/crawl_speed.py, docs/performance.md).
RTOL = 2e-4
#: Observation size: the head's position (3), quaternion (4), velocity and angular velocity
#: (3 + 3, global frame) and each arm's tip relative to the head (3 per arm).
OBSERVATION_SIZE = 13 + 3 * ARMS

#: Each option of :class:`OctopusCrawlEnv` -> its check ``(name, value)`` -> the value, naming
#: the option and the value it refuses; all run at construction, before any work.
OPTIONS = {
    "n_elements": lambda name, value: _checks.integer_at_least(name, value, 2),
    "period": lambda name, value: _checks.positive(name, value, " s"),
    "episode_steps": lambda name, value: _checks.integer_at_least(name, value, 1),
    "max_tension": envs._max_tension,
    "effort_weight": lambda name, value: _checks.non_negative(name, value, " m/(s N^2)"),
    "settle": lambda name, value: _checks.positive(name, value, " s"),
    "record": envs._record,
    "overwrite": _checks.flag,
    "rtol": lambda name, value: solver_options.rtol(value),
}


@functools.lru_cache(maxsize=4)
def settled(n_elements, settle):
    """The octopus's state (N = ``n_elements`` per arm) after ``settle`` seconds on the floor
    from rest without tension, computed once per process (each environment starts from it)."""
    sim = Simulator(octopus(n_elements))
    sim.step(settle)
    return sim.y


class OctopusCrawlEnv(gymnasium.Env):
    """Crawl forward (+x) with the octopus of ``examples/octopus.py``, pulling two cables of each arm.

    Every ``period`` seconds the agent sets 16 tensions (held over the period,
    :class:`rodmol.Simulator` of the System). Every episode starts from the same state, the
    octopus settled on the floor (``settle`` seconds from rest, computed once per process
    and restored bitwise at each reset), and lasts ``episode_steps`` periods (truncated
    then); it ends early (terminated) only if a step fails (``info["failure"]``). The
    environment draws nothing at random: the same actions give the same observations.

    Spaces
    ------
    action : Box(0, max_tension, (16,)) [N]: arm 1's cables 2 and 4, arm 2's, ... arm 8's
        (arm k leaves the head at 45 (k - 1) degrees from +x; cable 2 curls the arm down,
        cable 4 up; Table II's numbering).
    observation : Box (37,) float32, global frame [m, m/s, rad/s]: the head's position (3),
        quaternion (4, scalar first), velocity and angular velocity (3 + 3), and each arm's
        tip relative to the head's position (8 x 3).

    Reward
    ------
    ``dx / period - effort_weight * |T|^2`` per step [m/s]: the head's forward speed over
    the period (dx its displacement along +x) less the effort, T the action [N].

    Actions outside [0, ``max_tension``], NaN or infinite ones are handled as by
    ``rodmol/Reach-v0`` (clipped; ``info["non_finite"]`` counts them); ``step`` before the
    first ``reset`` or after the episode ended raises :class:`ResetNeeded`.

    Parameters
    ----------
    n_elements : int
        Elements N of each arm (6; its speed: docs/control.md).
    period : float
        Control period [s], > 0.
    episode_steps : int
        Periods per episode, >= 1 (60 x 0.05 s: 3 s).
    max_tension : float
        Upper bound of each tension [N], > 0 and finite.
    effort_weight : float
        Weight of the effort in the reward [m/(s N^2)], >= 0.
    settle : float
        Time [s] the octopus settles on the floor before the episodes' start state.
    record : path, optional
        Stream every episode into ``record/episode_NNNN`` (``system.h5`` and ParaView's
        series of each part: :func:`rodmol.load_result` reads it back), through the
        Simulator's ``out`` (:class:`rodmol.control.envs.Recording`).
    overwrite : bool
        With ``record``: replace the episodes recorded there earlier, all of them (otherwise
        refused when the environment is made).
    rtol : float
        CVODE's relative tolerance over the episodes (:data:`RTOL`; the settling runs at the
        scheme's default).
    """

    metadata = {"render_modes": []}

    def __init__(self, n_elements=6, period=0.05, episode_steps=60, max_tension=2.0, effort_weight=1e-3,
                 settle=1.0, record=None, overwrite=False, rtol=RTOL):
        given = dict(n_elements=n_elements, period=period, episode_steps=episode_steps, max_tension=max_tension,
                     effort_weight=effort_weight, settle=settle, record=record, overwrite=overwrite, rtol=rtol)
        options = {name: check(name, given[name]) for name, check in OPTIONS.items()}
        self.n_elements, self.period = options["n_elements"], options["period"]
        self.episode_steps, self.max_tension = options["episode_steps"], options["max_tension"]
        self.effort_weight, self.settle = options["effort_weight"], options["settle"]
        self.record, self.rtol = options["record"], options["rtol"]
        self._recording = envs.Recording(self.record, options["overwrite"])  # before any work
        self.system = octopus(self.n_elements)
        self._y0 = settled(self.n_elements, self.settle)
        self.sim = Simulator(self.system, initial=self._y0, rtol=self.rtol)
        self._start = self.sim.copy()
        self.action_space = spaces.Box(0.0, self.max_tension, (ARMS * len(CABLES),), np.float32)
        self.observation_space = spaces.Box(-np.inf, np.inf, (OBSERVATION_SIZE,), np.float32)
        self._steps, self._ended = 0, "before the first reset()"

    def reset(self, *, seed=None, options=None):
        if not (options is None or (isinstance(options, dict) and not options)):  # none is read: not ignored
            raise ParameterError(f"`options` {_checks.short(options)}: {type(self).__name__}.reset "
                                 "takes none (None or {})")
        super().reset(seed=seed)
        self.sim = self._recording.next_episode(self.sim, self._start, self.system, self._y0, rtol=self.rtol)
        self._steps, self._ended = 0, None
        return self._observation(self.sim.state), {}

    def step(self, action):
        if self._ended is not None:
            raise ResetNeeded(f"step() {self._ended}: call reset() to start an episode")
        tensions, non_finite = action_tensions(action, self.action_space.shape[0], self.max_tension,
                                               "cables 2 and 4 of arms 1-8")
        commands = {arm: {f"cable {c}": float(tensions[len(CABLES) * i + j]) for j, c in enumerate(CABLES)}
                    for i, arm in enumerate(ARM_NAMES)}
        self._steps += 1
        info, terminated = {"non_finite": non_finite}, False
        x_before = float(self.sim.state["head"].position[0])
        try:
            self.sim.step(self.period, commands)
        except IntegrationError as exc:
            terminated, info["failure"] = True, str(exc)
        state = self.sim.state
        speed = (float(state["head"].position[0]) - x_before) / self.period
        reward = speed - self.effort_weight * float(tensions @ tensions)
        info["speed"] = speed
        truncated, self._ended = episode_end(self._steps, self.episode_steps, terminated)
        return self._observation(state), reward, terminated, truncated, info

    def close(self):
        self.sim.close()

    def _observation(self, state):
        head = state["head"]
        rotation = head.rotation
        tips = [state[arm].tip - head.position for arm in ARM_NAMES]
        return np.concatenate([head.position, head.quaternion, rotation @ head.velocity,
                               rotation @ head.angular_velocity, *tips]).astype(np.float32)


def vector_env(num_envs, **kwargs):
    """``num_envs`` :class:`OctopusCrawlEnv` (keyword arguments ``kwargs``), each in its own process."""
    return envs.vector_env(num_envs, env=OctopusCrawlEnv, **kwargs)
