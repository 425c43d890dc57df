"""Inverse statics on the paper's arm: accuracy and the cost of a path of targets.

One target, sought from slack cables with bounds (0, 5) N: the tip of the
arm with cables 11 and 12 pulled (1.0, 0.5 N) with those two cables; the tip
and tip tangent of the arm with cables 11, 12 and 3 pulled (1.0, 0.5, 0.4 N)
with cables 11, 12, 3 and 7; the latter's tip with all twelve cables.
Reported: the residual, the largest error of the actuated cables' tensions
(unique in the first two cases), the steps, equilibria and wall time. A
path: 20 targets, the tips of a tension ramp (cable 11 from 0.9 to 1.1 N,
cable 12 from 0.6 to 0.5 N; 5 in the smoke run), a few mm apart, sought in turn with the four tip-section cables 9-12
(``rodmol.inverse_statics_path``, each warm-started from the last); its wall
time per target is compared with one forward equilibrium from the straight
rod (``rodmol.equilibrium``, the same targets' own, timed in the same run).

    python solvers/inverse_statics.py [--quick | --smoke] [--out DIR]
"""

import time

import _common as C
from _common import np, rodmol

SCRIPT = "inverse_statics.py"
PULLED = {11: 1.0, 12: 0.5, 3: 0.4}


def tip_of(model, y):
    return rodmol.SemiDiscrete(model).state_view(0.0, y).tip


def one_target(n):
    arm = rodmol.paper_arm(n)
    cases = (("tip, cables 11 and 12", {11: 1.0, 12: 0.5}, [11, 12], False),
             ("tip and tangent, cables 11, 12, 3, 7", PULLED, [11, 12, 3, 7], True),
             ("tip, all 12 cables", PULLED, None, False))
    rows = []
    for label, pulled, cables, tangent in cases:
        loaded = rodmol.paper_arm(n, tensions=pulled)
        view = rodmol.SemiDiscrete(loaded).state_view(0.0, rodmol.equilibrium(loaded))
        start = time.perf_counter()
        fit = rodmol.inverse_statics(arm, view.tip, direction=view.rotations[-1][:, 0] if tangent else None,
                                     cables=None if cables is None else [f"cable {i}" for i in cables],
                                     bounds=(0.0, 5.0))
        wall = time.perf_counter() - start
        error = (max(abs(fit.tensions[f"cable {i}"] - pulled.get(i, 0.0)) for i in cables) if cables
                 else float("nan"))
        rows.append(dict(N=n, case=f"one target: {label}", reachable=fit.reachable, residual_m=fit.residual,
                         tension_error_N=error, steps=fit.iterations, equilibria=fit.equilibria, wall_s=wall))
    return rows


def path(n, n_path):
    arm = rodmol.paper_arm(n)
    ramp = np.linspace(0.0, 1.0, n_path)
    tips, forward = [], []
    for a in ramp:
        model = rodmol.paper_arm(n, tensions={11: 0.9 + 0.2 * a, 12: 0.6 - 0.1 * a})
        start = time.perf_counter()
        y = rodmol.equilibrium(model)
        forward.append(time.perf_counter() - start)
        tips.append(tip_of(model, y))
    tips = np.array(tips)
    start = time.perf_counter()
    fits = rodmol.inverse_statics_path(arm, tips, cables=[f"cable {i}" for i in (9, 10, 11, 12)],
                                       bounds=(0.0, 5.0))
    wall = time.perf_counter() - start
    per_target, per_forward = wall / n_path, float(np.mean(forward))
    return [dict(N=n, case=f"path of {n_path} targets, cables 9-12", reachable=all(f.reachable for f in fits),
                 residual_m=max(f.residual for f in fits), steps=sum(f.iterations for f in fits) / n_path,
                 equilibria=sum(f.equilibria for f in fits) / n_path, wall_s=per_target,
                 forward_equilibrium_s=per_forward, ratio_to_forward=per_target / per_forward,
                 spacing_mm=float(1e3 * np.mean(np.linalg.norm(np.diff(tips, axis=0), axis=1))))]


def main(argv=None):
    args = C.parse_args(__doc__.splitlines()[0], argv)
    sizes = C.pick(args, [10, 30], [10], [6])
    n_path = C.pick(args, 20, 20, 5)
    rodmol.equilibrium(rodmol.paper_arm(sizes[0], tensions=PULLED))  # compile
    rows = []
    for n in sizes:
        rows += one_target(n) + path(n, n_path)
        print(rows[-1])
    header = C.header_lines(args, SCRIPT)
    columns = ["N", "case", "reachable", "residual_m", "tension_error_N", "steps", "equilibria", "wall_s",
               "forward_equilibrium_s", "ratio_to_forward", "spacing_mm"]
    text = C.markdown_table(rows, columns, {"residual_m": ".2e", "tension_error_N": ".1e", "wall_s": ".3f",
                                            "forward_equilibrium_s": ".3f", "ratio_to_forward": ".2f",
                                            "steps": ".1f", "equilibria": ".1f", "spacing_mm": ".2f"})
    note = ("Target: a reachable tip met to 0.1 mm; a path costs at most 5x one forward equilibrium per "
            "target (ratio_to_forward, wall times in one run; steps and equilibria per target on the path). "
            "residual_m on the path is the largest of its targets'.")
    C.write_results(args, "inverse_statics", "Inverse statics on the paper's arm", header, rows,
                    [("Results", text), ("Reading", note)])


if __name__ == "__main__":
    main()
