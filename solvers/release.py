"""Wall time per simulated second: the paper's arm in water released from straight.

The arm starts straight and at rest and falls under gravity and buoyancy
(the hardest start: every element moves at once). CVODE runs 2 s
(rtol 1e-6, output every 10 ms); RK23 runs a shorter horizon on the same
compiled right-hand side, since its step is held by the explicit limits.
Both are timed in the same run, solver only, median of --reps runs.

    python solvers/release.py [--quick | --smoke] [--out DIR] [--reps K]
"""


import _common as C
from _common import rodmol

SCRIPT = "release.py"


def main(argv=None):
    args = C.parse_args(__doc__.splitlines()[0], argv)
    header = C.header_lines(args, SCRIPT)
    sizes = C.pick(args, [25, 50, 100, 200], [25, 50, 100], [8, 16])
    t_cvode = C.pick(args, 2.0, 1.0, 0.05)
    rows = []
    for n in sizes:
        model = rodmol.paper_arm(n, medium="water")
        system = C.SemiDiscrete(model)
        y0 = rodmol.straight_state(model)
        C.warm_up(system, y0)
        wall_c, raw_c = C.timed(C.cvode, system, y0, C.outputs(t_cvode), 1e-6, args.reps)
        t_rk = C.pick(args, 0.2 if n <= 50 else 0.05, 0.05, 0.01)
        wall_r, raw_r = C.timed(C.rk23, system, y0, C.outputs(t_rk), 1e-6, args.reps)
        per_c, per_r = wall_c / t_cvode, wall_r / t_rk
        rows.append(dict(N=n, cvode_wall_per_sim_s=per_c, cvode_realtime_factor=1 / per_c,
                         cvode_steps=raw_c.stats["steps"], cvode_linear_solver=raw_c.stats["linear_solver"],
                         rk23_horizon_s=t_rk, rk23_wall_per_sim_s=per_r, rk23_steps=raw_r.stats["steps"],
                         cvode_speedup_over_rk23=per_r / per_c))
        print(f"N={n}: CVODE {per_c:.4f} s/s, RK23 {per_r:.3f} s/s ({per_r / per_c:.0f}x)", flush=True)
    C.write_results(args, "release", "Released from straight, in water", header, rows,
                    [("Wall time per simulated second (solver only)", C.markdown_table(rows))])


if __name__ == "__main__":
    main()
