"""Time-integration accuracy: CVODE's rtol sweep, CVODE against RK23, and the solver options.

1. rtol sweep on the bending test at fixed N: tip error (time-integrated
   u(L), relative to L, max and mean over the 10 ms outputs) against a
   CVODE run at rtol 1e-10, with wall time, steps and evaluations.
2. CVODE against RK23 on a common (short) horizon, both at rtol 1e-6, each
   against the same reference.
3. CVODE options at rtol 1e-6 (BDF order cap, Newton iterations, a looser
   angular-velocity tolerance): speed and tip error on the bending test, and
   the largest step-to-step increase of kinetic + strain energy of an
   inviscid swing in water (drag only removes energy, so any increase is
   integration error).

    python solvers/temporal.py [--quick | --smoke] [--out DIR] [--reps K]
"""

import os

import _common as C
from _common import np, plt, rodmol

from rodmol.discretise.layout import StateLayout

SCRIPT = "temporal.py"


def tip_errors(raw, ref, length):
    n = min(len(raw.t), len(ref.t))
    e = np.linalg.norm(C.tip(raw)[:n] - C.tip(ref)[:n], axis=1) / length
    return float(e.max()), float(e.mean())


def loose_w_atol(model, rtol):
    """default_atol with the angular-velocity scale (L/s)/r_min instead of 1 rad/s."""
    atol = C.default_atol(model, rtol)
    r_min = float(np.min(model.rod.radius_at(model.s_nodes)))
    StateLayout(model.n_elements).field(atol, "w")[...] = rtol * model.rod.length / r_min
    return atol


def swing(n, t_end):
    """Inviscid swing in water, drag on, no gravity, from rest bent by a uniform
    transverse load (tip deflection ~0.16 of 0.2 m; the setup of the energy
    test in tests/test_cables.py)."""
    rod = rodmol.Rod(0.2, 0.01, rodmol.Material(E=110e3, nu=0.5, mu=0.0, rho=1080.0))
    y0 = rodmol.equilibrium(rodmol.Model(rod, n, gravity=(0.0, -6.0, 0.0)))
    free = rodmol.Model(rod, n, gravity=(0.0, 0.0, 0.0), medium="water", viscosity=False)
    return free, y0, C.outputs(t_end)


