"""A System's ``simulate`` against the old driver, and a rod's against main, side by side.

Three versions of the package, each in its own long-lived worker process
(``core_speed.Version``: PYTHONPATH at its tree, one BLAS thread): ``old``, the commit before the
System's own CVODE driver (``solve/system_cvode.py``) was removed (548824c^);
``main``, the merge base of this branch (``--main REV``); ``new``, this
working tree. Every round runs every case once in each version, the versions'
order alternating between rounds (so that the shared machine's load falls on
all), and times the process's CPU over one ``rodmol.simulate`` call. Cases:

* ``octopus ramp`` and ``octopus pulsing``: ``solvers/octopus.py``'s eight
  arms at N = 30 on a free head, 1 s, GMRES (the default);
* ``bending N=100``: the paper's bending test, ``simulate(model, 6.0)``.

Reported per case and version: the median CPU time, CVODE's own counters
(steps, right-hand sides, linear setups, read through
``solvers/_cvode_stats.py``) and the median over rounds of the paired ratio
new / old and new / main (the two ran back to back in the round).

    python solvers/driver_speed.py [--quick | --smoke] [--out DIR] [--reps K] [--main REV]
"""

import os
import shutil
import sys
import tempfile
import time
import types

import core_speed

SCRIPT = "driver_speed.py"
OLD_COMMIT = "548824c^"  # the last commit with solve/system_cvode.py
HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
CASES = ("octopus ramp", "octopus pulsing", "bending N=100")

# --------------------------------------------------------------------------- worker
# Runs inside the subprocess with its tree first on PYTHONPATH: it must not import
# _common (which puts this checkout first on sys.path).


class _Worker:
    def __init__(self, mode="full"):
        import numpy as np

        import rodmol

        sys.path.insert(1, HERE)
        # octopus.py builds its System from rodmol's public names only; its _common is
        # this worker's numpy and rodmol, not the parent's checkout.
        sys.modules["_common"] = types.SimpleNamespace(np=np, rodmol=rodmol)
        import _cvode_stats
        import octopus

        self.rodmol, self.stats = rodmol, _cvode_stats
        n, self.t_octopus = (30, 1.0) if mode != "smoke" else (8, 0.05)
        self.cases = {f"octopus {name}": (octopus.octopus(n, pattern), self.t_octopus, {})
                      for name, pattern in octopus.PATTERNS.items()}
        self.cases["bending N=100"] = (rodmol.scenarios.get("bending").model(100 if mode != "smoke" else 10),
                                       6.0 if mode != "smoke" else 0.2, {})
        for name in self.cases:  # compiles (or loads) every kernel before anything is timed
            self.run(name)

    def info(self):
        return dict(rodmol_file=self.rodmol.__file__)

    def run(self, name):
        import gc

        thing, t_end, options = self.cases[name]
        gc.collect()
        with self.stats.Recorder() as made:
            cpu, wall = time.process_time(), time.perf_counter()
            result = self.rodmol.simulate(thing, t_end, **options)
            cpu, wall = time.process_time() - cpu, time.perf_counter() - wall
        counters = self.stats.counters(made.solvers[-1], result.stats["rhs_evals"])
        return dict(cpu_s=cpu, wall_s=wall, success=bool(result.success), steps=counters["steps"],
                    rhs_evals=int(result.stats["rhs_evals"]), linear_setups=counters["linear_setups"],
                    prec_solves=counters["prec_solves"])



def rounds(versions, reps):
    """Every case in every version per round, the versions' order alternating: the runs."""
    runs = []
    for rep in range(reps):
        for case in CASES:
            order = versions if (rep + CASES.index(case)) % 2 == 0 else versions[::-1]
            for v in order:
                runs.append(dict(rep=rep, case=case, version=v.label, **v.ask(cmd="run", name=case)))
        print(f"round {rep + 1}/{reps} done", flush=True)
    return runs


def table(C, runs):
    """One row per case: medians per version, counters, and the paired ratios' medians."""
    np, rows = C.np, []
    for case in CASES:
        mine = [r for r in runs if r["case"] == case]
        by = {}
        for r in mine:
            by.setdefault(r["rep"], {})[r["version"]] = r
        row = dict(case=case)
        for label in ("old", "main", "new"):
            runs_v = [r for r in mine if r["version"] == label]
            row[f"{label}_cpu_s"] = float(np.median([r["cpu_s"] for r in runs_v]))
            for key in ("steps", "rhs_evals", "linear_setups"):
                values = sorted({r[key] for r in runs_v})
                row[f"{label}_{key}"] = values[0] if len(values) == 1 else "/".join(map(str, values))
        for base in ("old", "main"):
            ratios = [d["new"]["cpu_s"] / d[base]["cpu_s"] for d in by.values()]
            row[f"new_vs_{base}"] = C.paired_ratio(mine, "cpu_s", "new", base)
            low, high = np.percentile(ratios, [25, 75])
            row[f"new_vs_{base}_iqr"] = f"{low:.3f}-{high:.3f}"
        row["main_vs_old"] = C.paired_ratio(mine, "cpu_s", "main", "old")
        rows.append(row)
    return rows


def main(argv=None):
    import _common as C  # the parent runs with this checkout (header, file writers)

    argv, main_rev = core_speed.split_option(sys.argv[1:] if argv is None else list(argv), "main", "main")
    args = C.parse_args(__doc__.splitlines()[0], argv)
    if not any(a.startswith("--reps") for a in argv):
        args.reps = C.pick(args, 21, 7, 1)
    trees = dict(old=C.package_tree(OLD_COMMIT), main=C.package_tree(core_speed.git("merge-base", main_rev, "HEAD")))
    head_sha = core_speed.git("rev-parse", "HEAD")
    dirty = bool(core_speed.git("status", "--porcelain", "--untracked-files=no", "--", "rodmol"))
    header = C.header_lines(args, SCRIPT) + [
        f"old: {trees['old'][1][:10]}; main: {trees['main'][1][:10]}; new: working tree at {head_sha[:10]}"
        + (" with uncommitted changes under rodmol/" if dirty else ""),
        f"{args.reps} rounds; CPU time of one rodmol.simulate call per run; one BLAS thread"]
    tmp = tempfile.mkdtemp(prefix="rodmol-driver-speed-")
    versions = []
    try:
        for label, tree in (("old", trees["old"][0]), ("main", trees["main"][0]), ("new", ROOT)):
            versions.append(core_speed.Version(label, tree, os.path.join(tmp, f"{label}.stderr"),
                                               os.path.abspath(__file__)))
        for v in versions:  # one after the other: compilation wants a core
            t0 = time.perf_counter()
            file = C.started(v, mode=args.mode)["rodmol_file"]
            print(f"{v.label}: {file} ready in {time.perf_counter() - t0:.1f} s", flush=True)
        runs = rounds(versions, args.reps)
    finally:
        for v in versions:
            v.close()
        shutil.rmtree(tmp, ignore_errors=True)
    rows = table(C, runs)
    for row in rows:
        print(row, flush=True)
    fmt = {key: ".4f" for key in rows[0] if key.endswith("_cpu_s")}
    fmt.update({key: ".3f" for key in ("new_vs_old", "new_vs_main", "main_vs_old")})
    C.write_results(args, "driver_speed", "A System's simulate against the old driver, a rod's against main",
                    header, rows, [("Results", C.markdown_table(rows, None, fmt))])
    C.write_csv(os.path.join(args.out, "driver_speed_runs.csv"), runs, header)


if __name__ == "__main__":
    if sys.argv[1:] == ["--worker"]:
        core_speed.worker_main(_Worker)
    else:
        main()
