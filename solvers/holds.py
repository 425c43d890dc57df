"""Held points (rodmol.Hold): the penalty joint's drift and cost against its stiffness.

Two rods held at both ends (base clamped, tip pinned where it is at rest):
a stiff propped cantilever under its weight (L = 0.5 m, r = 1 cm,
E = 1 GPa, mu = 1 kPa s, in air; released straight), and the paper's arm
in water with its tip pinned while cable 11 pulls (the "bending" tensions,
ramped to 2 N), at N = 40 (CVODE's band solver) and N = 100 (GMRES with the
block preconditioner). For penalty stiffnesses k = factor E A / ds (critical
damping 2 sqrt(k m), m = rho A ds, as the default), each run goes through
``rodmol.simulate`` (CVODE, default tolerances) from its start, and the
table gives: the pin's drift |u - p| (max over the run, and at rest from
``rodmol.equilibrium`` under the full loads) relative to L; the static
error it makes, the rest tip reaction against that of a pin of factor 1e4
(the stiffest whose equilibrium still converges to the usual residual:
the round-off floor of the residual grows with k); CVODE's steps, right-hand
sides, the solver's wall time and the whole call's (with the initial
equilibrium and the Result), each as a ratio to the same rod with its tip
free (measured in the same run, median of --reps). The default
(``rodmol.holds.default_stiffness``: factor HOLD_STIFFNESS_FACTOR L / ds,
4000 at N = 40) is added and marked.

    python solvers/holds.py [--quick | --smoke] [--out DIR] [--reps K]
"""

import time

import _common as C
from _common import np, rodmol

from rodmol.discretise import load_entries
from rodmol.holds import HOLD_STIFFNESS_FACTOR

SCRIPT = "holds.py"


def beam(n, hold):
    rod = rodmol.Rod(0.5, 0.01, rodmol.Material(E=1e9, nu=0.5, mu=1e3, rho=1000.0))
    return rodmol.Model(rod, n, gravity=(0.0, 0.0, -9.81), medium=rodmol.MEDIA["air"],
                        loads=[hold] if hold else [])


def arm(n, hold):
    tension = [(0.0, 0.0), (0.5, 2.0)]
    return rodmol.paper_arm(n, tensions={11: tension}, loads=[hold] if hold else [])


PROBLEMS = {  # name: (model(n, hold), start, t_end per mode, time of the full loads, N per mode)
    "propped cantilever": (beam, "straight", (0.1, 0.05, 0.01), 0.0, (40, 20, 10)),
    "paper arm, tip pinned": (arm, "equilibrium", (1.0, 0.5, 0.05), 0.5, (40, 20, 10)),
    # N = 100: CVODE's GMRES with the block preconditioner (the band solver below N = 50)
    "paper arm, tip pinned, N = 100": (arm, "equilibrium", (1.0, 0.5, 0.05), 0.5, (100, 60, 10)),
}
REFERENCE_FACTOR = 1e4


def hold_for(model, factor):
    """A pin at the tip with stiffness factor E A / ds and critical damping."""
    rest = load_entries.rest_nodes(model)
    k = factor * rest["axial_stiffness"][-1]
    return rodmol.Hold(model.rod.length, stiffness=k, damping=2.0 * np.sqrt(k * rest["mass"][-1]))


def tip_reaction(model, y):
    """The pin's force [N] on the rod at rest in y, global."""
    grid = load_entries.of_model(model)
    u = rodmol.StateLayout(model.n_elements).field(y, "u")[-1]
    return -grid.params[0, 7] * (u - grid.params[0, :3] - grid.initial[0])


def timed(model, start, t_end, reps):
    """The last run and the median wall times [s] of the whole call and of the solver alone."""
    walls, solver = [], []
    for _ in range(reps):
        begin = time.perf_counter()
        res = rodmol.simulate(model, t_end, initial=start, output_dt=t_end / 50)
        walls.append(time.perf_counter() - begin)
        solver.append(res.stats["wall_time_s"])
    return res, float(np.median(walls)), float(np.median(solver))


def main(argv=None):
    args = C.parse_args(__doc__.splitlines()[0], argv)
    header = C.header_lines(args, SCRIPT)
    factors = C.pick(args, (1.0, 10.0, 100.0, 1e3, 1e4, 1e5), (1.0, 100.0, 1e4), (10.0, 100.0))
    rows = []
    for name, (build, start, t_ends, loaded, sizes) in PROBLEMS.items():
        t_end, n = C.pick(args, *t_ends), C.pick(args, *sizes)
        free = build(n, None)
        rodmol.simulate(free, t_end / 10, initial=start)  # compile, warm
        res_free, wall_free, solver_free = timed(free, start, t_end, args.reps)
        stiff = build(n, hold_for(free, REFERENCE_FACTOR))
        reference = tip_reaction(stiff, rodmol.equilibrium(stiff, loaded))
        default = HOLD_STIFFNESS_FACTOR * free.rod.length / free.ds
        for factor in sorted({*factors, default}):
            model = build(n, hold_for(free, factor))
            rest = rodmol.equilibrium(model, loaded)
            held = model.loads[-1]
            p = load_entries.rest_nodes(model)["u"][-1]
            res, wall, solver = timed(model, start, t_end, args.reps)
            drift = np.linalg.norm(res.integrated_positions[:, -1] - p, axis=1)
            length = model.rod.length
            rows.append(dict(
                problem=name, N=n, factor=factor, default=factor == default,
                stiffness_N_per_m=held.stiffness, success=res.success,
                rest_drift_over_L=float(np.linalg.norm(rodmol.StateLayout(n).field(rest, "u")[-1] - p) / length),
                max_drift_over_L=float(np.max(drift) / length),
                reaction_error=float(np.linalg.norm(tip_reaction(model, rest) - reference)
                                     / np.linalg.norm(reference)),
                linear_solver=res.stats["linear_solver"], steps=res.stats["steps"], steps_over_free=res.stats["steps"] / res_free.stats["steps"],
                rhs_over_free=res.stats["rhs_evals"] / res_free.stats["rhs_evals"],
                solver_s=solver, solver_over_free=solver / solver_free, wall_s=wall,
                wall_over_free=wall / wall_free, h_min_s=res.stats["h_min"]))
            print({k: (f"{v:.4g}" if isinstance(v, float) else v) for k, v in rows[-1].items()}, flush=True)

    formats = dict(factor="g", stiffness_N_per_m=".3g", rest_drift_over_L=".2e", max_drift_over_L=".2e",
                   reaction_error=".2e", steps_over_free=".2f", rhs_over_free=".2f", solver_s=".3f",
                   solver_over_free=".2f", wall_s=".3f",
                   wall_over_free=".2f", h_min_s=".2e")
    columns = ["problem", "N", "factor", "default", "stiffness_N_per_m", "success", "rest_drift_over_L",
               "max_drift_over_L", "reaction_error", "linear_solver", "steps", "steps_over_free", "rhs_over_free", "solver_s", "solver_over_free", "wall_s",
               "wall_over_free", "h_min_s"]
    C.write_results(args, "holds", "Held points: drift and cost against the penalty stiffness", header, rows, [
        ("k = factor E A / ds, critical damping; ratios to the same rod with a free tip, same run; "
         f"reaction_error against the pin of factor {REFERENCE_FACTOR:g}",
         C.markdown_table(rows, columns, formats))])


if __name__ == "__main__":
    main()
