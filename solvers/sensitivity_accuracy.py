"""Forward sensitivities: their accuracy against rtol, and their cost against the plain run.

The paper's arm (N elements) pulled by cable 11 along a knot history (up,
held, released, pulled again), from its equilibrium, for --t-end seconds:

* accuracy: the tip's sensitivity to ``material.E``, ``medium.Cy,Cz`` and
  the second knot of ``tension.11``, integrated at rtol 1e-4 .. 1e-8
  (``simulate(..., sensitivities=[...])``), against central differences of
  two runs of ``simulate`` at rtol 1e-10 (step 1e-3 of the value): the
  largest difference over the frames relative to the largest derivative;
* cost: the run with 2 parameters (E, Cy,Cz) against the plain run, same
  rtol, same settings otherwise (the plain run's own linear solver, band
  below 50 elements, and GMRES), in one process, alternating which goes
  first, the median of --reps: wall time, and the process's CPU time, the
  ratios' measure (other processes on a shared machine move wall times by
  2x, not CPU times).

    python solvers/sensitivity_accuracy.py [--quick | --smoke] [--out DIR] [--reps K]
"""

import time

import _common as C
from _common import np, rodmol

from rodmol import named_parameters

SCRIPT = "sensitivity_accuracy.py"
KEYS = (("material.E", 0), ("medium.Cy,Cz", 0), ("tension.11", 1))
REFERENCE_RTOL, REFERENCE_STEP = 1e-10, 1e-3


def arm(n):
    knots = [(0.0, 0.0), (0.5, 2.0), (1.5, 2.0), (2.0, 0.0), (4.0, 0.0), (4.5, 1.0)]
    return rodmol.paper_arm(n, tensions={11: knots})


def reference(model, key, component, t_end, output_dt):
    p = named_parameters.parameter(model, key)
    h = REFERENCE_STEP * p.scale
    up, down = p.value.copy(), p.value.copy()
    up[component] += h
    down[component] -= h
    tips = [rodmol.simulate(p.at(model, v), t_end, rtol=REFERENCE_RTOL, output_dt=output_dt).tip for v in (up, down)]
    return (tips[0] - tips[1]) / (2.0 * h)


def accuracy(model, t_end, output_dt, rtols):
    references = {key: reference(model, key, c, t_end, output_dt) for key, c in KEYS}
    rows = []
    for rtol in rtols:
        start = time.perf_counter()
        run = rodmol.simulate(model, t_end, rtol=rtol, output_dt=output_dt, sensitivities=[k for k, _ in KEYS])
        wall = time.perf_counter() - start
        assert run.success, run.message
        row = dict(rtol=rtol, steps=run.stats["steps"], wall_s=wall)
        for key, component in KEYS:
            tip = run.sensitivity(key).tip
            tip = tip[component] if key.startswith("tension") else tip
            ref = references[key]
            row[f"error_{key.split('.')[-1].replace(',', '')}"] = float(np.max(np.abs(tip - ref)) / np.max(np.abs(ref)))
        rows.append(row)
        print(row, flush=True)
    return rows


def timed(model, t_end, output_dt, rtol, options):
    start, cpu = time.perf_counter(), time.process_time()
    run = rodmol.simulate(model, t_end, rtol=rtol, output_dt=output_dt, **options)
    wall, cpu = time.perf_counter() - start, time.process_time() - cpu
    assert run.success, run.message
    return wall, cpu, run.stats["steps"], run.stats["linear_solver"]


def cost(model, t_end, output_dt, rtols, reps):
    cases = {"plain": {}, "plain, gmres": dict(linsolver="gmres"),
             "2 sensitivities": dict(sensitivities=["material.E", "medium.Cy,Cz"])}
    rows = []
    for rtol in rtols:
        walls, cpus, info = {case: [] for case in cases}, {case: [] for case in cases}, {}
        for rep in range(reps):
            order = list(cases) if rep % 2 == 0 else list(reversed(cases))
            for case in order:
                wall, cpu, steps, solver = timed(model, t_end, output_dt, rtol, cases[case])
                walls[case].append(wall)
                cpus[case].append(cpu)
                info[case] = (steps, solver)
        plain, gmres = float(np.median(cpus["plain"])), float(np.median(cpus["plain, gmres"]))
        for case in cases:
            cpu = float(np.median(cpus[case]))
            rows.append(dict(rtol=rtol, run=case, linear_solver=info[case][1], steps=info[case][0],
                             wall_s=float(np.median(walls[case])), cpu_s=cpu, ratio_to_plain=cpu / plain,
                             ratio_to_gmres=cpu / gmres))
            print(rows[-1], flush=True)
    return rows


def main(argv=None):
    args = C.parse_args(__doc__.splitlines()[0], argv)
    header = C.header_lines(args, SCRIPT)
    n, t_end = C.pick(args, 30, 20, 8), C.pick(args, 6.0, 2.0, 0.3)
    output_dt = C.pick(args, 0.02, 0.02, 0.05)
    model = arm(n)
    rodmol.simulate(model, 0.05, sensitivities=["material.E"])  # compile and warm up
    rtols = C.pick(args, (1e-4, 1e-5, 1e-6, 1e-7, 1e-8), (1e-4, 1e-6, 1e-8), (1e-4, 1e-6))
    accurate = accuracy(model, t_end, output_dt, rtols)
    costs = cost(model, t_end, output_dt, C.pick(args, (1e-4, 1e-6, 1e-8), (1e-6,), (1e-6,)), args.reps)
    errors = {f"error_{k.split('.')[-1].replace(',', '')}": ".1e" for k, _ in KEYS}
    sections = [
        (f"accuracy of the tip's sensitivities, paper's arm N = {n}, {t_end:g} s from its equilibrium, against "
         f"central differences of runs at rtol {REFERENCE_RTOL:g} (largest difference / largest derivative; "
         "tension11: its second knot)",
         C.markdown_table(accurate, formats=dict(wall_s=".3f", **errors))),
        (f"cost: 2 parameters (E, Cy,Cz) against the plain run at the same rtol, median of {args.reps}; "
         "ratios of CPU time",
         C.markdown_table(costs, formats=dict(wall_s=".3f", cpu_s=".3f", ratio_to_plain=".2f",
                                              ratio_to_gmres=".2f"))),
    ]
    C.write_results(args, "sensitivity_accuracy", "Forward sensitivities: accuracy and cost", header,
                    [dict(table="accuracy", **row) for row in accurate] + [dict(table="cost", **row) for row in costs],
                    sections)


if __name__ == "__main__":
    main()
