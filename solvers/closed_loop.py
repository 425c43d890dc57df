"""A controller outside the right-hand side: the stepping simulator against the table replay.

A 100 Hz zero-order-hold proportional controller lifts the paper's arm's tip
(N = 30, in water, 6 s) with cable 11 (Table II: +y at L3), measuring the tip
once per period. Timed in one run, each the median of --reps:

* ``Simulator``: ``rodmol.Simulator`` stepped 600 times (the loop's wall
  time: controller, state views and steps);
* ``table replay``: the same tension history as knots (each jump a 1 ns ramp)
  through ``rodmol.simulate`` (its integration wall time, ``stats``);
* ``per-period simulate``: one ``simulate(..., initial=previous, t0=t)`` call per
  period with a new model for each tension, the workaround the Simulator
  replaces (its whole wall time, kernels ready);

the three interleaved in each repetition, their ratios to the replay taken
within a repetition (median and range over them); and the Simulator's tip against the replay's (the same equations to rtol).
Then held inputs: the arm from rest pulled by cables 11 and 5 at constant
tensions, stepped at 50 Hz by the Simulator against one ``simulate`` with
those tensions (its ``stats`` wall time), interleaved, the ratio within a
repetition, with CVODE's steps and right-hand sides of each: held inputs
must not cut CVODE's steps at every period.
The learning environment's steps (``rodmol/Reach-v0``, N = 30, 20 ms
periods, random actions) against real time close the table when gymnasium
is installed.

    python solvers/closed_loop.py [--quick | --smoke] [--out DIR] [--reps R]
"""

import time

import _common as C
from _common import np, rodmol

SCRIPT = "closed_loop.py"
PERIOD = 0.01  # s, 100 Hz
TARGET_Y = -0.06  # m, the tip height the controller seeks
GAIN, BIAS, T_MAX = 20.0, 0.5, 4.0  # N/m, N, N


def tension(tip):
    """The proportional law on cable 11 [N], clipped to [0, T_MAX]."""
    return float(np.clip(BIAS + GAIN * (TARGET_Y - tip[1]), 0.0, T_MAX))


def stepped(n, steps):
    """(Simulator after the loop, loop wall time [s])."""
    sim = rodmol.Simulator(rodmol.paper_arm(n))
    start = time.perf_counter()
    for _ in range(steps):
        sim.step(PERIOD, {"cable 11": tension(sim.state.tip)})
    return sim, time.perf_counter() - start


def replayed(n, t, history):
    knots = [(t[0], history[0])]
    for k in range(1, len(t)):
        knots += [(t[k - 1] + 1e-9, history[k]), (t[k], history[k])]
    return rodmol.simulate(rodmol.paper_arm(n, tensions={11: knots}), t[-1], output_times=t)


def per_period(n, steps):
    """The workaround: one simulate call per period; returns (tips, wall time [s])."""
    rest = rodmol.Simulator(rodmol.paper_arm(n))  # the same start: the rest state without tension
    result, tips = rest.y, [rest.state.tip]
    start = time.perf_counter()
    for k in range(steps):
        model = rodmol.paper_arm(n, tensions={11: tension(tips[-1])})
        result = rodmol.simulate(model, (k + 1) * PERIOD, initial=result, t0=k * PERIOD, output_dt=PERIOD)
        tips.append(result.tip[-1])
    return np.array(tips), time.perf_counter() - start


HELD_PERIOD = 0.02  # s, 50 Hz
HELD_TENSIONS = {11: 1.0, 5: 0.5}  # N, constant from t = 0


def held(n, t_end, rest):
    """Held tensions: (Simulator's loop wall time [s], its stats, simulate's Result) from the
    state ``rest``."""
    sim = rodmol.Simulator(rodmol.paper_arm(n), initial=rest)
    commands = {f"cable {k}": value for k, value in HELD_TENSIONS.items()}
    start = time.perf_counter()
    for _ in range(int(round(t_end / HELD_PERIOD))):
        sim.step(HELD_PERIOD, commands)
    wall = time.perf_counter() - start
    one = rodmol.simulate(rodmol.paper_arm(n, tensions=HELD_TENSIONS), t_end, initial=rest,
                          output_dt=HELD_PERIOD)
    gap = float(np.max(np.linalg.norm(sim.result.tip - one.tip, axis=1)))
    return wall, dict(sim.stats, tip_gap_m=gap), one


