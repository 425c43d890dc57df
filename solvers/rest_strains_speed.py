"""The kernel with rest strains against the one without, side by side in one run.

The rest strains (``Rod(rest_curvature=, rest_stretch=)``) add two columns
(q*, k*) to each cell's parameters and six subtractions to the Kelvin-Voigt
law of the compiled right-hand side. This measures what that costs on the
paper's bending test at N = 100 (a straight rod, so both versions compute the
same numbers): the tree of a base revision (default: the merge base with
``main``, extracted with ``git archive`` into a kept folder,
``_common.package_tree``) and the current working tree run in two
long-lived workers of ``core_speed.py`` (the same work on both sides: its
settings; when the base's package files are the working tree's, both import
the working tree), warmed up first, repetitions interleaved (old, new, new, old, ...). Reported: min and median of the
solver's wall time, of the whole ``simulate`` call, and of the right-hand
side per call, with the ratios new/old (of the minima, of the medians, and
the median of the ratios within each repetition); and whether the tips
agree bitwise (then both did the same steps: any difference in wall time is
the kernel's or the machine's).

    python solvers/rest_strains_speed.py [--quick | --smoke] [--out DIR] [--reps K] [--base REV]
"""

import os
import shutil
import subprocess
import sys
import tempfile

import _common as C
import core_speed

SCRIPT = "rest_strains_speed.py"


def main(argv=None):
    argv, base = core_speed.split_option(sys.argv[1:] if argv is None else list(argv), "base")
    args = C.parse_args(__doc__.splitlines()[0], argv)
    n, t_end = C.pick(args, 100, 100, 8), C.pick(args, 6.0, 6.0, 0.2)
    calls = C.pick(args, 2000, 1000, 70)
    git = core_speed.git
    base_sha = git("rev-parse", "--verify", (base or git("merge-base", "HEAD", "main")) + "^{commit}")
    # The same package files (as right after a merge, or in CI): both workers import the working tree,
    # whose compiled kernels are cached; an extracted copy would compile them all again for nothing.
    same_tree = subprocess.run(["git", "-C", core_speed.ROOT, "diff", "--quiet", base_sha, "--", "rodmol"]
                               ).returncode == 0
    where = "the working tree itself, the same files" if same_tree else "git archive"
    header = C.header_lines(args, SCRIPT) + [
        f"old: {base_sha[:10]} ({where}); new: working tree at {git('rev-parse', 'HEAD')[:10]}",
        f"bending test, N = {n}, t_end = {t_end:g} s, core_speed.py's worker settings; "
        f"{args.reps} interleaved repetitions per version"]
    tmp = tempfile.mkdtemp(prefix="rodmol-rest-speed-")
    old_tree = core_speed.ROOT if same_tree else C.package_tree(base_sha)[0]
    versions, runs, per_call = [], [], []
    try:
        for label, tree in (("old", old_tree), ("new", core_speed.ROOT)):
            versions.append(core_speed.Version(label, tree, os.path.join(tmp, f"{label}.stderr")))
            versions[-1].ask(cmd="init", n=n, t_end=t_end)
        for rep in range(args.reps):
            for v in versions if rep % 2 == 0 else versions[::-1]:
                tip = os.path.join(tmp, f"tip_{v.label}.npy") if rep == 0 else None
                runs.append(dict(rep=rep, version=v.label, **v.ask(cmd="simulate", tip_path=tip)))
                per_call.append(dict(rep=rep, version=v.label, **v.ask(cmd="percall", calls=calls)))
                print(f"rep {rep} {v.label}: solver {runs[-1]['wall_time_s']:.4f} s, "
                      f"rhs {per_call[-1]['rhs_kernel_us']:.2f} us", flush=True)
        tips = {v.label: C.np.load(os.path.join(tmp, f"tip_{v.label}.npy")) for v in versions}
    finally:
        for v in versions:
            v.close()
        shutil.rmtree(tmp, ignore_errors=True)

    rows = []
    for label, key, table in (("integration wall time [s]", "wall_time_s", runs),
                              ("whole rodmol.simulate call [s]", "simulate_s", runs),
                              ("right-hand side, bare compiled kernel [us]", "rhs_kernel_us", per_call),
                              ("right-hand side, SemiDiscrete call [us]", "rhs_call_us", per_call)):
        old = [r[key] for r in table if r["version"] == "old"]
        new = [r[key] for r in table if r["version"] == "new"]
        (old_min, old_med), (new_min, new_med) = core_speed.summary(C, old), core_speed.summary(C, new)
        paired = [b / a for a, b in zip(old, new)]  # repetition by repetition: the same load on both
        rows.append(dict(quantity=label, old_min=old_min, new_min=new_min, ratio_min=new_min / old_min,
                         old_median=old_med, new_median=new_med, ratio_median=new_med / old_med,
                         median_paired_ratio=float(C.np.median(paired))))
    same = bool(C.np.array_equal(tips["old"], tips["new"]))
    formats = {k: ".4g" for k in rows[0] if k != "quantity"}
    C.write_results(args, SCRIPT[:-3], "Rest strains: the kernel's cost on a straight rod", header, rows, [
        ("Old and new, side by side", C.markdown_table(rows, formats=formats)),
        ("Same numbers", f"tip trajectories bitwise equal: {same}")])


if __name__ == "__main__":
    main()