def main(argv=None):
    args = C.parse_args(__doc__.splitlines()[0], argv)
    header = C.header_lines(args, SCRIPT)
    n = C.pick(args, 100, 50, 8)
    t_end = C.pick(args, 6.0, 2.0, 0.2)
    rtols = C.pick(args, [1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8], [1e-4, 1e-5, 1e-6, 1e-7, 1e-8], [1e-4, 1e-6])

    model = rodmol.scenarios.get("bending").model(n)
    system = C.SemiDiscrete(model)
    y0 = C.initial_state(model)
    t_out = C.outputs(t_end)
    L = model.rod.length
    C.warm_up(system, y0)
    ref = C.run(C.cvode, system, y0, t_out, 1e-10)

    sweep = []
    for rtol in rtols:
        wall, raw = C.timed(C.cvode, system, y0, t_out, rtol, args.reps)
        emax, emean = tip_errors(raw, ref, L)
        sweep.append(dict(rtol=rtol, wall_s=wall, wall_per_sim_s=wall / t_end, steps=raw.stats["steps"],
                          rhs_evals=raw.stats["rhs_evals"], jac_evals=raw.stats["jac_evals"],
                          tip_err_max=emax, tip_err_mean=emean))
        print(f"rtol {rtol:.0e}: {wall:.3f} s, {raw.stats['steps']} steps, tip error {emax:.2e} L", flush=True)

    # CVODE against RK23 on a common horizon.
    horizon = C.pick(args, 0.5, 0.2, 0.01)
    t_short = C.outputs(horizon)
    ref_short = C.run(C.cvode, system, y0, t_short, 1e-10)
    duel = []
    for name, backend in (("cvode", C.cvode), ("rk23", C.rk23)):
        wall, raw = C.timed(backend, system, y0, t_short, 1e-6, 1 if name == "rk23" else args.reps)
        emax, emean = tip_errors(raw, ref_short, L)
        duel.append(dict(backend=name, horizon_s=horizon, wall_s=wall, wall_per_sim_s=wall / horizon,
                         steps=raw.stats["steps"], rhs_evals=raw.stats["rhs_evals"],
                         h_median_s=raw.stats["h_median"], tip_err_max=emax, tip_err_mean=emean))
    duel[1]["speedup_of_cvode"] = duel[1]["wall_s"] / duel[0]["wall_s"]
    duel[0]["speedup_of_cvode"] = 1.0
    d_rk = np.max(np.linalg.norm(C.tip(C.run(C.rk23, system, y0, t_short, 1e-6))
                                 - C.tip(C.run(C.cvode, system, y0, t_short, 1e-6)), axis=1)) / L
    print(f"RK23 vs CVODE over {horizon:g} s: CVODE {duel[1]['speedup_of_cvode']:.0f}x faster, "
          f"tips differ by {d_rk:.1e} L", flush=True)

    # Options.
    options = {
        "defaults (order 5, 3 Newton its)": dict(),
        "max_order=4": dict(max_order=4),
        "max_order=3": dict(max_order=3),
        "max_nonlin_iters=5": dict(max_nonlin_iters=5),
        "max_order=4, max_nonlin_iters=5": dict(max_order=4, max_nonlin_iters=5),
        "w atol scale (L/s)/r_min": dict(atol="loose-w"),
    }
    sw_n, sw_t = C.pick(args, 16, 16, 6), C.pick(args, 4.0, 2.0, 0.3)
    free, sy0, st_out = swing(sw_n, sw_t)
    fsystem = C.SemiDiscrete(free)
    opt_rows = []
    for label, opts in options.items():
        rtol = 1e-6
        o = dict(opts)
        if o.get("atol") == "loose-w":
            o["atol"] = loose_w_atol(model, rtol)
        wall, raw = C.timed(C.cvode, system, y0, t_out, rtol, args.reps, **o)
        emax, emean = tip_errors(raw, ref, L)
        # The swing, at the rtol of the energy test in tests/test_cables.py.
        o2 = dict(opts)
        if o2.get("atol") == "loose-w":
            o2["atol"] = loose_w_atol(free, 1e-5)
        sraw = C.run(C.cvode, fsystem, sy0, st_out, 1e-5, **o2)
        res = rodmol.result.from_states(fsystem, sraw.t, sraw.y, sraw.success, sraw.message, sraw.stats)
        e = rodmol.energy(free, res)
        mech = e["kinetic"] + e["strain"]
        opt_rows.append(dict(option=label, wall_s=wall, steps=raw.stats["steps"], rhs_evals=raw.stats["rhs_evals"],
                             tip_err_max=emax, tip_err_mean=emean, swing_steps=sraw.stats["steps"],
                             swing_max_energy_rise=float(np.max(np.diff(mech)) / mech[0])))
        print(f"{label}: {wall:.3f} s, tip error {emax:.1e}, swing energy rise "
              f"{opt_rows[-1]['swing_max_energy_rise']:.1e}", flush=True)

    base = os.path.join(args.out, "temporal")
    note = f"bending test, N = {n}, {t_end:g} s, reference CVODE rtol 1e-10; errors relative to L"
    C.write_csv(base + ".csv", sweep, header + [note])
    C.write_csv(base + "_rk23.csv", duel, header)
    C.write_csv(base + "_options.csv", opt_rows, header)

    fig, ax = plt.subplots(1, 2, figsize=(10, 4))
    r = np.array([s["rtol"] for s in sweep])
    ax[0].loglog(r, [s["tip_err_max"] for s in sweep], "o-", label="max over time")
    ax[0].loglog(r, [s["tip_err_mean"] for s in sweep], "s--", label="mean over time")
    ax[0].loglog(r, r, ":", color="grey", label="error = rtol")
    ax[0].set_xlabel("rtol")
    ax[0].set_ylabel("tip error / L")
    ax[0].legend(fontsize=8)
    ax[0].set_title(f"CVODE, bending, N = {n}")
    ax[1].semilogx(r, [s["wall_per_sim_s"] for s in sweep], "o-")
    ax[1].set_xlabel("rtol")
    ax[1].set_ylabel("wall time per simulated second [s]")
    ax[1].set_title("cost of accuracy")
    C.save_figure(fig, base + ".png")

    fmt = {"wall_s": ".3f", "wall_per_sim_s": ".4f", "tip_err_max": ".2e", "tip_err_mean": ".2e",
           "rtol": ".0e", "h_median_s": ".2e", "speedup_of_cvode": ".0f", "swing_max_energy_rise": ".1e"}
    sections = [
        ("rtol sweep", note + "\n\n" + C.markdown_table(sweep, None, fmt)),
        ("CVODE against RK23 (same right-hand side)",
         C.markdown_table(duel, None, fmt)
         + f"\nThe two solutions differ by {d_rk:.1e} L at most over the horizon.\n"),
        ("CVODE options at rtol 1e-6",
         "Bending test as above; the swing is an inviscid rod in water with drag (energy can only "
         f"fall), N = {sw_n}, {sw_t:g} s, rtol 1e-5; its column is the largest rise of kinetic + "
         "strain energy between outputs, relative to the initial energy.\n\n"
         + C.markdown_table(opt_rows, None, fmt)),
        ("Figure", f"![temporal]({os.path.basename(base)}.png)\n"),
    ]
    C.write_markdown(base + ".md", "Time integration: tolerances, RK23, options", header, sections)
    print("wrote", base + ".{csv,md,png}")


if __name__ == "__main__":
    main()
