"""Trajectory optimisation: the bending test's tension history recovered from its own tip track.

The paper's bending test (cable 11 pulled to 2 N over 0.5 s, held until 4 s, released;
6 s, from the equilibrium) is run on the paper's arm of N elements and its tip recorded
every 0.1 s. ``rodmol.optimal_tensions`` then seeks cable 11's tension on 13 knots (every
0.5 s, on which the test's history is exact) from zero tension, within (0, 5) N, by
L-BFGS-B with adjoint gradients, over growing horizons (1.5, 3, 4.5 s, then the whole run;
over the whole run at once it stopped in a local minimum at the 5 N bound): the knots found, their RMS error against the test's,
the losses and gradients it took and its time; the tensions and the tip track in a
picture (``optimal_tensions.png``).

    python solvers/optimal_tensions.py [--quick | --smoke] [--out DIR]
"""

import os
import time

import _common as C
from _common import np, plt, rodmol

from rodmol import scenarios

SCRIPT = "optimal_tensions.py"
RTOL = 1e-6


def main(argv=None):
    args = C.parse_args(__doc__.splitlines()[0], argv)
    header = C.header_lines(args, SCRIPT)
    n, t_end, count = C.pick(args, 30, 20, 6), C.pick(args, 6.0, 6.0, 1.0), C.pick(args, 13, 13, 3)
    knots = np.linspace(0.0, t_end, count)
    true = np.interp(knots, *zip(*scenarios.bending().tensions[11]))
    test = rodmol.paper_arm(n, tensions={11: list(zip(knots, true))})
    times = np.linspace(0.1, t_end, int(round(t_end / 0.1)))
    recorded = rodmol.simulate(test, t_end, output_times=times, rtol=RTOL)
    rows = np.searchsorted(recorded.t, times)
    loss = rodmol.TipTracking(times, recorded.tip[rows])
    start, cpu = time.perf_counter(), time.process_time()
    horizons = np.arange(1.5, t_end - 1e-9, 1.5)
    plan = rodmol.optimal_tensions(test, t_end, loss, ["cable 11"], knots, bounds=(0.0, 5.0), rtol=RTOL,
                                   horizons=horizons)
    wall, cpu = time.perf_counter() - start, time.process_time() - cpu
    found = plan.tensions["cable 11"].values[:, 0]
    rms = float(np.sqrt(np.mean((found - true) ** 2)))
    summary = dict(n_elements=n, t_end=t_end, knots=count, frames=len(times), rtol=RTOL, rms_error_N=rms,
                   max_error_N=float(np.max(np.abs(found - true))), evaluations=plan.evaluations,
                   iterations=len(plan.history) - 1, loss_start=plan.history[0], loss_end=plan.history[-1],
                   success=plan.success, wall_s=wall, cpu_s=cpu)
    print(summary, flush=True)
    table = [dict(t=float(t), true_N=float(a), found_N=float(b)) for t, a, b in zip(knots, true, found)]
    fig, (top, bottom) = plt.subplots(2, 1, figsize=(7, 6), sharex=True)
    fine = np.linspace(0.0, t_end, 601)
    top.plot(fine, np.interp(fine, knots, true), "k-", lw=3, alpha=0.3, label="bending test")
    top.plot(fine, np.interp(fine, knots, found), "C1--", label=f"found from zero (RMS {rms:.1e} N)")
    top.plot(knots, found, "C1o")
    top.set_ylabel("tension of cable 11 [N]")
    top.legend()
    tip = plan.result.tip
    moving = np.argsort(np.ptp(recorded.tip, axis=0))[::-1][:2]  # the two components that move most
    for axis, name in ((a, "xyz"[a]) for a in sorted(moving)):
        bottom.plot(times, recorded.tip[rows][:, axis], f"C{axis}.", ms=4, label=f"recorded tip {name}")
        bottom.plot(plan.result.t, tip[:, axis], f"C{axis}-", lw=1, label=f"optimised run's tip {name}")
    bottom.set_xlabel("t [s]")
    bottom.set_ylabel("tip position [m]")
    bottom.legend(fontsize=8)
    C.save_figure(fig, os.path.join(args.out, "optimal_tensions.png"))
    sections = [
        (f"the bending test recovered (paper's arm N = {n}, {t_end:g} s, {count} knots, tip every 0.1 s, from "
         "zero tension)", C.markdown_table([summary], formats=dict(rms_error_N=".1e", max_error_N=".1e",
                                                                    loss_start=".3g", loss_end=".3g",
                                                                    wall_s=".1f", cpu_s=".1f"))),
        ("the knots", C.markdown_table(table, formats=dict(true_N=".4f", found_N=".4f"))),
    ]
    C.write_results(args, "optimal_tensions", "Optimal tensions: the bending test recovered", header,
                    [dict(table="summary", **summary)] + [dict(table="knots", **row) for row in table], sections)


if __name__ == "__main__":
    main()