def held_rows(args, n):
    """The held-inputs table: the Simulator at 50 Hz against one simulate, ratios within a repetition."""
    t_end = C.pick(args, 6.0, 2.0, 0.4)
    rest = rodmol.Simulator(rodmol.paper_arm(n)).y  # at rest without tension
    held(n, 2 * HELD_PERIOD, rest)  # warm
    ratios, walls, ones = [], [], []
    for _ in range(max(args.reps, 5)):
        wall, stats, one = held(n, t_end, rest)
        walls.append(wall)
        ones.append(one.stats["wall_time_s"])
        ratios.append(wall / one.stats["wall_time_s"])
    ratios = np.array(ratios)
    common = dict(N=n, t_end_s=t_end, periods=int(round(t_end / HELD_PERIOD)))
    return [dict(method="Simulator, held tensions (50 Hz)", **common, wall_s=float(np.median(walls)),
                 ratio_to_simulate=float(np.median(ratios)), ratio_range=f"{ratios.min():.2f}-{ratios.max():.2f}",
                 steps=stats["steps"], rhs_evals=stats["rhs_evals"], restarts=stats["restarts"],
                 tip_gap_m=stats["tip_gap_m"]),
            dict(method="simulate, the same tensions", **common, wall_s=float(np.median(ones)),
                 ratio_to_simulate=1.0, steps=one.stats["steps"], rhs_evals=one.stats["rhs_evals"])]


def env_speed(n, steps):
    """Wall time [s] per simulated second of rodmol/Reach-v0 under random actions, or None."""
    try:
        import gymnasium  # import rodmol registered rodmol/Reach-v0
    except ImportError:
        return None
    env = gymnasium.make("rodmol/Reach-v0", n_elements=n)
    env.reset(seed=0)
    env.action_space.seed(0)
    start, simulated = time.perf_counter(), 0.0
    for _ in range(steps):
        _, _, terminated, truncated, _ = env.step(env.action_space.sample())
        simulated += env.unwrapped.period
        if terminated or truncated:
            env.reset()
    wall = time.perf_counter() - start
    env.close()
    return wall / simulated


def main(argv=None):
    args = C.parse_args(__doc__.splitlines()[0], argv)
    header = C.header_lines(args, SCRIPT)
    n = C.pick(args, 30, 30, 8)
    t_end = C.pick(args, 6.0, 2.0, 0.2)
    steps = int(round(t_end / PERIOD))
    stepped(n, 2)  # kernels compiled or loaded, outside the timings
    times = {"Simulator": [], "table replay": [], "per-period simulate": []}
    for _ in range(args.reps):  # interleaved: the machine's load changes between repetitions
        sim, wall = stepped(n, steps)
        times["Simulator"].append(wall)
        result = sim.result
        replay = replayed(n, result.t, result.tensions[:, 10])
        times["table replay"].append(replay.stats["wall_time_s"])
        old_tips, old_wall = per_period(n, steps)
        times["per-period simulate"].append(old_wall)
    replays = np.array(times["table replay"])
    rows = []
    for name, walls in times.items():
        ratios = np.array(walls) / replays  # within each repetition
        rows.append(dict(method=name, N=n, t_end_s=t_end, periods=steps, wall_s=float(np.median(walls)),
                         s_per_simulated_s=float(np.median(walls)) / t_end,
                         ratio_to_replay=float(np.median(ratios)),
                         ratio_range=f"{ratios.min():.2f}-{ratios.max():.2f}"))
    gap = float(np.max(np.linalg.norm(replay.tip - result.tip, axis=1)))
    gap_old = float(np.max(np.linalg.norm(old_tips - result.tip, axis=1)))
    stats = sim.stats
    env = env_speed(n, C.pick(args, 300, 100, 10))
    if env is not None:
        rows.append(dict(method="rodmol/Reach-v0 (20 ms steps, random actions)", N=n,
                         s_per_simulated_s=env))
    for row in rows:
        print(row, flush=True)
    facts = (f"Tip of the Simulator against the table replay: largest distance {gap:.2g} m; "
             f"against the per-period calls {gap_old:.2g} m. The Simulator's integrator: "
             f"{stats['steps']} steps, {stats['restarts']} restarts (one per tension change), "
             f"{stats['rhs_evals']} right-hand sides; the replay: {replay.stats['steps']} steps, "
             f"{replay.stats['rhs_evals']} right-hand sides. Tension range "
             f"{result.tensions[:, 10].min():.3g}-{result.tensions[:, 10].max():.3g} N.")
    held_table = held_rows(args, n)
    for row in held_table:
        print(row, flush=True)
    fmt = {"wall_s": ".3g", "s_per_simulated_s": ".3g", "ratio_to_replay": ".2f", "ratio_to_simulate": ".2f",
           "tip_gap_m": ".2g"}
    C.write_results(args, "closed_loop", "A 100 Hz controller outside the right-hand side", header,
                    rows + held_table, [
                        ("Results", C.markdown_table(rows, None, fmt)),
                        ("Agreement and work", facts + "\n"),
                        ("Held tensions: the Simulator at 50 Hz against one simulate",
                         C.markdown_table(held_table, None, fmt))])


if __name__ == "__main__":
    main()
