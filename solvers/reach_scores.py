"""Reference scores on the learning environment rodmol/Reach-v0: five policies, seeded episodes.

The environment at its defaults (N = 30, 20 ms periods, tensions 0-4 N,
effort weight 1e-3 m/N^2), its episodes run to 5 s (250 periods; the first
100, 2 s, are the default episode, whose return is scored); each policy
runs the same episodes (seeds 0, 1, ...: the same targets):

* ``random``: the action space's samples (seeded);
* ``proportional``: ``examples/reach_policies.py``'s law (each cable pulls
  with the part of the tip error on its side);
* ``inverse statics, open loop``: ``rodmol.inverse_statics`` of the target
  (all 12 cables within the action box) at the reset, those tensions held
  the whole episode;
* ``linear MPC``: :class:`LinearMPC`, receding-horizon control on
  ``rodmol.linearize`` -> ``reduced`` -> ``discretize`` about the target's
  equilibrium (from inverse statics), fed the arm's whole state
  (``env.unwrapped.state``, ``held``).

Per policy: the mean return over the default episode, the tip's distance
from the target at 2 s and at 5 s (median, largest, how many within
0.5 mm) and the wall time per episode.

    python solvers/reach_scores.py [--quick | --smoke] [--out DIR]
"""

import os
import sys
import time

import _common as C
from _common import np, rodmol
from scipy.optimize import lsq_linear

sys.path.append(os.path.join(os.path.dirname(C.HERE), "examples"))  # after solvers/: namesakes
from reach_policies import proportional  # noqa: E402  (one owner of that law)

from rodmol.control.envs import ReachEnv  # noqa: E402  (needs gymnasium)

SCRIPT = "reach_scores.py"
WITHIN = 5e-4  # m: "reached"
SCORED = 100  # periods the environment's default episode lasts (2 s): its return
# The MPC: its model's order, horizon [periods], the first period of each block of held
# tensions over it, how far [N] a tension may leave the equilibrium's, and the effort
# weight [m^2/N^2] on that change.
ORDER, HORIZON, BLOCKS, TRUST, EFFORT = 32, 50, (0, 5, 15), 1.0, 1e-5


def random_policy(env, seed):
    env.action_space.seed(seed)
    return lambda observation: env.action_space.sample()


def proportional_policy(env, seed):
    return lambda observation: proportional(env, observation)


def inverse_statics_policy(env, seed):
    fit = rodmol.inverse_statics(env.model, env.target, bounds=(0.0, env.max_tension))
    tensions = np.array([fit.tensions[c.name] for c in env.model.cables], dtype=np.float32)
    return lambda observation: tensions


class LinearMPC:
    """Receding-horizon control on the linear model about the target's equilibrium.

    At the reset: the tensions whose equilibrium puts the tip on the target
    (``rodmol.inverse_statics``), the model linearised about that equilibrium
    (no drift), reduced to ``ORDER`` states seen from the tip and sampled at
    the period. Every period: the model's state from the arm's
    (``coordinates(env.unwrapped.state)``), the model's miss of the tip now
    carried over the horizon (offset-free feedback: far from the equilibrium
    the linear tip is off), and the tensions of each block of the
    ``HORIZON`` that bring the predicted tip nearest the target, within the
    action box and ``TRUST`` of the model's operating tensions, ``EFFORT`` on
    their departure from the target's (``scipy.optimize.lsq_linear``); the
    first block's are applied.
    """

    def __init__(self, env, seed):
        self.env = env
        fit = rodmol.inverse_statics(env.model, env.target, bounds=(0.0, env.max_tension))
        self.reference = np.array([fit.tensions[c.name] for c in env.model.cables])
        model = fit.apply(env.model)
        self.use(rodmol.linearize(model, fit.state).reduced(output="tip", order=ORDER).discretize(env.period))

    def use(self, lin):
        """Plan on the sampled linear model ``lin`` of the tip from now on."""
        # y_k = y0 + C A^k x + sum_(j<k) C A^(k-1-j) B u_j with u_j its block's: by the prefix sums
        # S_m of the impulse responses C A^i B, block [s, e) adds S_(k-s) - S_(k-min(e, k)) to y_k.
        sums, power = [np.zeros_like(lin.D)], lin.C
        for _ in range(HORIZON):
            sums.append(sums[-1] + power @ lin.B)
            power = power @ lin.A
        edges = (*BLOCKS, HORIZON)
        # (a reduced model's D, its dropped fast modes settled: the input of the period before k)
        rows = [np.hstack([(sums[k - s] - sums[k - min(e, k)] if s < k else 0.0 * lin.D)
                           + (lin.D if s <= k - 1 < e else 0.0) for s, e in zip(edges[:-1], edges[1:])])
                for k in range(1, HORIZON + 1)]
        m, env = len(lin.u0), self.env
        self.gains = np.vstack(rows + [np.sqrt(EFFORT) * np.eye(len(BLOCKS) * m)])
        self.effort = np.sqrt(EFFORT) * np.tile(self.reference - lin.u0, len(BLOCKS))
        low = np.maximum(np.maximum(lin.bounds[:, 0], 0.0) - lin.u0, -TRUST)
        high = np.minimum(np.minimum(lin.bounds[:, 1], env.max_tension) - lin.u0, TRUST)
        self.box, self.lin = (np.tile(low, len(BLOCKS)), np.tile(high, len(BLOCKS))), lin

    def __call__(self, observation):
        lin, env = self.lin, self.env
        x, free = lin.coordinates(env.state), []
        miss = observation[:3] - (lin.y0 + lin.C @ x + lin.D @ (env.held - lin.u0))
        for _ in range(HORIZON):
            x = lin.A @ x + lin.f0
            free.append(lin.y0 + lin.C @ x + miss)
        misses = np.concatenate([env.target - f for f in free] + [self.effort])
        du = lsq_linear(self.gains, misses, bounds=self.box).x[:len(lin.u0)]  # the first block's
        return np.clip(lin.u0 + du, 0.0, env.max_tension).astype(np.float32)


