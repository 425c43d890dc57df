"""Work-precision of the two spatial schemes on the paper's three tests.

For each test (bending, reaching, fetching) a reference tip trajectory is
extrapolated (Richardson, order 2) from the centred scheme at the two finest
grids, integrated at rtol 1e-9. Then each scheme runs over a grid of N and
rtol; for each run: the largest distance of the tip (rebuilt from the strains,
``Result.tip``) from the reference over the 10 ms outputs, and the solver's
wall time per simulated second (its inverse is the real-time factor). Both
are measured in this one run, with the default CVODE options.

The summary picks, for each scheme and target error, the cheapest (N, rtol)
that reaches it, and lists the defaults' own error and speed.

    python solvers/schemes.py [--quick | --smoke] [--out DIR] [--reps K]
"""

import os

import _common as C
from _common import np, plt, rodmol

from rodmol.discretise.schemes import SCHEMES

SCRIPT = "schemes.py"
TARGETS_MM = (10.0, 3.0, 1.0, 0.3, 0.1)


def trajectory(scenario, n, scheme, rtol, t_out, reps=1):
    model = scenario.model(n)
    system = C.SemiDiscrete(model, scheme)
    y0 = C.initial_state(model, system=system)
    C.warm_up(system, y0)
    wall, raw = C.timed(C.cvode, system, y0, t_out, rtol, reps)
    return C.tip(raw, model), wall, raw


def reference(scenario, sizes, t_out):
    """Richardson limit (order 2) of the centred scheme's two finest grids."""
    coarse, fine = (trajectory(scenario, n, "centred", 1e-9, t_out)[0] for n in sizes)
    return fine + (fine - coarse) / 3.0, float(np.max(np.linalg.norm(fine - coarse, axis=1)) / 3.0)


def cheapest(rows, scheme, test, target_m):
    ok = [r for r in rows if r["scheme"] == scheme and r["test"] == test and r["tip_err_mm"] * 1e-3 <= target_m]
    return min(ok, key=lambda r: r["wall_per_s"]) if ok else None


def main(argv=None):
    args = C.parse_args(__doc__.splitlines()[0], argv)
    header = C.header_lines(args, SCRIPT)
    tests = C.pick(args, ["bending", "reaching", "fetching"], ["bending", "fetching"], ["bending"])
    sizes = {"centred": C.pick(args, [25, 50, 100, 200], [25, 50, 100], [6, 12]),
             "upwind": C.pick(args, [50, 100, 200, 400, 800, 1600], [50, 100, 400], [6, 12])}
    ref_sizes = C.pick(args, (400, 800), (200, 400), (24, 48))
    rtols = C.pick(args, [1e-3, 1e-4, 3e-5, 1e-5, 1e-6], [1e-3, 1e-4, 3e-5, 1e-5], [1e-4])
    t_cut = C.pick(args, None, None, 0.2)

    rows, notes = [], []
    for test in tests:
        scenario = rodmol.scenarios.get(test)
        t_end = t_cut or scenario.t_end
        t_out = C.outputs(t_end)
        ref, ref_err = reference(scenario, ref_sizes, t_out)
        notes.append(f"{test}: {t_end:g} s, reference from centred N = {ref_sizes}, its own error "
                     f"~{ref_err * 1e3:.1e} mm")
        print(notes[-1], flush=True)
        for scheme in SCHEMES:
            for n in sizes[scheme]:
                for rtol in rtols:
                    tip, wall, raw = trajectory(scenario, n, scheme, rtol, t_out, args.reps)
                    err = float(np.max(np.linalg.norm(tip - ref, axis=1)))
                    rows.append(dict(test=test, scheme=scheme, N=n, rtol=rtol, tip_err_mm=err * 1e3,
                                     wall_per_s=wall / t_end, realtime=t_end / wall,
                                     steps=raw.stats["steps"], success=raw.success))
                    print(f"  {scheme:8s} N={n:5d} rtol {rtol:.0e}: error {err * 1e3:8.3f} mm, "
                          f"{t_end / wall:6.1f}x real time, {raw.stats['steps']} steps", flush=True)

    summary = []
    for test in tests:
        for target in TARGETS_MM:
            for scheme in SCHEMES:
                best = cheapest(rows, scheme, test, target * 1e-3)
                summary.append(dict(test=test, target_mm=target, scheme=scheme,
                                    N=best["N"] if best else "-", rtol=best["rtol"] if best else "-",
                                    tip_err_mm=best["tip_err_mm"] if best else float("nan"),
                                    realtime=best["realtime"] if best else float("nan")))

    base = os.path.join(args.out, "schemes")
    C.write_csv(base + ".csv", rows, header + notes)
    fig, axes = plt.subplots(1, len(tests), figsize=(5.5 * len(tests), 4.5), squeeze=False)
    for ax, test in zip(axes[0], tests):
        for scheme, marker in zip(SCHEMES, "os"):
            for n in sizes[scheme]:
                sel = [r for r in rows if r["test"] == test and r["scheme"] == scheme and r["N"] == n]
                ax.loglog([r["wall_per_s"] for r in sel], [r["tip_err_mm"] for r in sel], marker + "-",
                          color="C0" if scheme == "centred" else "C3", alpha=0.35 + 0.65 * n / max(sizes[scheme]),
                          label=f"{scheme} N={n}")
        ax.set_xlabel("wall time per simulated second [s]")
        ax.set_ylabel("max tip error [mm]")
        ax.set_title(test)
        ax.legend(fontsize=6, ncol=2)
    C.save_figure(fig, base + ".png")

    fmt = {"tip_err_mm": ".3g", "wall_per_s": ".4f", "realtime": ".1f", "rtol": ".0e"}
    sections = [
        ("Cheapest run per target error", "; ".join(notes) + "\n\n" + C.markdown_table(
            summary, ["test", "target_mm", "scheme", "N", "rtol", "tip_err_mm", "realtime"], fmt)),
        ("All runs", C.markdown_table(rows, ["test", "scheme", "N", "rtol", "tip_err_mm", "wall_per_s",
                                             "realtime", "steps", "success"], fmt)),
        ("Figure", f"![work-precision of the schemes]({os.path.basename(base)}.png)\n"),
    ]
    C.write_markdown(base + ".md", "Work-precision of the spatial schemes", header, sections)
    print("wrote", base + ".{csv,md,png}")


if __name__ == "__main__":
    main()
