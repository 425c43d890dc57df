"""Where the time goes: right-hand side, Jacobian, linear algebra, callback overhead.

1. Per call (best of 7 batches): the compiled right-hand side through
   ``SemiDiscrete.__call__`` and the bare kernel (the difference is the
   Python cost of a call: inputs, dispatch), the compiled Jacobian, and the
   block preconditioner's factorisation and solve. (There is one kernel, the
   compiled one; the numpy reference it was once compared with here is gone.)
2. A whole bending run per linear solver under cProfile, grouped into:
   the compiled kernels (right-hand side, Jacobian, preconditioner), the
   Python around them (rodmol's callbacks), and what runs inside
   scikit-sundae's ``step`` itself: CVODE in C (BDF, Newton, GMRES or the
   band LU, vector operations) plus scikit-sundae's Cython wrappers.
   The run is also timed without the profiler.
3. What each solver change bought: the same run with the band LU and
   SUNDIALS' Jacobian, the band LU with the compiled Jacobian, and GMRES
   with the block preconditioner (interleaved repetitions, median).

    python solvers/profile_rhs.py [--quick | --smoke] [--out DIR]
"""

import cProfile
import os
import pstats
import time
from dataclasses import replace

import _common as C
from _common import np, plt, rodmol

from rodmol.discretise import stencil

SCRIPT = "profile_rhs.py"


