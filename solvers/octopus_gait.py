"""An octopus gait by trajectory optimisation against the example's hand-made crawl.

The octopus of ``examples/octopus.py`` (:func:`rodmol.control.octopus.octopus`, N elements
per arm, 6 as ``rodmol/OctopusCrawl-v0`` uses) settles on the floor for the example's
SETTLE seconds from straight; from that state both gaits run for the same time:

* hand-made: the example's crawl (the three front arms curl down with cable 2, then up
  with cable 4, a smooth 2 N pulse each, every 0.5 s);
* optimised: ``rodmol.optimal_tensions`` over the knot values of cables 2 and 4 of every
  arm (``"arm1.cable 2"`` ...; a few knots each over the run, linear between them, within
  the same 0 .. 2 N), minimising ``BodyAdvance("head", +x)`` (minus the head's forward
  position at the end) plus a small ``Effort``, by L-BFGS-B with adjoint gradients, from
  a uniform START tension.

Reported: the head's displacement over the run, the tensions' effort integral and the
CPU time of each; the knots found; a picture (``octopus_gait.png``: the head's forward
position against time for both, and the optimised octopus seen from the side).

    python solvers/octopus_gait.py [--quick | --smoke] [--out DIR]
"""

import importlib.util
import os
import time

import _common as C
from _common import np, plt, rodmol

from rodmol.control.octopus import ARMS, FLOOR, octopus

# The example's hand-made crawl, by its path: solvers/octopus.py is its namesake.
_spec = importlib.util.spec_from_file_location("octopus_example", os.path.join(C.ROOT, "examples", "octopus.py"))
example = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(example)

SCRIPT = "octopus_gait.py"
CABLES = (2, 4)  # each arm's: down (curls onto the floor) and up, as the example's and OctopusCrawl-v0's
START = 0.5  # N, every knot at the start of the optimisation
EFFORT_WEIGHT = 1e-6  # m per N^2 s: a tie-breaker beside the head's advance (millimetres)
ARM_NAMES = [f"arm{i + 1}" for i in range(ARMS)]


def effort(result, t0):
    """The integral of every cable's squared tension [N^2 s] over a run's frames (trapezoid)."""
    total = 0.0
    for name in ARM_NAMES:
        part = result[name]
        keep = part.t >= t0
        total += float(np.trapezoid(np.sum(part.tensions[keep] ** 2, axis=1), part.t[keep]))
    return total


def main(argv=None):
    args = C.parse_args(__doc__.splitlines()[0], argv)
    header = C.header_lines(args, SCRIPT)
    n, span = C.pick(args, 6, 6, 4), C.pick(args, 1.5, 1.0, 0.2)
    count, iterations = C.pick(args, 5, 4, 2), C.pick(args, 15, 15, 1)
    settle_time = example.SETTLE  # the crawl starts then
    t0, t_end = settle_time, settle_time + span
    settled = rodmol.simulate(octopus(n), settle_time, initial="straight")
    y0 = settled.states[-1]
    frames = dict(output_times=np.linspace(t0, t_end, int(round(span / 0.02)) + 1))

    rows = []
    cpu = time.process_time()
    hand = rodmol.simulate(example.octopus(n), t_end, t0=t0, initial=y0, **frames)
    rows.append(dict(gait="hand-made (examples/octopus.py)", cpu_s=time.process_time() - cpu))

    knots = np.linspace(t0, t_end, count)
    flat = list(zip(knots, [START] * count))
    model = octopus(n, lambda angle: {c: flat for c in CABLES})
    cables = [f"{arm}.cable {c}" for arm in ARM_NAMES for c in CABLES]
    loss = rodmol.BodyAdvance("head", [1.0, 0.0, 0.0]) + rodmol.Effort(EFFORT_WEIGHT)
    cpu = time.process_time()
    plan = rodmol.optimal_tensions(model, t_end, loss, cables, knots, bounds=(0.0, example.PULL), start=START,
                                   max_iterations=iterations, t0=t0, initial=y0)
    rows.append(dict(gait=f"optimised ({count} knots x {len(cables)} cables)", cpu_s=time.process_time() - cpu,
                     evaluations=plan.evaluations, iterations=len(plan.history) - 1))
    best = rodmol.simulate(plan.model, t_end, t0=t0, initial=y0, **frames)
    for row, run in zip(rows, (hand, best)):
        x = run["head"].position
        row.update(dx_mm=1e3 * (x[-1, 0] - x[0, 0]), dy_mm=1e3 * (x[-1, 1] - x[0, 1]),
                   dz_mm=1e3 * (x[-1, 2] - x[0, 2]), effort_N2s=effort(run, t0), success=run.success)
        print(row, flush=True)
    table = [dict(cable=cable, **{f"t{k}": float(v) for k, v in enumerate(plan.tensions[cable].values[:, 0])})
             for cable in cables]

    fig, (left, right) = plt.subplots(1, 2, figsize=(10, 4))
    for run, label, style in ((hand, "hand-made crawl", "k-"), (best, "optimised gait", "C1-")):
        left.plot(run.t - t0, 1e3 * (run["head"].position[:, 0] - run["head"].position[0, 0]), style, label=label)
    left.set_xlabel("t [s] (after settling)")
    left.set_ylabel("head's forward displacement x [mm]")
    left.legend()
    for j, at in enumerate(np.linspace(0, len(best.t) - 1, 4).astype(int)):
        colour = plt.cm.viridis(j / 3)
        for name in ARM_NAMES:
            p = best[name].positions[at]
            right.plot(p[:, 0], p[:, 2], "-", color=colour, lw=1)
        head = best["head"].position[at]
        right.plot(head[0], head[2], "o", color=colour, label=f"t = {best.t[at] - t0:.2f} s")
    right.axhline(FLOOR, color="0.5", lw=0.8)
    right.set_aspect("equal")
    right.set_xlabel("x [m]")
    right.set_ylabel("z [m]")
    right.set_title("optimised gait, side view")
    right.legend(fontsize=8)
    C.save_figure(fig, os.path.join(args.out, "octopus_gait.png"))
    sections = [
        (f"the head's displacement over {span:g} s after {settle_time:g} s of settling (octopus of N = {n} per arm)",
         C.markdown_table(rows, formats=dict(cpu_s=".1f", dx_mm=".2f", dy_mm=".2f", dz_mm=".2f", effort_N2s=".2f"))),
        ("the knots found [N]", C.markdown_table(table, formats={f"t{k}": ".3f" for k in range(count)})),
    ]
    C.write_results(args, "octopus_gait", "An octopus gait: optimised against the hand-made crawl", header,
                    [dict(table="gaits", **row) for row in rows] + [dict(table="knots", **row) for row in table],
                    sections)


if __name__ == "__main__":
    main()
