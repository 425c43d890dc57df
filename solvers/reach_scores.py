"""Reference scores on the learning environment rodmol/Reach-v0: four policies, seeded episodes.

The environment at its defaults (N = 30, 20 ms periods, 100 periods = 2 s,
tensions 0-4 N, effort weight 1e-3 m/N^2); each policy runs the same
episodes (seeds 0, 1, ...: the same targets):

* ``random``: the action space's samples (seeded);
* ``proportional``: ``examples/reach_policies.py``'s law (each cable pulls
  with the part of the tip error on its side);
* ``inverse statics, open loop``: ``rodmol.inverse_statics`` of the target
  (all 12 cables within the action box) at the reset, those tensions held
  the whole episode;
* ``linear MPC``: every ``RELINEARIZE`` periods ``rodmol.linearize`` about
  the present state and held tensions (``env.unwrapped.state``, ``held``,
  ``held_model()``; the drift f0 included: the arm is moving), sampled at
  the period; every period the tensions held over the next ``HORIZON``
  periods that bring the predicted tip nearest the target (least squares
  over the horizon, within the action box: ``scipy.optimize.lsq_linear``).

Per policy: the mean return, the tip's distance from the target at the end
(median and largest, and how many episodes end within 0.5 mm) and the wall
time per episode.

    python solvers/reach_scores.py [--quick | --smoke] [--out DIR]
"""

import os
import sys
import time
from dataclasses import replace

import _common as C
from _common import np, rodmol
from scipy.optimize import lsq_linear

sys.path.insert(0, os.path.join(os.path.dirname(C.HERE), "examples"))
from reach_policies import proportional  # noqa: E402  (one owner of that law)

from rodmol.control.envs import ReachEnv  # noqa: E402  (needs gymnasium)

SCRIPT = "reach_scores.py"
HORIZON = 25  # periods the MPC looks ahead (0.5 s)
RELINEARIZE = 5  # periods between linearisations
EFFORT = float(os.environ.get("EFFORT", 1e-4))  # m^2/N^2
HORIZON = int(os.environ.get("HORIZON", HORIZON))
ORDER = int(os.environ.get("ORDER", 16))
DISTURBANCE = int(os.environ.get("DIST", 1))
AT_STATE = int(os.environ.get("AT_STATE", 1))
TRUST = float(os.environ.get("TRUST", "inf"))
RELINEARIZE = int(os.environ.get("RELIN", RELINEARIZE))
WITHIN = 5e-4  # m: "reached"


def random_policy(env, seed):
    env.action_space.seed(seed)
    return lambda observation: env.action_space.sample()


def proportional_policy(env, seed):
    return lambda observation: proportional(env, observation)


def inverse_statics_policy(env, seed):
    fit = rodmol.inverse_statics(env.model, env.target, bounds=(0.0, env.max_tension))
    tensions = np.array([fit.tensions[f"cable {k}"] for k in range(1, 13)], dtype=np.float32)
    return lambda observation: tensions


