"""Adjoint gradients: their cost against the plain run, and their accuracy against rtol.

The paper's arm (N elements) pulled by cable 11 along a smooth history of --knots
knots, from its equilibrium, for --t-end seconds; the loss is the tip's distance to a
track recorded with another history (TipTracking at every 0.1 s):

* cost: ``rodmol.gradient`` by the 100 knots of ``tension.11``, ``material.E`` and
  ``medium.Cy,Cz`` (102 components) against ``simulate`` of the same run at the same
  rtol (the run's own linear solver), in one process, alternating which goes first,
  the median of --reps; CPU time (other processes on a shared machine move wall
  times by 2x); the gradient with bounded memory (``checkpoint_every=20``) too;
* accuracy: the gradient at rtol 1e-4 .. 1e-8 against central differences of the
  loss of two runs of ``simulate`` at rtol 1e-10 (step 1e-3 of the value): E, Cy,Cz
  and two knots (relative to the largest knot component); E and Cy,Cz also against
  the forward sensitivities of one run at rtol 1e-10 (``simulate(...,
  sensitivities=[...])``, the loss's derivative by the chain rule), a reference
  without the differences' cancellation.

    python solvers/adjoint_cost.py [--quick | --smoke] [--out DIR] [--reps K]
"""

import time

import _common as C
from _common import np, rodmol

from rodmol import named_parameters

SCRIPT = "adjoint_cost.py"
REFERENCE_RTOL, REFERENCE_STEP = 1e-10, 1e-3
KEYS = ["tension.11", "material.E", "medium.Cy,Cz"]


def arm(n, t_end, knots, phase=0.0):
    t = np.linspace(0.0, t_end, knots)
    return rodmol.paper_arm(n, tensions={11: list(zip(t, 1.0 + np.sin(2.0 * np.pi * t / t_end + phase) ** 2))})


def case(n, t_end, knots):
    times = np.linspace(0.1, t_end, int(round(t_end / 0.1)))
    recorded = rodmol.simulate(arm(n, t_end, knots, phase=0.7), t_end, output_times=times, rtol=1e-8)
    targets = recorded.tip[np.searchsorted(recorded.t, times)]
    return arm(n, t_end, knots), times, rodmol.TipTracking(times, targets)


def loss_of(model, t_end, times, loss, rtol):
    run = rodmol.simulate(model, t_end, output_times=times, rtol=rtol)
    assert run.success, run.message
    return float(np.sum((run.tip[np.searchsorted(run.t, times)] - loss.targets) ** 2))


def accuracy(model, t_end, times, loss, rtols, knot_components):
    checks = [("material.E", 0), ("medium.Cy,Cz", 0)] + [("tension.11", k) for k in knot_components]
    references = {}
    for key, component in checks:
        p = named_parameters.parameter(model, key)
        h = REFERENCE_STEP * p.scale
        up, down = p.value.copy(), p.value.copy()
        up[component] += h
        down[component] -= h
        references[key, component] = (loss_of(p.at(model, up), t_end, times, loss, REFERENCE_RTOL)
                                      - loss_of(p.at(model, down), t_end, times, loss, REFERENCE_RTOL)) / (2 * h)
    forward = rodmol.simulate(model, t_end, output_times=times, rtol=REFERENCE_RTOL,
                              sensitivities=["material.E", "medium.Cy,Cz"])
    rows_at = np.searchsorted(forward.t, times)
    residual = forward.tip[rows_at] - loss.targets
    by_forward = {key: float(2.0 * np.sum(residual * forward.sensitivity(key).tip[rows_at]))
                  for key in ("material.E", "medium.Cy,Cz")}
    rows = []
    for rtol in rtols:
        start = time.perf_counter()
        value, grads = rodmol.gradient(model, t_end, loss, KEYS, rtol=rtol)
        row = dict(rtol=rtol, wall_s=time.perf_counter() - start)
        largest_knot = np.max(np.abs(grads["tension.11"]))
        for key, component in checks:
            scale = largest_knot if key.startswith("tension") else abs(references[key, component])
            name = f"knot{component}" if key.startswith("tension") else key.split(".")[-1].replace(",", "")
            row[f"error_{name}"] = float(abs(grads[key][component] - references[key, component]) / scale)
        for key, reference in by_forward.items():
            name = key.split(".")[-1].replace(",", "")
            row[f"error_{name}_vs_forward"] = float(abs(grads[key][0] - reference) / abs(reference))
        rows.append(row)
        print(row, flush=True)
    return rows


