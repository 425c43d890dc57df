"""gymnasium environments of the paper's arm (``pip install rodmol[rl]``).

``import rodmol`` registers ``"rodmol/Reach-v0"`` (:class:`ReachEnv`) with
gymnasium (:mod:`rodmol.control.registration`), whose ``make`` imports this
module::

    import gymnasium
    import rodmol

    env = gymnasium.make("rodmol/Reach-v0")
    envs = rodmol.control.envs.vector_env(4)  # in parallel processes (after importing it)

rodmol itself never imports this module, so it works without gymnasium.
"""

import contextlib
import functools
import os
from pathlib import Path

import gymnasium
import numpy as np
from gymnasium import spaces

from .. import _checks
from ..arm import CABLE_OFFSETS, paper_arm
from ..errors import IntegrationError, ParameterError, RodmolError
from .simulator import Simulator

REACH_ID = "rodmol/Reach-v0"  # registered by rodmol.control.registration
#: Distance of the targets from the base [fraction of L], and largest angle [rad] from the base axis.
TARGET_REACH = (0.8, 0.97)
TARGET_CONE = np.radians(45.0)


class ResetNeeded(RodmolError, gymnasium.error.ResetNeeded):
    """``step`` before the first ``reset`` or after the episode ended (terminated or truncated):
    gymnasium's contract, which its ``OrderEnforcing`` wrapper (``gymnasium.make``) enforces
    before the first reset only."""


def _record(name, value):
    """A directory to record into (a path, not made yet), or None."""
    if value is None:
        return None
    if not isinstance(value, (str, os.PathLike)) or not str(os.fspath(value)).strip():
        raise ParameterError(f"`{name}` must be a directory (a path) or None, got {_checks.short(value)}")
    return Path(value)


def _max_tension(name, value):
    """A tension bound [N] > 0 that the float32 action box holds."""
    bound = _checks.positive(name, value, " N")
    if bound > float(np.finfo(np.float32).max):
        raise ParameterError(f"`{name}` must fit the float32 action box (<= 3.4e38 N), "
                             f"got {_checks.short(value)}")
    return bound


#: Each option of :class:`ReachEnv` -> its check ``(name, value)`` -> the value, which names the
#: option and the value it refuses; all run at construction, before any work. ``n_elements`` is
#: the model's own (:class:`rodmol.Model` checks it).
OPTIONS = {
    "period": lambda name, value: _checks.positive(name, value, " s"),
    "episode_steps": lambda name, value: _checks.integer_at_least(name, value, 1),
    "max_tension": _max_tension,
    "effort_weight": lambda name, value: _checks.non_negative(name, value, " m/N^2"),
    "record": _record,
    "overwrite": _checks.flag,
}


def episode_end(steps, episode_steps, terminated):
    """(truncated, why a further ``step`` must wait for ``reset`` or None) after step ``steps``
    of an episode of ``episode_steps``: every environment's one rule."""
    truncated = steps >= episode_steps and not terminated
    if not (terminated or truncated):
        return truncated, None
    return truncated, f"after the episode was {'terminated' if terminated else 'truncated'} at step {steps}"


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

    Actions: a tension outside [0, ``max_tension``] is clipped to it, a NaN
    is 0 N and an infinite one the bound it points to (``info["non_finite"]``
    counts them): a policy that diverges does not end a training run. An
    action of another shape or not numbers raises ParameterError.

    ``step`` before the first ``reset`` or after the episode ended
    (terminated or truncated) raises :class:`ResetNeeded` (gymnasium's
    ``ResetNeeded`` too); ``reset`` takes no ``options`` (None or ``{}``).

    Targets: points at ``TARGET_REACH`` (0.8-0.97) L from the base within
    ``TARGET_CONE`` (45 degrees) of the base axis, uniform in solid angle
    (the tip at rest, 22 degrees below the axis in water, lies inside; that
    every target is reachable exactly is not checked: the reward is the
    distance). They come from the environment's seeded generator
    (``reset(seed=...)``), and a reset restores the start state bitwise, so
    episodes are reproducible.

    Model-based control: :attr:`state` (the whole state vector), :attr:`t`
    and :attr:`held` (the tensions held now) are the operating point, and
    ``rodmol.linearize(env.held_model(), env.state, env.t)`` the linear model
    about it (read them on ``env.unwrapped``).

    Parameters
    ----------
    n_elements : int
        Elements N of the arm (30: faster than real time on one core).
    period : float
        Control period [s], > 0.
    episode_steps : int
        Periods per episode, >= 1.
    max_tension : float
        Upper bound of each tension [N], > 0 and finite.
    effort_weight : float
        Weight of the effort in the reward [m/N^2], >= 0.
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
        given = dict(period=period, episode_steps=episode_steps, max_tension=max_tension,
                     effort_weight=effort_weight, record=record, overwrite=overwrite)
        options = {name: check(name, given[name]) for name, check in OPTIONS.items()}
        self.period, self.episode_steps = options["period"], options["episode_steps"]
        self.max_tension, self.effort_weight = options["max_tension"], options["effort_weight"]
        self.record = options["record"]
        self._recording = Recording(self.record, options["overwrite"])  # before any work
        self.model = paper_arm(n_elements, medium="water")
        self.sim = Simulator(self.model)
        self._start, self._y0 = self.sim.copy(), self.sim.y
        self.action_space = spaces.Box(0.0, self.max_tension, (len(CABLE_OFFSETS),), np.float32)
        self.observation_space = spaces.Box(-np.inf, np.inf, (21,), np.float32)
        self.target, self._steps = self.sim.state.tip.copy(), 0
        self._ended = "before the first reset()"  # why step must wait for a reset, or None

    # ----------------------------------------------------------------- for model-based control

    @property
    def state(self):
        """The arm's whole state vector now (``rodmol.StateLayout``), a copy: the observation
        is a part of it."""
        return self.sim.y

    @property
    def t(self):
        """The simulated time now [s] (0 at a reset)."""
        return self.sim.t

    @property
    def held(self):
        """The tensions [N] of cables 1-12 held now (those of the last action, as clipped;
        0 N after a reset), float64."""
        tensions = self.sim.held["tensions"]
        return np.array([tensions[f"cable {k}"] for k in sorted(CABLE_OFFSETS)])

    def held_model(self):
        """The arm with the tensions held now as constants: ``rodmol.linearize(env.held_model(),
        env.state, env.t)`` is the linear model about the present state and inputs."""
        return self.sim.held_model()

    # ----------------------------------------------------------------- gymnasium's API

    def reset(self, *, seed=None, options=None):
        if not (options is None or (isinstance(options, dict) and not options)):  # none is read: not ignored
            raise ParameterError(f"`options` {_checks.short(options)}: {type(self).__name__}.reset "
                                 "takes none (None or {})")
        super().reset(seed=seed)
        self.target = self._draw_target()
        self.sim = self._recording.next_episode(self.sim, self._start, self.model, self._y0)
        self._steps, self._ended = 0, None
        return self._observation(self.sim.state), {"target": self.target.copy()}

    def step(self, action):
        if self._ended is not None:
            raise ResetNeeded(f"step() {self._ended}: call reset() to start an episode")
        tensions, non_finite = self._tensions(action)
        self._steps += 1
        info, terminated = {"non_finite": non_finite}, False
        try:
            self.sim.step(self.period, tensions)
        except IntegrationError as exc:
            terminated, info["failure"] = True, str(exc)
        state = self.sim.state  # one view: its positions are rebuilt once
        distance = float(np.linalg.norm(state.tip - self.target))
        reward = -distance - self.effort_weight * float(tensions @ tensions)
        info["distance"] = distance
        truncated, self._ended = episode_end(self._steps, self.episode_steps, terminated)
        return self._observation(state), reward, terminated, truncated, info

    def close(self):
        self.sim.close()

    # ----------------------------------------------------------------- internals

    def _tensions(self, action):
        return action_tensions(action, self.action_space.shape[0], self.max_tension, "cables 1-12")

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


