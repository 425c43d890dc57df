"""The bending test at N = 100 on an older commit and on this checkout, side by side in one run.

``rodmol.simulate(scenarios.get("bending").model(N), 6.0)`` with the default
options of each version, in two long-lived worker subprocesses (the old
package extracted by ``_common.package_tree``, the new one this working
tree; ``core_speed.Version``), both warmed up before anything is timed, the
repetitions alternating (old, new, new, old, ...). Reported: the solver's
wall time (``stats["wall_time_s"]``) and CPU time over the same span
(``_cpu_span``: on a shared machine the wall time counts the other jobs' time
slices too) and the whole ``simulate`` call's wall and CPU time, min
and median per version, and the median over repetitions of new/old within
each (the two ran back to back, so they saw the same load); steps and
right-hand sides; the largest distance between the two tip trajectories.

    python solvers/bending_vs_commit.py [--quick | --smoke] [--out DIR] [--reps K] [--commit REV]
"""

import os
import shutil
import sys
import tempfile
import time

import core_speed

SCRIPT = "bending_vs_commit.py"
OLD_COMMIT = "f8094e2"  # the start of the round before issue 34


class _Worker:
    """Runs inside the subprocess (the tree under test first on PYTHONPATH)."""

    def __init__(self, n, t_end):
        import numpy as np

        import rodmol

        self.np, self.rodmol, self.t_end = np, rodmol, t_end
        self.model = rodmol.scenarios.get("bending").model(n)
        rodmol.simulate(self.model, min(t_end, 0.05))  # compile (or load) the kernels

    def info(self):
        package = os.path.dirname(os.path.abspath(self.rodmol.__file__))
        foreign = sorted(name for name, mod in sys.modules.items()
                         if (name == "rodmol" or name.startswith("rodmol."))
                         and getattr(mod, "__file__", None)
                         and not os.path.abspath(mod.__file__).startswith(package + os.sep))
        return dict(rodmol_file=self.rodmol.__file__, foreign_modules=foreign)

    def simulate(self, tip_path=None):
        import gc

        from _cpu_span import cpu_span

        from rodmol.solve import outputs

        gc.collect()
        t0, c0 = time.perf_counter(), time.process_time()
        with cpu_span(outputs) as span:
            res = self.rodmol.simulate(self.model, self.t_end)
        total, cpu = time.perf_counter() - t0, time.process_time() - c0
        if tip_path:
            self.np.save(tip_path, self.np.column_stack([res.t, res.tip]))
        st = res.stats
        return dict(wall_time_s=float(st["wall_time_s"]), solver_cpu_s=span["cpu_s"], simulate_s=total,
                    simulate_cpu_s=cpu, steps=int(st["steps"]),
                    rhs_evals=int(st["rhs_evals"]), success=bool(res.success))


def main(argv=None):
    import _common as C

    argv, commit = core_speed.split_option(sys.argv[1:] if argv is None else list(argv), "commit", OLD_COMMIT)
    args = C.parse_args(__doc__.splitlines()[0], argv)
    if not any(a == "--reps" or a.startswith("--reps=") for a in argv):
        args.reps = C.pick(args, 15, 7, 2)
    np = C.np
    n = C.pick(args, 100, 100, 8)
    t_end = C.pick(args, 6.0, 6.0, 0.2)
    old_tree, old_sha = C.package_tree(commit)
    head = core_speed.git("rev-parse", "HEAD")
    dirty = bool(core_speed.git("status", "--porcelain", "--untracked-files=no", "--", "rodmol"))
    header = C.header_lines(args, SCRIPT) + [
        f"old: {old_sha[:10]} (git archive); new: working tree at {head[:10]}"
        + (" with uncommitted changes under rodmol/" if dirty else ""),
        f"bending test, N = {n}, rodmol.simulate(model, {t_end:g}) with each version's default options; "
        f"{args.reps} interleaved repetitions"]
    tmp = tempfile.mkdtemp(prefix="rodmol-bending-vs-")
    versions, runs = [], []
    try:
        for label, tree in (("old", old_tree), ("new", C.ROOT)):
            v = core_speed.Version(label, tree, os.path.join(tmp, label + ".stderr"), os.path.abspath(__file__))
            versions.append(v)
            t0 = time.perf_counter()
            info = v.ask(cmd="init", n=n, t_end=t_end)
            print(f"{label}: {info['rodmol_file']} ready in {time.perf_counter() - t0:.1f} s", flush=True)
            if not os.path.realpath(info["rodmol_file"]).startswith(os.path.realpath(tree) + os.sep) \
                    or info["foreign_modules"]:
                raise RuntimeError(f"{label} worker imported rodmol from outside {tree}: {info}")
        for rep in range(args.reps):
            for v in (versions if rep % 2 == 0 else versions[::-1]):
                tip_path = os.path.join(tmp, f"tip_{v.label}.npy") if rep == 0 else None
                runs.append(dict(rep=rep, version=v.label, **v.ask(cmd="simulate", tip_path=tip_path)))
                r = runs[-1]
                print(f"rep {rep} {v.label}: solver {r['wall_time_s']:.4f} s, simulate {r['simulate_s']:.4f} s, "
                      f"{r['steps']} steps", flush=True)
        tips = {v.label: np.load(os.path.join(tmp, f"tip_{v.label}.npy")) for v in versions}
    finally:
        for v in versions:
            v.close()
        shutil.rmtree(tmp, ignore_errors=True)

    a, b = tips["old"], tips["new"]
    m = min(len(a), len(b))
    tip_diff = float(np.max(np.linalg.norm(a[:m, 1:] - b[:m, 1:], axis=1)))
    rows = []
    for key, label in (("wall_time_s", "solver wall time [s]"), ("solver_cpu_s", "solver CPU time [s]"),
                       ("simulate_s", "whole simulate call [s]"),
                       ("simulate_cpu_s", "whole simulate call, CPU time [s]"),
                       ("steps", "steps"), ("rhs_evals", "right-hand sides")):
        old = [r[key] for r in runs if r["version"] == "old"]
        new = [r[key] for r in runs if r["version"] == "new"]
        paired = float(np.median([b_ / a_ for a_, b_ in zip(old, new)]))
        rows.append(dict(quantity=label, old_min=min(old), old_median=float(np.median(old)), new_min=min(new),
                         new_median=float(np.median(new)), new_over_old_paired=paired))
        print(f"{label:28s} old {np.median(old):.4g}  new {np.median(new):.4g}  new/old (paired) {paired:.3f}")
    print(f"tip trajectories: max |old - new| = {tip_diff:.2e} m")
    base = os.path.join(args.out, "bending_vs_commit")
    note = (f"old: {commit}; the ratio is the median over repetitions of new/old within each; tip trajectories: "
            f"max |old - new| = {tip_diff:.2e} m")
    C.write_csv(base + ".csv", rows, header + [note])
    C.write_csv(base + "_runs.csv", runs, header)
    fmt = {k: ".4g" for k in ("old_min", "old_median", "new_min", "new_median")} | {"new_over_old_paired": ".3f"}
    C.write_markdown(base + ".md", f"Bending test: {commit} against this checkout", header,
                     [("Results", note + "\n\n" + C.markdown_table(rows, None, fmt))])
    print("wrote", base + ".{csv,md}")


if __name__ == "__main__":
    if sys.argv[1:] == ["--worker"]:
        core_speed.worker_main(_Worker)
    else:
        main()