def per_call(fn, reps):
    """Seconds per call: the best of 7 batches of ``reps / 7`` calls (as timeit:
    the other batches were slowed down by something else on the machine)."""
    fn()
    batch = max(1, reps // 7)
    times = []
    for _ in range(7):
        t0 = time.perf_counter()
        for _ in range(batch):
            fn()
        times.append((time.perf_counter() - t0) / batch)
    return float(np.min(times))


# cProfile entries (file suffix, function name) -> group
GROUPS = [
    (("stencil.py", "rhs"), "kernel: right-hand side"),
    (("jacobian.py", "jacobian_blocks"), "kernel: Jacobian"),
    (("jacobian.py", "fill_matrix"), "kernel: Jacobian"),
    (("preconditioner.py", "block_setup"), "kernel: preconditioner setup"),
    (("preconditioner.py", "block_solve"), "kernel: preconditioner solve"),
    (("_solver.py", "step"), "CVODE (C) + scikit-sundae wrappers"),
]


def breakdown(stats):
    groups = {}
    for (filename, _, name), (_, _, tottime, _, _) in stats.stats.items():
        label = "Python: rodmol callbacks and loop"
        for (suffix, fname), group in GROUPS:
            if filename.endswith(suffix) and name == fname:
                label = group
                break
        else:
            if "sksundae" in filename or "numba" in filename or filename.startswith("<") or \
                    filename.startswith("~"):
                label = "Python: other (scikit-sundae, numpy, numba dispatch)"
        groups[label] = groups.get(label, 0.0) + tottime
    return groups


def main(argv=None):
    args = C.parse_args(__doc__.splitlines()[0], argv)
    header = C.header_lines(args, SCRIPT)
    n = C.pick(args, 100, 100, 8)
    t_end = C.pick(args, 6.0, 2.0, 0.2)
    reps = C.pick(args, 2000, 500, 50)

    model = rodmol.scenarios.get("bending").model(n)
    y0 = C.initial_state(model)
    fast = C.SemiDiscrete(model)
    rng = np.random.default_rng(0)
    y = y0 + 1e-4 * rng.normal(size=y0.size)
    out = np.empty_like(y)
    fast.update_inputs(0.3, y)
    karg = fast.kernel_arguments()
    atol = C.default_atol(model, 1e-6)
    pre = fast.preconditioner(atol / 1e-6)
    fy = fast(0.3, y)
    pre.setup(0.3, y, fy, False, [0], 1e-3)
    z = np.empty_like(y)
    # The same arm with friction on every cable: the capstan factors of each
    # cable's whole path are evaluated at every call (rodmol.discretise.routing).
    rough = C.SemiDiscrete(model.replace(cables=[replace(c, friction=0.3) for c in model.cables]))

    calls = [
        ("right-hand side, compiled (SemiDiscrete call)", per_call(lambda: fast(0.3, y, out), reps)),
        ("right-hand side, bare kernel", per_call(lambda: stencil.rhs(y, out, *karg), reps)),
        ("right-hand side with friction on every cable", per_call(lambda: rough(0.3, y, out), reps)),
        (f"Jacobian, compiled ({pre.jacobian.evaluations} kernel evaluations)", per_call(lambda: pre.jacobian.evaluate(0.3, y, fy),
                                                                 max(20, reps // 50))),
        ("preconditioner setup (factor I - gamma J)", per_call(lambda: pre.factor(1e-3), max(20, reps // 20))),
        ("preconditioner solve", per_call(lambda: pre.solve(0.3, y, fy, fy, z, 1e-3, 0.0, 1), reps)),
    ]
    call_rows = [dict(operation=k, microseconds=v * 1e6) for k, v in calls]
    overhead = calls[0][1] - calls[1][1]
    for r in call_rows:
        print(f"{r['operation']:48s} {r['microseconds']:9.2f} us", flush=True)

    system = C.SemiDiscrete(model)
    t_out = C.outputs(t_end)
    run_rows, groups_by_solver = [], {}
    for linsolver in ("gmres", "band"):
        C.warm_up(system, y0, linsolver=linsolver)
        plain = C.run(C.cvode, system, y0, t_out, 1e-6, linsolver=linsolver)
        profiler = cProfile.Profile()
        profiler.enable()
        C.run(C.cvode, system, y0, t_out, 1e-6, linsolver=linsolver)
        profiler.disable()
        groups = breakdown(pstats.Stats(profiler))
        total = sum(groups.values())
        groups_by_solver[linsolver] = groups
        st = plain.stats
        for label, seconds in sorted(groups.items(), key=lambda kv: -kv[1]):
            run_rows.append(dict(linsolver=linsolver, part=label, seconds=seconds, share=seconds / total))
        run_rows.append(dict(linsolver=linsolver, part="total under cProfile", seconds=total, share=1.0))
        run_rows.append(dict(linsolver=linsolver, part="total without profiler", seconds=st["wall_time_s"],
                             share=""))
        print(f"{linsolver}: {st['wall_time_s']:.3f} s for {t_end:g} s ({st['steps']} steps, "
              f"{st['rhs_evals']} RHS calls)", flush=True)
        rhs_share = groups.get("kernel: right-hand side", 0.0) / total
        print(f"   right-hand side kernel: {100 * rhs_share:.0f}% of the run", flush=True)

    # What each change bought: the same run with the pieces switched on in
    # turn (same process, interleaved repetitions, median).
    ladder = [
        ("band LU, SUNDIALS Jacobian (the start)", dict(linsolver="band", jacobian="sundials")),
        ("band LU, compiled Jacobian", dict(linsolver="band", jacobian="compiled")),
        ("GMRES + block preconditioner (default)", dict(linsolver="gmres")),
    ]
    for _, opts in ladder:
        C.warm_up(system, y0, **opts)
    walls = {label: [] for label, _ in ladder}
    last = {}
    for _ in range(args.reps):
        for label, opts in ladder:
            raw = C.run(C.cvode, system, y0, t_out, 1e-6, **opts)
            walls[label].append(raw.stats["wall_time_s"])
            last[label] = raw.stats
    start = np.median(walls[ladder[0][0]])
    ladder_rows = []
    prev = start
    for label, _ in ladder:
        w = float(np.median(walls[label]))
        ladder_rows.append(dict(configuration=label, wall_s=w, wall_per_sim_s=w / t_end,
                                speedup_vs_previous=prev / w, speedup_vs_start=start / w,
                                steps=last[label]["steps"], rhs_evals=last[label]["rhs_evals"]))
        prev = w
        print(f"{label}: {w:.3f} s ({start / w:.1f}x the start)", flush=True)

    base = os.path.join(args.out, "profile_rhs")
    C.write_csv(base + "_ladder.csv", ladder_rows, header + [f"bending test, N = {n}, {t_end:g} s, rtol 1e-6"])
    C.write_csv(base + "_calls.csv", call_rows, header + [f"bending model, N = {n}"])
    C.write_csv(base + ".csv", run_rows, header + [f"bending test, N = {n}, {t_end:g} s, rtol 1e-6"])

    fig, ax = plt.subplots(figsize=(8, 4.8))
    labels = sorted({k for g in groups_by_solver.values() for k in g})
    left = np.zeros(len(groups_by_solver))
    names = list(groups_by_solver)
    for label in labels:
        vals = np.array([groups_by_solver[s].get(label, 0.0) for s in names])
        ax.barh(names, vals, left=left, label=label)
        left += vals
    ax.set_xlabel("seconds under cProfile")
    ax.set_title(f"bending test, N = {n}, {t_end:g} s: where the time goes")
    ax.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.18), ncol=2)
    C.save_figure(fig, base + ".png")

    sections = [
        ("Per call", C.markdown_table(call_rows, None, {"microseconds": ".2f"})
         + f"\nThe Python around a call of the right-hand side costs {overhead * 1e6:.1f} us.\n"),
        ("What each solver change bought (compiled right-hand side throughout; same run, median of "
         "repetitions)",
         C.markdown_table(ladder_rows, None, {"wall_s": ".3f", "wall_per_sim_s": ".4f",
                                              "speedup_vs_previous": ".2f", "speedup_vs_start": ".1f"})),
        ("Whole run, grouped", C.markdown_table(run_rows, None, {"seconds": ".4f", "share": ".1%"})
         + "\ncProfile adds its own overhead to every Python call, so the Python shares are upper "
           "bounds; 'CVODE (C) + scikit-sundae wrappers' is the time spent inside scikit-sundae's "
           "`step` outside any Python callback.\n"),
        ("Figure", f"![profile]({os.path.basename(base)}.png)\n"),
    ]
    C.write_markdown(base + ".md", "Profile of a run", header, sections)
    print("wrote", base + ".{csv,md,png}")


if __name__ == "__main__":
    main()
