"""Speed of the configurations behind the scheme targets, timed in one run.

The bending test (6 s) with the configurations that ``solvers/schemes.py``
found cheapest for 0.1 mm and 1 mm of tip error, with the defaults, and
with the paper's scheme at its old setting (N = 100, rtol 1e-6). For each
one: the median solver wall time of --reps runs, the real-time factor, and
the tip error against the same Richardson reference as ``schemes.py``.

    python solvers/scheme_targets.py [--quick | --smoke] [--out DIR] [--reps K]
"""

import os

import _common as C
from _common import np, rodmol
from schemes import reference, trajectory

SCRIPT = "scheme_targets.py"

CONFIGS = [  # (label, scheme, N, rtol)
    ("default (centred, N = 100, rtol 3e-5)", "centred", 100, None),
    ("0.1 mm target: centred, N = 100, rtol 1e-4", "centred", 100, 1e-4),
    ("1 mm target: centred, N = 50, rtol 1e-4", "centred", 50, 1e-4),
    ("centred, N = 25, default rtol", "centred", 25, None),
    ("paper's scheme, N = 100, default rtol 1e-4", "upwind", 100, None),
    ("paper's scheme, N = 100, rtol 1e-6 (the old default)", "upwind", 100, 1e-6),
]


def main(argv=None):
    args = C.parse_args(__doc__.splitlines()[0], argv)
    header = C.header_lines(args, SCRIPT)
    scenario = rodmol.scenarios.get("bending")
    t_end = C.pick(args, scenario.t_end, scenario.t_end, 0.2)
    t_out = C.outputs(t_end)
    ref_sizes = C.pick(args, (400, 800), (200, 400), (24, 48))
    ref, ref_err = reference(scenario, ref_sizes, t_out)
    configs = CONFIGS if not args.smoke else [(label, s, 8, r) for label, s, _, r in CONFIGS[:2]]
    rows = []
    for label, scheme, n, rtol in configs:
        rtol = rtol or rodmol.SCHEMES[scheme].default_rtol
        tip, wall, raw = trajectory(scenario, n, scheme, rtol, t_out, args.reps)
        err = float(np.max(np.linalg.norm(tip - ref, axis=1)))
        rows.append(dict(config=label, scheme=scheme, N=n, rtol=rtol, tip_err_mm=err * 1e3,
                         wall_s=wall, realtime=t_end / wall, steps=raw.stats["steps"]))
        print(rows[-1], flush=True)
    base = os.path.join(args.out, "scheme_targets")
    note = (f"bending test, {t_end:g} s; solver wall time, median of {args.reps} runs; reference: "
            f"centred N = {ref_sizes}, Richardson, its own error ~{ref_err * 1e3:.1e} mm")
    C.write_csv(base + ".csv", rows, header + [note])
    fmt = {"rtol": ".0e", "tip_err_mm": ".3g", "wall_s": ".4f", "realtime": ".1f"}
    C.write_markdown(base + ".md", "Scheme targets, timed", header,
                     [("Results", note + "\n\n" + C.markdown_table(rows, None, fmt))])
    print("wrote", base + ".{csv,md}")


if __name__ == "__main__":
    main()
