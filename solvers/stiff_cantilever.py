"""Stiff, lightly damped rods: Till's steel cantilever, CVODE against generalized-alpha.

Till's example (JohnDTill/ContinuumRobotExamples, 02_Dynamics): E = 200 GPa,
G = 80 GPa, r = 1 mm, L = 0.5 m, rho = 8000 kg/m^3, N = 40, transverse
gravity, no fluid, released at t = 0+ from the static deflection under a
0.196 N transverse tip force, 25 s; Till's C++ (BDF-alpha, fixed 2 ms steps)
takes 0.73 s of CPU time. Each configuration runs through ``rodmol.simulate``
(released: the loaded model's equilibrium as ``initial=`` of the unloaded
one; or from straight), timed with ``time.process_time`` after a warm-up
(the equilibrium is computed outside the timing, as in Till's; median of
--reps runs). Reported:
steps, the first-mode period (mean spacing of the tip's crossings of its
mean over the first 2 s) and its error against Euler-Bernoulli, and the
tip's swing amplitude over the first and the last 0.5 s, and the share of the
swing's energy (total energy above the rest state's, ``rodmol.energy``) left
at the end: numerical damping, with mu = 0.

    python solvers/stiff_cantilever.py [--quick | --smoke] [--out DIR] [--reps K]
"""

import time

import _common as C
from _common import np, rodmol

SCRIPT = "stiff_cantilever.py"
L, RADIUS, E, G, RHO = 0.5, 1e-3, 200e9, 80e9, 8000.0
TIP_FORCE = 0.196  # N
TILL_CPU = 0.73  # s, Till's C++ on this machine class
#: First bending period of the Euler-Bernoulli cantilever [s] (0.1787 s).
PERIOD_EB = 2 * np.pi / (1.8751**2 * np.sqrt(E * RADIUS**2 / (4 * RHO)) / L**2)


def models(n, mu):
    rod = rodmol.Rod(L, RADIUS, rodmol.Material(E, G=G, mu=mu, rho=RHO))
    free = rodmol.Model(rod, n)  # gravity (0, -9.81, 0): transverse to the rod along x
    loaded = rodmol.Model(rod, n, loads=[rodmol.PointForce(L, (0.0, -TIP_FORCE, 0.0))])
    return free, loaded


def output_times(t_end):
    """Every 2 ms over the first 2 s and the last 0.5 s (period and amplitude), 10 ms between."""
    dense_start = np.arange(0.0, min(2.0, t_end), 2e-3)
    middle = np.arange(2.0, t_end - 0.5, 1e-2)
    dense_end = np.arange(max(t_end - 0.5, 0.0), t_end, 2e-3)
    return np.unique(np.concatenate([dense_start, middle, dense_end, [t_end]]))


def rest_energy(free):
    """Total energy [J] of the unloaded rod at rest in its gravity equilibrium."""
    rest = rodmol.simulate(free, 1e-6, initial="equilibrium", output_dt=1e-6)
    return float(rodmol.energy(free, rest)["total"][0])


def measure(free, y0, t_end, budget, backend, e_rest, reps, **options):
    times = output_times(t_end)
    rodmol.simulate(free, min(t_end, 0.02), initial=y0, backend=backend, **options)  # compile
    cpus = []
    for _ in range(reps):
        start = time.process_time()
        res = rodmol.simulate(free, t_end, initial=y0, backend=backend, output_times=times,
                              max_wall_time=budget, **options)
        cpus.append(time.process_time() - start)
    cpu = float(np.median(cpus))
    tip = res.tip[:, 1]
    early, late = res.t <= min(2.0, t_end), res.t >= res.t[-1] - 0.5
    try:
        period = rodmol.oscillation_period(res.t[early], tip[early])
    except rodmol.ParameterError:  # a run that stopped before two swings
        period = float("nan")
    energy = rodmol.energy(free, res)["total"]
    return dict(success=res.success, t_reached=float(res.t[-1]), cpu_s=cpu,
                cpu_over_till=cpu / TILL_CPU * 25.0 / t_end, steps=res.stats.get("steps"),
                rhs_evals=res.stats.get("rhs_evals"), jac_evals=res.stats.get("jac_evals"),
                newton_iters=res.stats.get("newton_iters", ""), period_s=period,
                period_error_pct=float(100 * (period / PERIOD_EB - 1)),
                amplitude_start_mm=float(1e3 * np.ptp(tip[res.t <= 0.5]) / 2),
                amplitude_end_mm=float(1e3 * np.ptp(tip[late]) / 2),
                swing_energy_kept_pct=float(100 * (energy[-1] - e_rest) / (energy[0] - e_rest)))


def configurations(args):
    """(label, backend, options) of the runs; CVODE's order 5 gets a wall budget."""
    cvode = [("cvode BDF<=2 (auto) rtol 3e-5", "cvode", {}),
             ("cvode BDF<=2 rtol 1e-4", "cvode", dict(rtol=1e-4)),
             ("cvode BDF<=2 rtol 1e-5", "cvode", dict(rtol=1e-5)),
             ("cvode BDF<=5 rtol 3e-5", "cvode", dict(max_order=5))]
    galpha = [(f"galpha dt {dt * 1e3:g} ms rho_inf {rho:g}", "galpha", dict(dt=dt, rho_inf=rho))
              for dt in (2e-3, 1e-3) for rho in (1.0, 0.9, 0.5, 0.0)]
    if args.mode == "smoke":
        return cvode[:1] + galpha[:2]
    return cvode + galpha


def main(argv=None):
    args = C.parse_args(__doc__.splitlines()[0], argv)
    header = C.header_lines(args, SCRIPT)
    n = C.pick(args, 40, 40, 10)
    t_end = C.pick(args, 25.0, 5.0, 0.3)
    budget = C.pick(args, 60.0, 10.0, 5.0)
    rows = []
    for mu, start in ((0.0, "released"), (10.0, "released"), (10.0, "straight")):
        if args.mode == "smoke" and mu > 0:
            continue
        free, loaded = models(n, mu)
        y0 = rodmol.equilibrium(loaded) if start == "released" else rodmol.straight_state(free)
        e_rest = rest_energy(free)
        for label, backend, options in configurations(args):
            if start == "straight" and "rho_inf 0.9" not in label and "auto" not in label:
                continue  # from straight: the default of each backend only
            row = dict(mu_Pa_s=mu, start=start, configuration=label)
            row.update(measure(free, y0, t_end, budget, backend, e_rest, args.reps, **options))
            rows.append(row)
            print({k: (round(v, 5) if isinstance(v, float) else v) for k, v in row.items()}, flush=True)

    formats = dict(cpu_s=".3f", cpu_over_till=".2f", period_s=".5f", period_error_pct=".3f",
                   amplitude_start_mm=".2f", amplitude_end_mm=".2f", t_reached=".4g",
                   swing_energy_kept_pct=".2f")
    columns = ["mu_Pa_s", "start", "configuration", "success", "t_reached", "cpu_s", "cpu_over_till",
               "steps", "period_s", "period_error_pct", "amplitude_start_mm", "amplitude_end_mm",
               "swing_energy_kept_pct"]
    C.write_results(args, "stiff_cantilever", "Steel cantilever, stiff and lightly damped", header, rows, [
        (f"N = {n}, {t_end:g} s; Euler-Bernoulli period {PERIOD_EB:.5f} s; Till's C++ "
         f"{TILL_CPU} s CPU for 25 s (cpu_over_till scales to 25 s)",
         C.markdown_table(rows, columns, formats))])


if __name__ == "__main__":
    main()
