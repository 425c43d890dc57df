"""Why does the octopus take more right-hand sides than one arm? CVODE's
counters and the cost against the number of arms.

The octopus of ``octopus.py`` (its head, arms, cable patterns, N and
tolerances) with 1, 2, 4 and 8 arms on the free head, against one arm alone
(a Model, CVODE's band LU; and a one-rod System, GMRES); and two studies at
8 arms: the head fixed (the arms then share only the step size), and the
preconditioner as it was before the head's clamp links
(``SystemPreconditioner`` with only its penalty-joint links: each arm and
the head on their own, the tree coupling left to GMRES); and the octopus's eight arms each run
alone (a Model, its own cable and phase), and their sum: with the pulsing
pattern an arm whose phase makes it start under tension at t = 0 takes
more steps than the first arm, which starts from zero. Reported per case:
wall time (median of --reps interleaved rounds) and its ratio to one arm
alone, the same of the process's CPU time, right-hand sides, and CVODE's
counters (``_cvode_stats.py``): steps, error-test failures, Newton
iterations and convergence failures, GMRES iterations and convergence
failures, preconditioner Jacobians and setups, and the CPU time per
right-hand side; and the accuracy of the octopus's head and tips, with and
without the clamp links, against a run at rtol = 1e-8.

    python solvers/octopus_stats.py [--quick | --smoke] [--out DIR] [--reps K]
"""

import time

import _common as C
import _cvode_stats
import octopus as O
from _common import np, rodmol

from rodmol.discretise import system_preconditioner

SCRIPT = "octopus_stats.py"
ARM_COUNTS = (1, 2, 4, 8)


def _without_clamp_links(assembly, part, links=system_preconditioner.links):
    return [link for link in links(assembly, part) if not link.clamp]


def run(thing, t_end, options, before=False):
    """simulate ``thing``; (wall [s], CPU [s], result, CVODE's counters)."""
    links = system_preconditioner.links
    if before:
        system_preconditioner.links = _without_clamp_links
    try:
        with _cvode_stats.Recorder() as made:
            start, cpu = time.perf_counter(), time.process_time()
            result = rodmol.simulate(thing, t_end, **options)
            wall, cpu = time.perf_counter() - start, time.process_time() - cpu
    finally:
        system_preconditioner.links = links
    return wall, cpu, result, _cvode_stats.counters(made.solvers[-1], result.stats["rhs_evals"])


def _motion(result):
    """The head's position (n, 3) and the arms' tips (arms, n, 3) [m], global, of an octopus run."""
    return result["head"].position, np.array([result[name].tip for name in result.assembly.rods])


def main(argv=None):
    args = C.parse_args(__doc__.splitlines()[0], argv)
    header = C.header_lines(args, SCRIPT)
    n, t_end = O.settings(args)
    water = O.WATER
    rows, accuracy = [], []
    for name, pattern in O.PATTERNS.items():
        cases = [("one arm, Model (band LU)", O.arm(n, 1, pattern(0.0)).replace(gravity=water["gravity"]),
                  dict(initial="straight"), False),
                 ("one arm, System (GMRES)", rodmol.System({"a": O.arm(n, 1, pattern(0.0))}, **water), {}, False)]
        cases += [(f"{k} arm{'s' if k > 1 else ''} + free head", O.octopus(n, pattern, k), {}, False)
                  for k in ARM_COUNTS]
        cases += [(f"{O.ARMS} arms + fixed head", O.octopus(n, pattern, O.ARMS, "fixed"), {}, False),
                  (f"{O.ARMS} arms + free head, before (no clamp links)", O.octopus(n, pattern), {}, True)]
        # The octopus's other arms alone (Models), each with its cable and phase (arm 1 is the one above).
        alone = [(f"arm {i + 1} alone, Model", O.arm(n, 1 if i % 2 == 0 else 3, pattern(2.0 * np.pi * i / O.ARMS))
                  .replace(gravity=water["gravity"]), dict(initial="straight"), False) for i in range(1, O.ARMS)]
        cases += alone
        walls = {label: [] for label, *_ in cases}
        last = {}
        for _ in range(args.reps):  # interleaved: a change of the machine's load falls on every case
            for label, thing, options, before in cases:
                wall, cpu, result, counts = run(thing, t_end, options, before)
                walls[label].append((wall, cpu))
                last[label] = (result, counts)
        one = np.median(walls[cases[0][0]], axis=0)
        for label, *_ in cases:
            result, counts = last[label]
            wall, cpu = np.median(walls[label], axis=0)
            rhs = result.stats["rhs_evals"]
            row = dict(pattern=name, case=label, state_size=result.states.shape[1], wall_s=wall, cpu_s=cpu,
                       vs_one_arm=wall / one[0], cpu_vs_one_arm=cpu / one[1], rhs_evals=rhs, steps=counts["steps"],
                       error_test_fails=counts["error_test_fails"], newton_iters=counts["newton_iters"],
                       newton_conv_fails=counts["newton_conv_fails"], krylov_iters=counts["krylov_iters"],
                       krylov_conv_fails=counts["krylov_conv_fails"], jacobians=result.stats["jac_evals"],
                       linear_setups=counts["linear_setups"], cpu_us_per_rhs=1e6 * cpu / rhs,
                       success=result.success)
            rows.append(row)
            print(row, flush=True)
        # Accuracy: the octopus's head and tips against a run at rtol 1e-8, with and without the clamp links.
        reference = _motion(run(O.octopus(n, pattern), t_end, dict(rtol=1e-8))[2])
        for label in (f"{O.ARMS} arms + free head", f"{O.ARMS} arms + free head, before (no clamp links)"):
            head, tips = _motion(last[label][0])
            accuracy.append(dict(pattern=name, case=label, head_error_m=float(np.abs(head - reference[0]).max()),
                                 tip_error_m=float(np.abs(tips - reference[1]).max()), head_z_end_m=float(head[-1, 2])))
        arms = [row for row in rows[-len(cases):] if row["case"] in ([cases[0][0]] + [c[0] for c in alone])]
        total = {key: sum(row[key] for row in arms) for key in ("wall_s", "cpu_s", "rhs_evals", "steps")}
        rows.append(dict(pattern=name, case=f"the {O.ARMS} arms alone, summed", state_size=O.ARMS * rows[-1]["state_size"],
                         **total, vs_one_arm=total["wall_s"] / one[0], cpu_vs_one_arm=total["cpu_s"] / one[1],
                         cpu_us_per_rhs=1e6 * total["cpu_s"] / total["rhs_evals"], success=True))
    fmt = {"wall_s": ".3g", "vs_one_arm": ".2f", "cpu_s": ".3g", "cpu_vs_one_arm": ".2f", "cpu_us_per_rhs": ".0f"}
    columns = ["pattern", "case", "wall_s", "vs_one_arm", "cpu_s", "cpu_vs_one_arm", "rhs_evals", "steps", "error_test_fails", "newton_iters",
               "newton_conv_fails", "krylov_iters", "krylov_conv_fails", "jacobians", "linear_setups",
               "cpu_us_per_rhs"]
    C.write_results(args, "octopus_stats", "Octopus: CVODE's counters against the number of arms", header
                    + [f"N = {n}, t_end = {t_end:g} s, medians of {args.reps} interleaved rounds"], rows,
                    [("Results", C.markdown_table(rows, columns, fmt)),
                     ("Accuracy (against the same octopus at rtol = 1e-8; largest error over the output times)",
                      C.markdown_table(accuracy, None, {"head_error_m": ".2e", "tip_error_m": ".2e",
                                                        "head_z_end_m": ".6f"}))])


if __name__ == "__main__":
    main()