class SuccessiveMPC(LinearMPC):
    """:class:`LinearMPC` on a model taken anew every period about the arm's state now and
    the tensions held (``rodmol.linearize(env.held_model(), env.state, env.t)``, its drift
    f0 the rates there), whole (a reduced model's static correction treats the drift's
    dropped modes as settled), sampled at the period; the tensions within ``TRUST`` of
    those held, ``EFFORT`` on their departure from the target's equilibrium's."""

    def __call__(self, observation):
        env = self.env
        self.use(rodmol.linearize(env.held_model(), env.state, env.t).output("tip").discretize(env.period))
        return super().__call__(observation)


POLICIES = {"random": random_policy, "proportional": proportional_policy,
            "inverse statics, open loop": inverse_statics_policy, "linear MPC": LinearMPC,
            "successive linear MPC": SuccessiveMPC}


def episode(env, make, seed):
    """(return over the first ``SCORED`` periods, distance [m] after them and at the end, wall
    time [s]) of one episode."""
    start = time.perf_counter()
    observation, _ = env.reset(seed=seed)
    policy = make(env, seed)
    total, distances, done, info = 0.0, [], False, {}
    while not done:
        observation, reward, terminated, truncated, info = env.step(policy(observation))
        if len(distances) < SCORED:
            total += reward
        distances.append(info["distance"])
        done = terminated or truncated
    if "failure" in info:
        print("episode failed:", info["failure"], flush=True)
    return total, distances[min(SCORED, len(distances)) - 1], distances[-1], time.perf_counter() - start


def main(argv=None):
    args = C.parse_args(__doc__.splitlines()[0], argv)
    header = C.header_lines(args, SCRIPT)
    n = C.pick(args, 30, 30, 8)
    episodes = C.pick(args, 5, 2, 1)
    steps = C.pick(args, 250, 250, 10)
    env = ReachEnv(n_elements=n, episode_steps=steps)
    scored, end = min(SCORED, steps) * env.period, steps * env.period
    rows = []
    for name, make in POLICIES.items():
        runs = np.array([episode(env, make, seed) for seed in range(episodes)])
        returns, at_scored, at_end, walls = runs.T
        rows.append(dict(policy=name, N=n, episodes=episodes, mean_return=float(returns.mean()),
                         **{f"distance_{scored:g}s_median_mm": float(1e3 * np.median(at_scored)),
                            f"distance_{scored:g}s_max_mm": float(1e3 * at_scored.max()),
                            f"within_0.5mm_at_{scored:g}s": f"{int(np.sum(at_scored <= WITHIN))}/{episodes}",
                            f"distance_{end:g}s_median_mm": float(1e3 * np.median(at_end)),
                            f"distance_{end:g}s_max_mm": float(1e3 * at_end.max()),
                            f"within_0.5mm_at_{end:g}s": f"{int(np.sum(at_end <= WITHIN))}/{episodes}"},
                         wall_s_per_episode=float(walls.mean()), per_episode=" ".join(
                             f"{1e3 * d:.3g}/{1e3 * e:.3g}" for d, e in zip(at_scored, at_end))))
        print(rows[-1], flush=True)
    env.close()
    fmt = {"mean_return": ".2f", "wall_s_per_episode": ".3g"}
    fmt.update({key: ".3g" for key in rows[0] if key.endswith("_mm")})
    C.write_results(args, "reach_scores", "Reference scores on rodmol/Reach-v0", header, rows, [
        ("Results", C.markdown_table(rows, None, fmt)),
        ("Reading", f"Episodes seeded 0-{episodes - 1}: the same targets for every policy. mean_return: the "
                    f"environment's return over its default episode ({SCORED} periods, {scored:g} s), the sum "
                    "of -|tip - target| - 1e-3 |T|^2 [m]; the episodes go on to "
                    f"{end:g} s for the distances at the end. per_episode: each episode's distance [mm] "
                    f"at {scored:g} s / at {end:g} s.\n")])


if __name__ == "__main__":
    main()
