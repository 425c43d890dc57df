"""Wall time per simulated second against N on the paper's bending test.

For each N: CVODE (rtol 1e-6, output every 10 ms, from the gravity
equilibrium) with the default linear solver and with the band LU, timed on
the solver alone (median of --reps runs, kernels compiled beforehand), with
steps, right-hand-side and Jacobian evaluations, real-time factor, the step
sizes CVODE takes against the paper's explicit stability limits, and the
whole ``rodmol.simulate`` call once (which adds the post-processing in
``rodmol.result``). Then: RK23 against CVODE at N = 100 (RK23 on a shorter
horizon), the 60 s fetching-and-holding run, and the cold JIT start.

    python solvers/scaling.py [--quick | --smoke] [--out DIR] [--reps K]
"""

import json
import os
import subprocess
import sys
import tempfile

import _common as C
from _common import np, plt, rodmol

SCRIPT = "scaling.py"


def bending_row(n, t_end, reps, linsolver, config):
    model = rodmol.scenarios.get("bending").model(n)
    system = C.SemiDiscrete(model)
    y0 = C.initial_state(model)
    t_out = C.outputs(t_end)
    C.warm_up(system, y0, linsolver=linsolver)
    wall, raw = C.timed(C.cvode, system, y0, t_out, 1e-6, reps, linsolver=linsolver)
    wave, viscous = C.explicit_limits(model)
    st = raw.stats
    return dict(N=n, config=config, linsolver=st["linear_solver"], wall_s=wall, wall_per_sim_s=wall / t_end,
                realtime_factor=t_end / wall, steps=st["steps"], rhs_evals=st["rhs_evals"],
                jac_evals=st["jac_evals"], prec_solves=st.get("prec_solves", 0),
                h_min_s=st["h_min"], h_median_s=st["h_median"], h_max_s=st["h_max"],
                wave_limit_s=wave, viscous_limit_s=viscous,
                h_median_over_viscous=st["h_median"] / viscous), (model, y0)


def simulate_total(model, y0, t_end):
    """One whole rodmol.simulate call [s] (solver + post-processing), and its solver time."""
    with C.Stopwatch() as sw:
        result = rodmol.simulate(model, t_end, initial=y0)
    return sw.seconds, result.stats["wall_time_s"]


def cold_start(n):
    """Seconds of JIT compilation in a fresh process with an empty numba cache."""
    code = (
        "import time; t0 = time.perf_counter(); import rodmol; t1 = time.perf_counter()\n"
        f"m = rodmol.scenarios.get('bending').model({n}); y0 = rodmol.equilibrium(m)\n"
        "t2 = time.perf_counter(); rodmol.simulate(m, 0.05, initial=y0); t3 = time.perf_counter()\n"
        "rodmol.simulate(m, 0.05, initial=y0); t4 = time.perf_counter()\n"
        "import json; print(json.dumps(dict(import_s=t1 - t0, first_s=t3 - t2, second_s=t4 - t3)))\n")
    out = {}
    with tempfile.TemporaryDirectory() as cache:
        env = dict(os.environ, NUMBA_CACHE_DIR=cache)
        for label in ("cold", "warm"):  # the cold run fills the cache the warm one reads
            res = subprocess.run([sys.executable, "-c", code], env=env, check=True, capture_output=True,
                                 text=True)
            out[label] = json.loads(res.stdout.strip().splitlines()[-1])
    # Start-up = what the cold process spends beyond the warm one (import + first run).
    cold, warm = out["cold"], out["warm"]
    jit = (cold["import_s"] + cold["first_s"]) - (warm["import_s"] + warm["first_s"])
    return dict(cold_import_s=cold["import_s"], cold_first_run_s=cold["first_s"],
                warm_import_s=warm["import_s"], warm_first_run_s=warm["first_s"],
                jit_start_up_s=jit)