def cost(model, t_end, times, loss, rtols, reps):
    runs = {"plain": lambda rtol: rodmol.simulate(model, t_end, output_times=times, rtol=rtol),
            "gradient (102 components)": lambda rtol: rodmol.gradient(model, t_end, loss, KEYS, rtol=rtol,
                                                                      stats=stats),
            "gradient, checkpoint_every=20": lambda rtol: rodmol.gradient(model, t_end, loss, KEYS, rtol=rtol,
                                                                          checkpoint_every=20, stats=stats)}
    rows, stats = [], {}
    for rtol in rtols:
        cpus, info = {name: [] for name in runs}, {}
        for rep in range(reps):
            for name in (list(runs) if rep % 2 == 0 else list(reversed(runs))):
                stats.clear()
                cpu = time.process_time()
                out = runs[name](rtol)
                cpus[name].append(time.process_time() - cpu)
                info[name] = dict(steps=out.stats["steps"]) if name == "plain" else dict(
                    steps=stats["forward_steps"], backward_steps=stats["backward_steps"],
                    kept_steps=stats["kept_steps"], forward_wall_s=stats["forward_s"],
                    backward_wall_s=stats["backward_s"])
        plain = float(np.median(cpus["plain"]))
        for name in runs:
            cpu = float(np.median(cpus[name]))
            rows.append(dict(rtol=rtol, run=name, cpu_s=cpu, ratio_to_plain=cpu / plain, **info[name]))
            print(rows[-1], flush=True)
    return rows


def main(argv=None):
    args = C.parse_args(__doc__.splitlines()[0], argv)
    header = C.header_lines(args, SCRIPT)
    n, t_end = C.pick(args, 30, 20, 8), C.pick(args, 6.0, 2.0, 0.3)
    knots = C.pick(args, 100, 100, 10)
    model, times, loss = case(n, t_end, knots)
    rodmol.gradient(model, min(t_end, 0.2), rodmol.TerminalTarget([0, 0, 0]), KEYS)  # compile and warm up
    rtols = C.pick(args, (1e-4, 1e-5, 1e-6, 1e-7, 1e-8), (1e-4, 1e-6, 1e-8), (1e-4, 1e-6))
    accurate = accuracy(model, t_end, times, loss, rtols, (knots // 4, knots // 2))
    costs = cost(model, t_end, times, loss, C.pick(args, (1e-4, 1e-6, 1e-8), (1e-6,), (1e-6,)), args.reps)
    errors = {k: ".1e" for k in accurate[0] if k.startswith("error_")}
    sections = [
        (f"accuracy of the gradient, paper's arm N = {n}, {t_end:g} s from its equilibrium, {knots} knots, against "
         f"central differences of the loss of runs at rtol {REFERENCE_RTOL:g} (|difference| / |reference|; a knot's "
         "/ the largest knot component)",
         C.markdown_table(accurate, formats=dict(wall_s=".3f", **errors))),
        (f"cost: the gradient by {knots} knots, E and Cy,Cz against the plain run at the same rtol, median of "
         f"{args.reps}; ratios of CPU time",
         C.markdown_table(costs, formats=dict(cpu_s=".3f", ratio_to_plain=".2f", forward_wall_s=".3f",
                                                    backward_wall_s=".3f"))),
    ]
    C.write_results(args, "adjoint_cost", "Adjoint gradients: cost and accuracy", header,
                    [dict(table="accuracy", **row) for row in accurate] + [dict(table="cost", **row) for row in costs],
                    sections)


if __name__ == "__main__":
    main()
