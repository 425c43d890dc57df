"""Spatial convergence of the equilibrium and of the tip trajectory, against Richardson extrapolation.

For each scheme (the paper's upwind one and the centred one), N doubles from
25 to 1600 (--quick: to 400). For each N:

* the static equilibrium under gravity and buoyancy (the paper's initial
  state): the tip position u(L);
* the bending test from that equilibrium, CVODE at rtol 1e-8 (so that the
  time error is far below the space error): the tip rebuilt from the strains
  (``Result.tip``) at the 10 ms outputs.

The limit N -> infinity is estimated by Richardson extrapolation from the
two finest grids, with the order observed on the three finest; errors are
distances to that limit relative to L (the trajectory's: largest over time),
and the observed order between successive grids is log2(e(N) / e(2N)).

    python solvers/convergence.py [--quick | --smoke] [--out DIR]
"""

import os

import _common as C
from _common import np, plt, rodmol

SCRIPT = "convergence.py"


def observed_orders(values):
    """log2 of successive differences' ratios: |v_N - v_2N| / |v_2N - v_4N|."""
    d = [float(np.max(np.linalg.norm(np.atleast_2d(b - a), axis=-1))) for a, b in zip(values, values[1:])]
    return [float(np.log2(d0 / d1)) if d1 > 0 else float("nan") for d0, d1 in zip(d, d[1:])]


def richardson(values):
    """Limit from the two finest values, with the order of the three finest."""
    p = observed_orders(values[-3:])[0]
    fine, coarse = values[-1], values[-2]
    return fine + (fine - coarse) / (2.0**p - 1.0), p


def main(argv=None):
    args = C.parse_args(__doc__.splitlines()[0], argv)
    header = C.header_lines(args, SCRIPT)
    sizes = C.pick(args, [25, 50, 100, 200, 400, 800, 1600], [25, 50, 100, 200, 400], [8, 16, 32, 64])
    t_end = C.pick(args, 6.0, 2.0, 0.1)
    rtol = 1e-8
    scenario = rodmol.scenarios.get("bending")
    L = scenario.model(sizes[0]).rod.length

    rows, summary = [], {}
    for scheme in rodmol.SCHEMES:
        eq_tips, trajectories, scheme_rows = [], [], []
        for n in sizes:
            model = scenario.model(n)
            system = C.SemiDiscrete(model, scheme)
            with C.Stopwatch() as sw_eq:
                y0 = C.initial_state(model, system=system)
            C.warm_up(system, y0)
            with C.Stopwatch() as sw_dyn:
                raw = C.run(C.cvode, system, y0, C.outputs(t_end), rtol)
            # At rest the integrated tip position u(L) is the rebuilt one.
            eq_tips.append(y0[system.layout.tip_slice("u")].copy())
            trajectories.append(C.tip(raw, model).copy())
            scheme_rows.append(dict(scheme=scheme, N=n, ds_m=model.ds, equilibrium_s=sw_eq.seconds,
                                    dynamics_s=sw_dyn.seconds, steps=raw.stats["steps"],
                                    success=raw.success))
            print(f"{scheme} N={n}: equilibrium {sw_eq.seconds:.2f} s, {t_end:g} s of dynamics "
                  f"{sw_dyn.seconds:.2f} s", flush=True)
        eq_limit, eq_p = richardson(eq_tips)
        tr_limit, tr_p = richardson(trajectories)
        eq_orders, tr_orders = observed_orders(eq_tips), observed_orders(trajectories)
        for i, row in enumerate(scheme_rows):
            row["equilibrium_tip_error"] = float(np.linalg.norm(eq_tips[i] - eq_limit) / L)
            row["trajectory_tip_error"] = float(np.max(np.linalg.norm(trajectories[i] - tr_limit, axis=1)) / L)
            row["equilibrium_order"] = eq_orders[i] if i < len(eq_orders) else float("nan")
            row["trajectory_order"] = tr_orders[i] if i < len(tr_orders) else float("nan")
        rows += scheme_rows
        summary[scheme] = (eq_p, tr_p, eq_orders, tr_orders)

    base = os.path.join(args.out, "convergence")
    note = (f"bending test; trajectory over {t_end:g} s at rtol {rtol:g}; per scheme, Richardson limit "
            f"from N = {sizes[-2]}, {sizes[-1]} with the order observed on the three finest grids; "
            "errors relative to L; 'order' at N is log2 of the ratio of the differences N -> 2N and 2N -> 4N")
    C.write_csv(base + ".csv", rows, header + [note])

    fig, ax = plt.subplots(figsize=(6.5, 4.5))
    ns = np.array(sizes[:-1], float)  # the finest grid defines the limit: its error is not independent
    for scheme, color in zip(rodmol.SCHEMES, ("C0", "C3")):
        sel = [r for r in rows if r["scheme"] == scheme][:-1]
        ax.loglog(ns, [r["equilibrium_tip_error"] for r in sel], "o-", color=color,
                  label=f"{scheme}: equilibrium tip")
        ax.loglog(ns, [r["trajectory_tip_error"] for r in sel], "s--", color=color,
                  label=f"{scheme}: tip trajectory (max over t)")
    first = rows[0]["trajectory_tip_error"]
    ax.loglog(ns, first * ns[0] / ns, ":", color="grey", label="O(1/N)")
    ax.loglog(ns, first * (ns[0] / ns) ** 2, "-.", color="grey", label="O(1/N^2)")
    C.n_axis(ax, ns)
    ax.set_xlabel("elements N")
    ax.set_ylabel("error / L (vs Richardson limit)")
    ax.set_title("spatial convergence, bending test")
    ax.legend(fontsize=7)
    C.save_figure(fig, base + ".png")

    fmt = {"ds_m": ".2e", "equilibrium_s": ".2f", "dynamics_s": ".2f", "equilibrium_tip_error": ".2e",
           "trajectory_tip_error": ".2e", "equilibrium_order": ".3f", "trajectory_order": ".3f"}
    orders = "".join(
        f"- {scheme}: equilibrium {', '.join(f'{p:.3f}' for p in eq_o)}; trajectory "
        f"{', '.join(f'{p:.3f}' for p in tr_o)} (coarse to fine)\n"
        for scheme, (_, _, eq_o, tr_o) in summary.items())
    sections = [
        ("Results", note + "\n\n" + C.markdown_table(rows, None, fmt)),
        ("Observed order", orders + "\nThe paper's upwind scheme is first order in ds, the centred "
                           "scheme second order (docs/model.md).\n"),
        ("Figure", f"![convergence]({os.path.basename(base)}.png)\n"),
    ]
    C.write_markdown(base + ".md", "Spatial convergence", header, sections)
    print("wrote", base + ".{csv,md,png}")


if __name__ == "__main__":
    main()
