"""Where a step of the bending test goes: counts per run times cost per call.

The paper's bending test (6 s, default scheme and rtol, outputs every 10 ms)
at N = 100 and at N = 30, CVODE with the default linear solver. Three parts:

1. Counts of one run: CVODE's steps, right-hand sides, preconditioner
   setups and solves, Jacobian evaluations, and the Python calls of
   scikit-sundae's ``step`` (one-step calls, the ones that hand the last
   step back again after outputs were interpolated inside it, and the
   interpolations at output times).
2. Cost per call (best of 7 batches): each compiled kernel bare and through
   its Python caller, one scikit-sundae interpolation call and one repeated
   one-step call, rodmol's per-step checks.
3. The whole run three ways, interleaved, median of the CPU time (the
   process's, from the first step to the last output, ``_common.run_cpu``:
   on a shared machine the wall time counts the other jobs' time slices
   too): rodmol's driver
   (``rodmol.solve.backends.cvode``); a bare loop of one-step calls with the
   same solver options and outputs (no watch, no output store, the system
   itself as the right-hand side); the same loop without the outputs
   (states at the steps' ends only, so no interpolation and no repeated
   step). The differences are the cost of rodmol's loop and of the outputs.

The table multiplies (1) by (2); what is left of the driver's CPU time is
CVODE's own work in C (vector operations, BDF, GMRES) and scikit-sundae's
Cython wrappers of the callbacks, which cannot be timed apart from Python.

    python solvers/step_overhead.py [--quick | --smoke] [--out DIR] [--reps K]
"""

import os
import time

import _common as C
from _common import np, rodmol

from rodmol.discretise import stencil
from rodmol.discretise.preconditioner import block_solve
from rodmol.solve.stepping import Stepper, solver_options
from rodmol.solve.watch import Watch

SCRIPT = "step_overhead.py"