def action_tensions(action, n, max_tension, what):
    """The ``n`` tensions [N] ``action`` asks for (of ``what``, for the message), within
    [0, ``max_tension``] (a NaN: 0 N, an infinite one: the bound it points to), and how many
    of its entries were not finite: the rule of every environment's actions."""
    tensions = _checks.floats(action)
    if tensions is None or tensions.shape != (n,):
        raise ParameterError(f"`action` must be {n} numbers, the tensions [N] of {what}, "
                             f"got {_checks.short(action)}")
    non_finite = int(np.count_nonzero(~np.isfinite(tensions)))
    tensions = np.nan_to_num(tensions, nan=0.0, posinf=max_tension, neginf=0.0)
    return np.clip(tensions, 0.0, max_tension), non_finite


def vector_env(num_envs, env=ReachEnv, **kwargs):
    """``num_envs`` environments ``env`` (default :class:`ReachEnv`; keyword arguments
    ``kwargs``), each in its own process (``gymnasium.vector.AsyncVectorEnv``)."""
    return gymnasium.vector.AsyncVectorEnv([functools.partial(env, **kwargs)] * int(num_envs))


class Recording:
    """Where an environment records its episodes, if anywhere: each episode streamed into
    ``record/episode_NNNN`` (``NNNN`` from 0001) by a Simulator of its own (``out``: the run's
    HDF5 file and ParaView's series), the rule of every environment's ``record=``.

    Made at the environment's construction, before any work: the episodes recorded in
    ``record`` earlier are refused unless ``overwrite``, which removes them all (a shorter
    recording would leave the later ones beside it): :func:`rodmol.output.run_files.claim`.
    """

    def __init__(self, record, overwrite):
        self.record, self.overwrite, self.episodes = record, overwrite, 0
        if record is None:
            return
        from ..output import run_files

        earlier = sorted(record.glob("episode_[0-9][0-9][0-9][0-9]*")) if record.is_dir() else []
        for folder in earlier:
            run_files.refuse_replacing(folder, overwrite)
        for folder in earlier:
            run_files.claim(folder, True)
            with contextlib.suppress(OSError):  # holds files not rodmol's
                folder.rmdir()

    def next_episode(self, sim, start, model, initial, **options):
        """The simulator of the next episode: ``sim`` reset to its copy ``start`` or, recording,
        ``sim`` closed and a new Simulator of ``model`` (sim's) from the state ``initial`` (at
        t = 0, as ``start``) with the Simulator's ``options`` (sim's, e.g. ``rtol``)
        streaming into the next episode's folder."""
        if self.record is None:
            sim.reset(start)
            return sim
        sim.close()
        self.episodes += 1
        return Simulator(model, initial=initial, out=self.record / f"episode_{self.episodes:04d}",
                         overwrite=self.overwrite, **options)