def main(argv=None):
    args = C.parse_args(__doc__.splitlines()[0], argv)
    sizes = C.pick(args, [25, 50, 100, 200, 400, 800], [25, 50, 100, 200, 400], [8, 16])
    t_end = C.pick(args, 6.0, 6.0, 0.2)
    compare_band = C.pick(args, [25, 50, 100, 200, 400, 800], [25, 100, 400], [8])
    header = C.header_lines(args, SCRIPT)

    rows, totals, kept = [], [], {}
    for n in sizes:
        row, (model, y0) = bending_row(n, t_end, args.reps, "auto", "default")
        rows.append(row)
        kept[n] = (model, y0)
        total, solver = simulate_total(model, y0, t_end)
        totals.append(dict(N=n, simulate_total_s=total, solver_s=solver,
                           post_processing_s=total - solver, simulate_realtime_factor=t_end / total))
        print(f"N={n}: {row['wall_per_sim_s']:.4f} s per simulated s ({row['realtime_factor']:.1f}x "
              f"real time), simulate() {total:.3f} s", flush=True)
        if n in compare_band:
            # The other solver than the default's at this N, for comparison.
            other = "gmres" if row["linsolver"] == "band" else "band"
            alt, _ = bending_row(n, t_end, args.reps, other, other)
            rows.append(alt)
    auto = [r for r in rows if r["config"] == "default"]
    ns = np.array([r["N"] for r in auto], float)
    walls = np.array([r["wall_s"] for r in auto])
    slope = float(np.polyfit(np.log(ns), np.log(walls), 1)[0]) if len(ns) > 1 else float("nan")
    local = [dict(N=f"{int(a)}-{int(b)}", exponent=float(np.log(wb / wa) / np.log(b / a)))
             for a, b, wa, wb in zip(ns, ns[1:], walls, walls[1:])]

    # RK23 against CVODE, per simulated second, N = 100 (same run).
    n_rk = C.pick(args, 100, 100, 8)
    horizon = C.pick(args, 0.2, 0.1, 0.005)
    if n_rk in kept:
        model, y0 = kept[n_rk]
        cv = next(r for r in auto if r["N"] == n_rk)
    else:
        cv, (model, y0) = bending_row(n_rk, t_end, args.reps, "auto", "default")
    system = C.SemiDiscrete(model)
    rk_wall, rk_raw = C.timed(C.rk23, system, y0, C.outputs(horizon), 1e-6, 1)
    rk_row = dict(N=n_rk, rk23_horizon_s=horizon, rk23_wall_s=rk_wall,
                  rk23_wall_per_sim_s=rk_wall / horizon, rk23_steps=rk_raw.stats["steps"],
                  rk23_h_median_s=rk_raw.stats["h_median"],
                  cvode_wall_per_sim_s=cv["wall_per_sim_s"],
                  cvode_over_rk23_speedup=(rk_wall / horizon) / cv["wall_per_sim_s"])
    print(f"RK23 at N={n_rk}: {rk_row['rk23_wall_per_sim_s']:.2f} s per simulated s, "
          f"CVODE {rk_row['cvode_over_rk23_speedup']:.0f}x faster", flush=True)

    # 60 s: fetching (cables 2, 5, 11 pulled in turn and held), then holding.
    n_long = C.pick(args, 100, 100, 8)
    t_long = C.pick(args, 60.0, 60.0, 1.0)
    model = rodmol.scenarios.get("fetching").model(n_long)
    y0 = C.initial_state(model)
    C.warm_up(C.SemiDiscrete(model), y0)
    with C.Stopwatch() as sw:
        result = rodmol.simulate(model, t_long, initial=y0)
    long_row = dict(N=n_long, t_end_s=t_long, simulate_total_s=sw.seconds,
                    solver_s=result.stats["wall_time_s"], steps=result.stats["steps"],
                    h_max_s=result.stats["h_max"], max_quaternion_drift=float(result.quaternion_norm_error.max()),
                    final_quaternion_drift=float(result.quaternion_norm_error[-1]), success=result.success)
    print(f"{t_long:g} s fetching+hold at N={n_long}: simulate() {sw.seconds:.2f} s "
          f"(solver {long_row['solver_s']:.2f} s), drift {long_row['max_quaternion_drift']:.1e}", flush=True)

    start = cold_start(100) if args.mode != "smoke" else {}
    if start:
        print(f"JIT start-up (cold - warm): {start['jit_start_up_s']:.2f} s", flush=True)

    base = os.path.join(args.out, "scaling")
    C.write_csv(base + ".csv", rows, header + [f"bending test, rtol 1e-6, {t_end:g} s simulated, "
                                               f"median of {args.reps} runs, solver wall time"])
    C.write_csv(base + "_simulate.csv", totals, header)
    C.write_csv(base + "_extra.csv", [dict(kind="rk23", **rk_row)], header)
    C.write_csv(base + "_long.csv", [long_row], header)
    if start:
        C.write_csv(base + "_startup.csv", [start], header)

    fig, ax = plt.subplots(1, 2, figsize=(10, 4))
    for config, style, label in (("default", "o-", "CVODE, default (gmres from N = 50)"),
                                 ("band", "s--", "CVODE, band LU"), ("gmres", "d:", "CVODE, gmres")):
        sel = [r for r in rows if r["config"] == config]
        if sel:
            ax[0].loglog([r["N"] for r in sel], [r["wall_per_sim_s"] for r in sel], style, label=label)
    ax[0].loglog(ns, walls[0] / t_end * ns / ns[0], ":", color="grey", label="linear in N")
    ax[0].axhline(1 / 12, color="r", lw=0.8, ls="--", label="12x real time")
    ax[0].axhline(1 / 50, color="m", lw=0.8, ls="--", label="50x real time")
    ax[0].set_xlabel("elements N")
    ax[0].set_ylabel("wall time per simulated second [s]")
    ax[0].legend(fontsize=8)
    ax[0].set_title(f"bending test, rtol 1e-6 (fit: N^{slope:.2f})")
    sel = auto
    ax[1].loglog([r["N"] for r in sel], [r["h_median_s"] for r in sel], "o-", label="CVODE median step")
    ax[1].loglog([r["N"] for r in sel], [r["h_max_s"] for r in sel], "^:", label="CVODE largest step")
    ax[1].loglog([r["N"] for r in sel], [r["wave_limit_s"] for r in sel], "k--", label="ds / sqrt(E/rho)")
    ax[1].loglog([r["N"] for r in sel], [r["viscous_limit_s"] for r in sel], "k:", label="ds^2 / (3 mu/rho)")
    for a in ax:
        C.n_axis(a, ns)
    ax[1].set_xlabel("elements N")
    ax[1].set_ylabel("step [s]")
    ax[1].legend(fontsize=8)
    ax[1].set_title("steps taken vs explicit stability limits")
    C.save_figure(fig, base + ".png")

    fmt = {"wall_s": ".3f", "wall_per_sim_s": ".4f", "realtime_factor": ".1f", "h_min_s": ".2e",
           "h_median_s": ".2e", "h_max_s": ".2e", "wave_limit_s": ".2e", "viscous_limit_s": ".2e",
           "h_median_over_viscous": ".0f"}
    sections = [
        ("Bending test: wall time per simulated second",
         C.markdown_table(rows, ["N", "config", "linsolver", "wall_s", "wall_per_sim_s", "realtime_factor", "steps",
                                 "rhs_evals", "jac_evals", "prec_solves"], fmt)
         + f"\nFitted exponent of the default solver's wall time in N: **{slope:.2f}**; local: "
         + ", ".join(f"{r['N']}: {r['exponent']:.2f}" for r in local) + ".\n"),
        ("Steps taken against the explicit stability limits",
         C.markdown_table(auto, ["N", "h_min_s", "h_median_s", "h_max_s", "wave_limit_s", "viscous_limit_s",
                           "h_median_over_viscous"], fmt)),
        ("Whole rodmol.simulate call (solver + post-processing in rodmol.result)",
         C.markdown_table(totals, None, {"simulate_total_s": ".3f", "solver_s": ".3f",
                                         "post_processing_s": ".3f", "simulate_realtime_factor": ".1f"})),
        ("CVODE against RK23 (same right-hand side, same run)",
         C.markdown_table([rk_row], None, {"rk23_wall_s": ".3f", "rk23_wall_per_sim_s": ".3f",
                                           "rk23_h_median_s": ".2e", "cvode_wall_per_sim_s": ".4f",
                                           "cvode_over_rk23_speedup": ".0f"})),
        (f"{t_long:g} s fetching, then holding",
         C.markdown_table([long_row], None, {"simulate_total_s": ".2f", "solver_s": ".2f", "h_max_s": ".3f",
                                             "max_quaternion_drift": ".1e", "final_quaternion_drift": ".1e"})),
    ]
    if start:
        sections.append(("JIT start-up (fresh process, empty numba cache, minus a warm one)",
                         C.markdown_table([start], None, {k: ".2f" for k in start})))
    sections.append(("Figure", f"![scaling]({os.path.basename(base)}.png)\n"))
    C.write_markdown(base + ".md", "Scaling with N (bending test)", header, sections)
    print("wrote", base + ".{csv,md,png}")


if __name__ == "__main__":
    main()