def per_call(fn, calls):
    """Seconds per call: the best of 7 batches of ``calls / 7`` calls."""
    fn()
    batch = max(1, calls // 7)
    best = float("inf")
    for _ in range(7):
        t0 = time.perf_counter()
        for _ in range(batch):
            fn()
        best = min(best, (time.perf_counter() - t0) / batch)
    return best


class CountingSolver:
    """scikit-sundae's CVODE with its ``step`` calls counted by kind."""

    def __init__(self, solver):
        self.solver, self.onestep, self.repeats, self.interpolations, self.reached = solver, 0, 0, 0, -np.inf

    def step(self, t, method="normal", tstop=None):
        r = self.solver.step(t, method, tstop)
        if method == "onestep":
            self.onestep += 1
            self.repeats += r.t <= self.reached
            self.reached = max(self.reached, r.t)
        else:
            self.interpolations += 1
        return r

    def __getattr__(self, name):
        return getattr(self.solver, name)


def counts(system, y0, t_out, rtol, atol):
    """The counts of one run of rodmol's driver (its Stepper's solver wrapped)."""
    import sys

    sys.path.insert(0, C.HERE)
    import _cvode_stats

    made = []
    init = Stepper.__init__

    def counting(stepper, *args, **kwargs):
        init(stepper, *args, **kwargs)
        stepper._solver = CountingSolver(stepper._solver)
        made.append(stepper)

    Stepper.__init__ = counting
    try:
        with _cvode_stats.Recorder() as rec:
            raw = C.cvode(system, y0, t_out, rtol=rtol, atol=atol)
    finally:
        Stepper.__init__ = init
    cv = _cvode_stats.counters(rec.solvers[-1], raw.stats["rhs_evals"])
    s = made[-1]._solver
    return raw, dict(steps=cv["steps"], rhs=raw.stats["rhs_evals"], newton=cv["newton_iters"],
                     krylov=cv["krylov_iters"], psetups=raw.stats.get("prec_setups", cv["linear_setups"]),
                     psolves=raw.stats.get("prec_solves", 0), jacobians=raw.stats["jac_evals"],
                     onestep=s.onestep, repeats=s.repeats, interpolations=s.interpolations)


def costs(system, y0, rtol, atol, calls):
    """Microseconds per call of each piece, on a state of the run (after 50 steps)."""
    stepper = Stepper(system, 0.0, y0, rtol=rtol, atol=atol)
    watch = Watch(system, (0.0, 6.0))
    r = None
    for _ in range(50):
        r, _ = stepper.step(6.0, stepper.stop_time(6.0), watch)
    t, y = r.t, np.array(r.y)
    inside = r.t - 0.25 * stepper.sizes[-1]
    out = np.empty_like(y)
    system.update_inputs(t, y)
    karg = system.kernel_arguments()
    pre = stepper.precond
    us = {}
    us["rhs kernel"] = per_call(lambda: stencil.rhs(y, out, *karg), calls)
    us["rhs through SemiDiscrete"] = per_call(lambda: system(t, y, out), calls)
    stepper.mark()

    def rodmol_rhs():
        stepper.evals = 0  # below watched_from: no check, as in a run between two frames
        stepper._rhs(t, y, out)

    us["rhs through the Stepper (rodmol's callback)"] = per_call(rodmol_rhs, calls)
    if pre is not None:
        fy = system(t, y)
        y.flags.writeable = False
        g, head, fac, scratch = pre.factors
        us["preconditioner solve kernel"] = per_call(lambda: block_solve(g, head, fac, fy, out, *scratch), calls)
        us["preconditioner solve (rodmol's callback)"] = per_call(
            lambda: pre.solve(t, y, fy, fy, out, g, 0.0, 1), calls)
        us["preconditioner setup, Jacobian kept (factor)"] = per_call(lambda: pre.factor(g), calls // 20)
        us["Jacobian evaluation (compiled)"] = per_call(lambda: pre.jacobian.evaluate(t, y, fy), calls // 20)
        pre.factor(g)
    solver = stepper._solver
    us["scikit-sundae interpolation call"] = per_call(lambda: solver.step(inside), calls)

    def pair():  # an interpolation, then the one-step call that hands the same step back
        solver.step(inside)
        solver.step(6.0, method="onestep", tstop=6.0)

    us["scikit-sundae repeated one-step call"] = per_call(pair, calls) - us["scikit-sundae interpolation call"]
    us["rodmol's per-step checks (watch.state, stop_time, pace)"] = per_call(
        lambda: (watch.state(t, 1e-3, y), stepper.stop_time(6.0), watch.pace(t, y)), calls)
    return {k: v * 1e6 for k, v in us.items()}


def bare_loop(system, y0, t_out, rtol, atol, outputs=True):
    """CPU time [s] of a bare one-step loop with rodmol's solver options, from the first
    step on: the outputs interpolated (``outputs``) or only the steps' ends kept."""
    from sksundae.cvode import CVODE

    options, _, _ = solver_options(system, rtol, atol)
    solver = CVODE(system, **options)
    knots = np.unique(np.asarray(system.knot_times(), dtype=float))
    t_end = float(t_out[-1])
    ys = np.empty((len(t_out), len(y0)))
    solver.init_step(float(t_out[0]), y0)
    start = time.process_time()
    k, reached = 1, float(t_out[0])
    while reached < t_end:
        j = np.searchsorted(knots, reached, side="right")
        tstop = float(knots[j]) if j < len(knots) and knots[j] < t_end else t_end
        r = solver.step(float(t_out[min(k, len(t_out) - 1)]), method="onestep", tstop=tstop)
        if not r.success:
            raise RuntimeError(r.message)
        reached = max(reached, r.t)
        while k < len(t_out) and t_out[k] <= r.t:
            ys[k] = solver.step(float(t_out[k])).y if outputs else r.y
            k += 1
    return time.process_time() - start


def driver(system, y0, t_out, rtol):
    """(CPU time [s] of rodmol's driver from its first step on; its solver wall time [s])."""
    raw, cpu = C.run_cpu(C.cvode, system, y0, t_out, rtol)
    return cpu, raw.stats["wall_time_s"]


def study(n, t_end, reps, calls):
    model = rodmol.scenarios.get("bending").model(n)
    system = C.SemiDiscrete(model)
    y0 = C.initial_state(model, system=system)
    rtol = rodmol.SCHEMES[system.scheme.name].default_rtol
    atol = C.default_atol(model, rtol)
    t_out = C.outputs(t_end)
    C.warm_up(system, y0)
    raw, count = counts(system, y0, t_out, rtol, atol)
    us = costs(system, y0, rtol, atol, calls)
    cpu = {"rodmol's driver": [], "bare loop, outputs interpolated": [], "bare loop, no outputs": []}
    walls = []
    for _ in range(reps):
        c, w = driver(system, y0, t_out, rtol)
        cpu["rodmol's driver"].append(c)
        walls.append(w)
        cpu["bare loop, outputs interpolated"].append(bare_loop(system, y0, t_out, rtol, atol))
        cpu["bare loop, no outputs"].append(bare_loop(system, y0, t_out, rtol, atol, outputs=False))
    wall = {k: float(np.median(v)) for k, v in cpu.items()}
    total = wall["rodmol's driver"]
    linsolver = raw.stats["linear_solver"]

    def row(part, calls_, cost_us, ms=None):
        ms = calls_ * cost_us * 1e-3 if ms is None else ms
        return dict(N=n, part=part, calls=calls_, us_per_call=cost_us, ms_per_run=ms, share=ms * 1e-3 / total,
                    us_per_step=ms * 1e3 / count["steps"])

    rows = [row("right-hand side, kernel", count["rhs"], us["rhs kernel"]),
            row("right-hand side, the system's Python around it (inputs, dispatch)", count["rhs"],
                us["rhs through SemiDiscrete"] - us["rhs kernel"])]
    if "preconditioner solve kernel" in us:
        rows += [row("preconditioner solve, kernel", count["psolves"], us["preconditioner solve kernel"]),
                 row("preconditioner solve, the Python around it", count["psolves"],
                     us["preconditioner solve (rodmol's callback)"] - us["preconditioner solve kernel"]),
                 row("preconditioner setup (factor)", count["psetups"],
                     us["preconditioner setup, Jacobian kept (factor)"]),
                 row("Jacobian evaluation", count["jacobians"], us["Jacobian evaluation (compiled)"])]
    rows += [row("scikit-sundae one-step calls (a new step)", count["onestep"] - count["repeats"], float("nan"), 0.0),
             row("scikit-sundae repeated one-step calls", count["repeats"],
                 us["scikit-sundae repeated one-step call"]),
             row("scikit-sundae interpolation calls", count["interpolations"],
                 us["scikit-sundae interpolation call"]),
             row("rodmol's loop: checks, output store, the Stepper's callback (driver - bare loop)",
                 count["onestep"], float("nan"),
                 (total - wall["bare loop, outputs interpolated"]) * 1e3)]
    known = sum(r["ms_per_run"] for r in rows)
    rows.append(row("CVODE in C, scikit-sundae's callback wrappers and step calls (the rest)", count["steps"],
                    float("nan"), total * 1e3 - known))
    rows.append(row("whole run (rodmol's driver, CPU time)", count["steps"], float("nan"), total * 1e3))
    summary = dict(N=n, linear_solver=linsolver, cpu_ms=total * 1e3, realtime_cpu=t_end / total,
                   solver_wall_ms=float(np.median(walls)) * 1e3, us_per_step=total * 1e6 / count["steps"],
                   bare_loop_ms=wall["bare loop, outputs interpolated"] * 1e3,
                   bare_loop_no_outputs_ms=wall["bare loop, no outputs"] * 1e3, **count)
    print(summary, flush=True)
    for r in rows:
        print(f"  {r['part']:72s} {r['calls']:6d} x {r['us_per_call']:7.2f} us = {r['ms_per_run']:7.2f} ms "
              f"({100 * r['share']:4.1f}%)", flush=True)
    return rows, summary, [dict(N=n, operation=k, microseconds=v) for k, v in us.items()]


def main(argv=None):
    args = C.parse_args(__doc__.splitlines()[0], argv)
    if args.reps == 3 and args.mode != "smoke":
        args.reps = 9
    header = C.header_lines(args, SCRIPT)
    sizes = C.pick(args, (100, 30), (100, 30), (8,))
    t_end = C.pick(args, 6.0, 6.0, 0.2)
    calls = C.pick(args, 2100, 700, 70)
    rows, summaries, call_rows = [], [], []
    for n in sizes:
        r, s, c = study(n, t_end, args.reps, calls)
        rows += r
        summaries.append(s)
        call_rows += c
    base = os.path.join(args.out, "step_overhead")
    note = (f"bending test, {t_end:g} s, default scheme and rtol, outputs every 10 ms; whole runs: CPU time, "
            f"medians of {args.reps} interleaved runs (solver_wall_ms: the driver's wall time, median); per call: "
            f"best of 7 batches of {calls // 7}")
    C.write_csv(base + ".csv", rows, header + [note])
    C.write_csv(base + "_runs.csv", summaries, header + [note])
    C.write_csv(base + "_calls.csv", call_rows, header + [note])
    fmt = {"us_per_call": ".2f", "ms_per_run": ".2f", "share": ".1%", "us_per_step": ".1f", "cpu_ms": ".1f",
           "solver_wall_ms": ".1f", "realtime_cpu": ".0f", "bare_loop_ms": ".1f", "bare_loop_no_outputs_ms": ".1f", "microseconds": ".2f"}
    sections = [("Runs", note + "\n\n" + C.markdown_table(summaries, None, fmt)),
                ("Where the time goes", C.markdown_table(rows, None, fmt)),
                ("Per call", C.markdown_table(call_rows, None, fmt))]
    C.write_markdown(base + ".md", "Where a step of the bending test goes", header, sections)
    print("wrote", base + ".{csv,md}")


if __name__ == "__main__":
    main()
