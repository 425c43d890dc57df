"""Two policies on the reaching environment rodmol/Reach-v0, and a recorded episode.

A random policy and a proportional one (each tension pulls on the side of the
arm the target lies on, in proportion to the tip's distance from it) run one
short episode each from the same seed (the same target); the proportional
episode is streamed for ParaView into ``OUT/episode_0001`` (open ``rod.xdmf``
with an absolute path, see docs/paraview.md). Needs gymnasium
(``pip install rodmol[rl]``).

    python examples/reach_policies.py [--out DIR] [--steps 100] [--n 20]
"""

import argparse
import os

import numpy as np

from rodmol.arm import CABLE_OFFSETS
from rodmol.control.envs import ReachEnv  # needs gymnasium

GAIN = 8.0  # N per m of tip error


def proportional(env, observation):
    """Tensions [N] from the tip error e = target - tip (the last three observations),
    global frame. At rest the arm lies in the x-y plane and its sections are not twisted,
    so a cable at local offset (p_y, p_z) bends the arm toward global (0, p_y, p_z):
    each cable pulls with the part of the error along its own side. Cables anchored
    nearer the tip (Table II: 9-12 at L3) bend its end most; they get the full gain,
    those at L2 half, those at L1 a quarter."""
    error = observation[-3:].astype(float)
    tensions = np.empty(12)
    for number, (p_y, p_z) in CABLE_OFFSETS.items():
        side = np.array([p_y, p_z]) / np.hypot(p_y, p_z)
        share = 2.0 ** -((12 - number) // 4)  # 1 at L3, 1/2 at L2, 1/4 at L1
        tensions[number - 1] = share * GAIN * max(0.0, side @ error[1:])
    return np.clip(tensions, 0.0, env.max_tension).astype(np.float32)


def episode(env, policy, seed):
    """(return, tip distance at the start and at the end [m]) of one episode."""
    observation, _ = env.reset(seed=seed)
    start = float(np.linalg.norm(observation[-3:]))
    total, done, info = 0.0, False, {}
    while not done:
        observation, reward, terminated, truncated, info = env.step(policy(env, observation))
        total += reward
        done = terminated or truncated
    if "failure" in info:
        print("episode failed:", info["failure"])
    return total, start, info["distance"]


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default="out/reach_policies", help="directory of the recorded episode")
    parser.add_argument("--steps", type=int, default=100, help="control periods (20 ms) per episode")
    parser.add_argument("--n", type=int, default=20, help="elements of the arm")
    parser.add_argument("--seed", type=int, default=3)
    parser.add_argument("--overwrite", action="store_true", help="replace an episode recorded in --out earlier")
    args = parser.parse_args(argv)

    env = ReachEnv(n_elements=args.n, episode_steps=args.steps)
    env.action_space.seed(args.seed)
    random_run = episode(env, lambda env, _: env.action_space.sample(), args.seed)
    env.close()
    recorded = ReachEnv(n_elements=args.n, episode_steps=args.steps, record=args.out,
                        overwrite=args.overwrite)
    p_run = episode(recorded, proportional, args.seed)
    recorded.close()
    for name, (total, start, end) in (("random", random_run), ("proportional", p_run)):
        print(f"{name} policy: return {total:.3f}, tip distance from the target {start * 1e3:.1f} mm "
              f"at the start, {end * 1e3:.1f} mm at the end")
    print("recorded episode:", os.path.abspath(os.path.join(args.out, "episode_0001", "rod.xdmf")))


if __name__ == "__main__":
    main()
