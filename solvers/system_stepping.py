"""A System stepped by a controller: ``rodmol.Simulator(system)`` against one ``simulate``.

The octopus of ``examples/octopus.py`` (``rodmol.control.octopus``, eight arms of N
elements on a free head, on the floor) from rest, its three front arms pulled by
cables 2 and 4 in the example's crawl pulses (0.5 s cycles), sampled at 50 Hz and
held over each period (a zero-order hold). Timed in one run, interleaved, each
the median of --reps (at least 3):

* ``Simulator``: ``rodmol.Simulator(system)`` stepped at 50 Hz (the loop's wall
  time: the commands by rod and cable, the per-part state views and the steps);
* ``table replay``: the same tensions as knots (each jump a 1 ns ramp) through one
  ``rodmol.simulate`` of the same System (its integration wall time, ``stats``);

the ratio taken within a repetition, with CVODE's steps and right-hand sides of
each and the largest gap of the head's position between the two (the same
equations to rtol).

    python solvers/system_stepping.py [--quick | --smoke] [--out DIR] [--reps R]
"""

import time

import _common as C
from _common import np, rodmol

from rodmol.control.octopus import ARMS, arm_angle, octopus

SCRIPT = "system_stepping.py"
PERIOD = 0.02  # s, 50 Hz
CYCLE, PULL = 0.5, 2.0  # s, N: the example's crawl
FRONT = [f"arm{i + 1}" for i in range(ARMS) if np.cos(arm_angle(i)) > 0.5]


def pulse(t, start, width):
    phase = (t / CYCLE - start) % 1.0
    return PULL * np.sin(np.pi * phase / width) ** 2 if phase < width else 0.0


def commands(t):
    """The tensions {rod: {cable: N}} held from ``t`` [s] over the next period."""
    return {arm: {"cable 2": pulse(t, 0.0, 0.5), "cable 4": pulse(t, 0.5, 0.4)} for arm in FRONT}


def stepped(n, periods):
    """(the Simulator after the loop, the loop's wall time [s])."""
    sim = rodmol.Simulator(octopus(n))
    start = time.perf_counter()
    for _ in range(periods):
        sim.step(PERIOD, commands(sim.t))
        sim.state["head"].position  # noqa: B018 (what a controller reads)
    return sim, time.perf_counter() - start


def replayed(n, t):
    """One simulate of the same System with the held tensions as knots."""
    held = [commands(tk) for tk in t[:-1]]

    def knots(arm, cable):
        values = [held[0][arm][cable]] + [h[arm][cable] for h in held]
        out = [(t[0], values[0])]
        for k in range(1, len(t)):
            out += [(t[k - 1] + 1e-9, values[k]), (t[k], values[k])]
        return out

    tables = {arm: {2: knots(arm, "cable 2"), 4: knots(arm, "cable 4")} for arm in FRONT}
    system = octopus(n, lambda angle: tables.get(f"arm{1 + round(angle / (2 * np.pi) * ARMS) % ARMS}", {}))
    return rodmol.simulate(system, t[-1], output_times=t)


def main(argv=None):
    args = C.parse_args(__doc__.splitlines()[0], argv)
    header = C.header_lines(args, SCRIPT)
    n = C.pick(args, 10, 10, 4)
    t_end = C.pick(args, 2.0, 1.0, 0.1)
    periods = int(round(t_end / PERIOD))
    stepped(n, 2)  # the kernels compiled
    ratios, walls, ones = [], [], []
    for _ in range(max(args.reps, 3)):
        sim, wall = stepped(n, periods)
        result = sim.result
        one = replayed(n, result.t)
        walls.append(wall)
        ones.append(one.stats["wall_time_s"])
        ratios.append(wall / one.stats["wall_time_s"])
    ratios = np.array(ratios)
    gap = float(np.max(np.abs(result["head"].position - one["head"].position)))
    common = dict(N=n, arms=ARMS, t_end_s=t_end, periods=periods)
    rows = [dict(method="Simulator(System), 50 Hz", **common, wall_s=float(np.median(walls)),
                 real_time_factor=float(np.median(walls)) / t_end, ratio_to_simulate=float(np.median(ratios)),
                 ratio_range=f"{ratios.min():.2f}-{ratios.max():.2f}", steps=sim.stats["steps"],
                 rhs_evals=sim.stats["rhs_evals"], restarts=sim.stats["restarts"], head_gap_m=gap),
            dict(method="simulate, the same tensions as a table", **common, wall_s=float(np.median(ones)),
                 real_time_factor=float(np.median(ones)) / t_end, ratio_to_simulate=1.0,
                 steps=one.stats["steps"], rhs_evals=one.stats["rhs_evals"])]
    fmt = dict(wall_s=".3g", real_time_factor=".3g", ratio_to_simulate=".3g", head_gap_m=".2g")
    C.write_results(args, "system_stepping", "A System stepped at 50 Hz against one simulate", header, rows,
                    [("Results", C.markdown_table(rows, None, fmt))])
    for row in rows:
        print(row)


if __name__ == "__main__":
    main()
