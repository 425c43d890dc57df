"""Work-precision: tip error against wall time for each backend and linear solver.

The bending test's first part (the pull ramps up and the arm swings) at a
fixed N, integrated at several tolerances by CVODE with each linear solver
option (preconditioned GMRES, band LU with SUNDIALS' or the compiled
Jacobian, LAPACK band, SuperLU_MT sparse with the compiled or scikit-sundae's
coloured Jacobian, dense where N is small enough) and by RK23. Error: the
largest distance of the time-integrated tip from a CVODE run at rtol 1e-10,
relative to L, over the 10 ms outputs. Wall time: the solver alone, median
of --reps runs.

    python solvers/work_precision.py [--quick | --smoke] [--out DIR] [--reps K]
"""

import os

import _common as C
from _common import np, plt, rodmol

SCRIPT = "work_precision.py"

CONFIGS = {
    "cvode gmres (default)": (C.cvode, dict(linsolver="gmres")),
    "cvode band, SUNDIALS J": (C.cvode, dict(linsolver="band", jacobian="sundials")),
    "cvode band, compiled J": (C.cvode, dict(linsolver="band", jacobian="compiled")),
    "cvode lapackband": (C.cvode, dict(linsolver="lapackband")),
    "cvode sparse, compiled J": (C.cvode, dict(linsolver="sparse", jacobian="compiled")),
    "cvode sparse, scikit-sundae J": (C.cvode, dict(linsolver="sparse", jacobian="sundials")),
    "cvode dense": (C.cvode, dict(linsolver="dense")),
    "rk23": (C.rk23, dict()),
}


def main(argv=None):
    args = C.parse_args(__doc__.splitlines()[0], argv)
    header = C.header_lines(args, SCRIPT)
    n = C.pick(args, 50, 25, 6)
    t_end = C.pick(args, 1.0, 0.5, 0.05)
    rtols = C.pick(args, [1e-4, 1e-5, 1e-6, 1e-7, 1e-8], [1e-4, 1e-6, 1e-8], [1e-4, 1e-6])
    rk_rtols = C.pick(args, [1e-4, 1e-6, 1e-8], [1e-4, 1e-6], [1e-4])
    dense_max_n = 25  # a dense LU of 19 N unknowns per Newton setup: only small N

    model = rodmol.scenarios.get("bending").model(n)
    system = C.SemiDiscrete(model)
    y0 = C.initial_state(model)
    t_out = C.outputs(t_end)
    L = model.rod.length
    ref = C.run(C.cvode, system, y0, t_out, 1e-10)
    skipped = []
    rows = []
    for name, (backend, opts) in CONFIGS.items():
        if name == "cvode dense" and n > dense_max_n:
            skipped.append(f"{name}: N = {n} > {dense_max_n} (O(N^3) per setup)")
            continue
        if backend is C.cvode:
            C.warm_up(system, y0, **opts)
        for rtol in (rk_rtols if name == "rk23" else rtols):
            wall, raw = C.timed(backend, system, y0, t_out, rtol, 1 if name == "rk23" else args.reps, **opts)
            err = np.linalg.norm(C.tip(raw) - C.tip(ref), axis=1).max() / L
            rows.append(dict(config=name, rtol=rtol, wall_s=wall, steps=raw.stats["steps"],
                             rhs_evals=raw.stats["rhs_evals"], jac_evals=raw.stats["jac_evals"],
                             tip_err_max=float(err), success=raw.success))
            print(f"{name:32s} rtol {rtol:.0e}: {wall:.3f} s, error {err:.1e}", flush=True)

    base = os.path.join(args.out, "work_precision")
    note = (f"bending test, N = {n}, first {t_end:g} s, errors relative to L against CVODE rtol 1e-10"
            + ("; skipped: " + "; ".join(skipped) if skipped else ""))
    C.write_csv(base + ".csv", rows, header + [note])

    fig, ax = plt.subplots(figsize=(7, 5))
    markers = "osd^v<>px"
    for i, name in enumerate(dict.fromkeys(r["config"] for r in rows)):
        sel = [r for r in rows if r["config"] == name]
        ax.loglog([r["wall_s"] for r in sel], [r["tip_err_max"] for r in sel], markers[i % 9] + "-",
                  label=name)
        for r in sel:
            ax.annotate(f"{r['rtol']:.0e}", (r["wall_s"], r["tip_err_max"]), fontsize=6)
    ax.set_xlabel("wall time [s]")
    ax.set_ylabel("max tip error / L")
    ax.set_title(f"work-precision, bending, N = {n}, {t_end:g} s")
    ax.legend(fontsize=7)
    C.save_figure(fig, base + ".png")

    # The same rows, with each configuration's time relative to the default at equal rtol.
    default = {r["rtol"]: r["wall_s"] for r in rows if r["config"] == "cvode gmres (default)"}
    for r in rows:
        r["time_vs_default"] = r["wall_s"] / default[r["rtol"]] if r["rtol"] in default else float("nan")
    fmt = {"wall_s": ".3f", "tip_err_max": ".1e", "rtol": ".0e", "time_vs_default": ".2f"}
    sections = [("Results", note + "\n\n" + C.markdown_table(
                    rows, ["config", "rtol", "wall_s", "time_vs_default", "steps", "rhs_evals", "jac_evals",
                           "tip_err_max", "success"], fmt)),
                ("Figure", f"![work-precision]({os.path.basename(base)}.png)\n")]
    C.write_markdown(base + ".md", "Work-precision by backend and linear solver", header, sections)
    print("wrote", base + ".{csv,md,png}")


if __name__ == "__main__":
    main()