class LinearMPC:
    """Receding-horizon control on linear models about the equilibria of the held tensions.

    Every ``RELINEARIZE`` periods: the equilibrium under the tensions held
    now (``env.unwrapped.held_model()``), the model linearised there (no
    drift), reduced to ``ORDER`` states seen from the tip and sampled at the
    period. Every period: the model's state from the arm's
    (``coordinates(env.unwrapped.state)``), the model's miss of the tip now
    carried over the horizon (offset-free feedback), and the tensions, held
    over the next ``HORIZON`` periods within the action box, that bring the
    predicted tip nearest the target, with ``EFFORT`` on their change
    (bounded least squares); the first is applied.
    """

    def __init__(self, env, seed):
        self.env, self.lin, self.age = env, None, 0

    def _model(self):
        env = self.env
        model = env.held_model()
        if AT_STATE == 2:  # the target's equilibrium
            fit = rodmol.inverse_statics(env.model, env.target, bounds=(0.0, env.max_tension))
            model = env.model.replace(cables=[replace(c, tension=fit.tensions[c.name]) for c in env.model.cables])
            point = fit.state
        else:
            point = env.state if AT_STATE else rodmol.equilibrium(model, env.t)
        full = rodmol.linearize(model, point, env.t)
        lin = (full.reduced(output="tip", order=ORDER) if ORDER else full.output("tip")).discretize(env.period)
        gains, power, gain = [], lin.C, np.zeros_like(lin.D)
        for _ in range(HORIZON):  # y_k = y0 + C A^k x + G_k u, G_k = C (I + ... + A^(k-1)) B + D
            gain = gain + power @ lin.B
            power = power @ lin.A
            gains.append(gain + lin.D)
        self.gains = np.vstack(gains + [np.sqrt(EFFORT) * np.eye(len(lin.u0))])
        self.box = (np.maximum(np.maximum(lin.bounds[:, 0], 0.0) - lin.u0, -TRUST),
                    np.minimum(np.minimum(lin.bounds[:, 1], env.max_tension) - lin.u0, TRUST))
        self.lin, self.age = lin, 0

    def __call__(self, observation):
        env = self.env
        if self.lin is None or self.age >= RELINEARIZE:
            self._model()
        self.age += 1
        lin = self.lin
        x, free = lin.coordinates(env.state), []
        miss = observation[:3] - (lin.y0 + lin.C @ x + lin.D @ (env.held - lin.u0)) if DISTURBANCE else 0.0
        for _ in range(HORIZON):
            x = lin.A @ x + lin.f0
            free.append(lin.y0 + lin.C @ x + miss)
        misses = np.concatenate([env.target - f for f in free] + [-np.sqrt(EFFORT) * lin.u0 * (AT_STATE != 2)])
        du = lsq_linear(self.gains, misses, bounds=self.box).x
        return np.clip(lin.u0 + du, 0.0, env.max_tension).astype(np.float32)


POLICIES = {"random": random_policy, "proportional": proportional_policy,
            "inverse statics, open loop": inverse_statics_policy, "linear MPC": LinearMPC}


def episode(env, make, seed):
    """(return, final distance [m], wall time [s]) of one episode."""
    start = time.perf_counter()
    observation, _ = env.reset(seed=seed)
    policy = make(env, seed)
    total, done, info = 0.0, False, {}
    while not done:
        observation, reward, terminated, truncated, info = env.step(policy(observation))
        total += reward
        done = terminated or truncated
    if "failure" in info:
        print("episode failed:", info["failure"], flush=True)
    return total, info["distance"], time.perf_counter() - start


def main(argv=None):
    args = C.parse_args(__doc__.splitlines()[0], argv)
    header = C.header_lines(args, SCRIPT)
    n = C.pick(args, 30, 30, 8)
    episodes = C.pick(args, 5, 2, 1)
    steps = C.pick(args, 100, 100, 10)
    env = ReachEnv(n_elements=n, episode_steps=steps)
    rows = []
    for name, make in POLICIES.items():
        runs = np.array([episode(env, make, seed) for seed in range(episodes)])
        returns, ends, walls = runs.T
        rows.append(dict(policy=name, N=n, episodes=episodes, periods=steps, mean_return=float(returns.mean()),
                         final_distance_median_mm=float(1e3 * np.median(ends)),
                         final_distance_max_mm=float(1e3 * ends.max()),
                         within_0_5_mm=f"{int(np.sum(ends <= WITHIN))}/{episodes}",
                         wall_s_per_episode=float(walls.mean())))
        print(rows[-1], flush=True)
    env.close()
    fmt = {"mean_return": ".3f", "final_distance_median_mm": ".3g", "final_distance_max_mm": ".3g",
           "wall_s_per_episode": ".3g"}
    C.write_results(args, "reach_scores", "Reference scores on rodmol/Reach-v0", header, rows, [
        ("Results", C.markdown_table(rows, None, fmt)),
        ("Reading", f"Episodes seeded 0-{episodes - 1} (the same targets for every policy); the return "
                    "sums -|tip - target| - 1e-3 |T|^2 over the periods; final distances at the last period.\n")])


if __name__ == "__main__":
    main()
