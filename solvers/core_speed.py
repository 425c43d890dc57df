"""The core before and after its refactor, side by side in one run.

The paper's bending test (``rodmol.scenarios.get("bending").model(N)``,
``rodmol.simulate(model, 6.0)`` with the default options: gravity
equilibrium, CVODE rtol 1e-6, the default linear solver) on the code of the
last commit before the refactor (9fce6d7, its package extracted with
``git archive`` into a kept folder, ``_common.package_tree``) and on the
current checkout (working tree as it is). Each version runs in its own long-lived
subprocess with PYTHONPATH pointing at its tree (the current virtualenv
supplies the dependencies); both are warmed up (numba compilation) before
anything is timed, and the repetitions alternate between the two processes
(old, new, new, old, ...) so that the machine's load drifts affect both.

Reported per version, min and median over the repetitions: the solver's
integration time (``result.stats["wall_time_s"]``), the whole ``simulate``
call (equilibrium + integration + Result), steps and right-hand-side
evaluations; and, per call (best of 7 batches per round, rounds
interleaved): the right-hand side through ``SemiDiscrete.__call__`` and the
bare compiled kernel, the compiled Jacobian (blocks only) and the block
preconditioner's setup (factorisation, Jacobian current) and solve. The two
tip trajectories (``Result.tip``) are compared. Ratios new/old are given of
the minima, of the medians, and as the median of the ratios within each
repetition (the two versions ran back to back, so these see the same load).

    python solvers/core_speed.py [--quick | --smoke] [--out DIR] [--reps K] [--commit REV]
"""

import json
import os
import shutil
import subprocess
import sys
import tempfile
import time

SCRIPT = "core_speed.py"
OLD_COMMIT = "9fce6d7"
HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
MARK = "@@core_speed@@ "  # prefix of the workers' answers (anything else they print is ignored)

# --------------------------------------------------------------------------- worker
# Runs inside the subprocess, with the tree under test first on PYTHONPATH. It
# must not import _common (which puts this checkout first on sys.path).


def _per_call(fn, calls):
    """Seconds per call: the best of 7 batches of ``calls / 7`` calls."""
    fn()
    batch = max(1, calls // 7)
    best = float("inf")
    for _ in range(7):
        t0 = time.perf_counter()
        for _ in range(batch):
            fn()
        best = min(best, (time.perf_counter() - t0) / batch)
    return best


class _Worker:
    def __init__(self, n, t_end):
        import numpy as np

        import rodmol

        self.np, self.rodmol = np, rodmol
        self.model = rodmol.scenarios.get("bending").model(n)
        self.t_end = t_end
        package = os.path.dirname(os.path.abspath(rodmol.__file__))
        if os.path.isdir(os.path.join(package, "discretise")):  # the current layout
            from rodmol.discretise import stencil
            from rodmol.discretise.system import SemiDiscrete

            self.version = "new"
            # The old core's scheme and tolerance, so that both sides do the same work.
            self.options = dict(scheme="upwind", rtol=1e-6)
            system = SemiDiscrete(self.model, "upwind")  # the scheme the old core had
            self.kernel = stencil.rhs
            scale = rodmol.default_atol(self.model, 1e-6) / 1e-6
            self.jac = system.jacobian(scale, None)
            self.pre = system.preconditioner(scale)
        else:  # before the refactor (9fce6d7)
            self.options = {}
            from rodmol.semidiscrete import SemiDiscrete

            from rodmol import jacobian, kernels

            self.version = "old"
            system = SemiDiscrete(self.model)
            self.kernel = kernels.rhs
            scale = rodmol.default_atol(self.model, 1e-6) / 1e-6
            self.jac = jacobian.CompiledJacobian(system, scale, None)
            self.pre = jacobian.BlockPreconditioner(system, scale)
        self.system = system
        y0 = rodmol.equilibrium(self.model)
        rng = np.random.default_rng(0)
        self.y = y0 + 1e-4 * rng.normal(size=y0.size)
        self.t = 0.3  # inside the pull's ramp: the tension is evaluated per call
        self.out = np.empty_like(self.y)
        self.z = np.empty_like(self.y)
        self.gamma = 1e-3
        system.update_inputs(self.t, self.y)
        self.karg = system.kernel_arguments()
        self.fy = system(self.t, self.y)
        self.pre.setup(self.t, self.y, self.fy, False, [0], self.gamma)
        # Warm-up: compile (or load) everything a default run and the per-call timings use.
        rodmol.simulate(self.model, min(t_end, 0.05), **self.options)
        self.percall(7)

    def info(self):
        res = self.rodmol.simulate(self.model, min(self.t_end, 0.05), **self.options)
        package = os.path.dirname(os.path.abspath(self.rodmol.__file__))
        foreign = sorted(name for name, mod in sys.modules.items()
                         if (name == "rodmol" or name.startswith("rodmol."))
                         and getattr(mod, "__file__", None)
                         and not os.path.abspath(mod.__file__).startswith(package + os.sep))
        return dict(version=self.version, rodmol_file=self.rodmol.__file__, foreign_modules=foreign,
                    size=int(self.y.size),
                    linear_solver=res.stats.get("linear_solver", ""),
                    jacobian_evaluations=int(getattr(self.jac, "evaluations", -1)))

    def simulate(self, tip_path=None):
        import gc

        gc.collect()
        t0 = time.perf_counter()
        res = self.rodmol.simulate(self.model, self.t_end, **self.options)
        total = time.perf_counter() - t0
        if tip_path:
            self.np.save(tip_path, self.np.column_stack([res.t, res.tip]))
        st = res.stats
        return dict(wall_time_s=float(st["wall_time_s"]), simulate_s=total, steps=int(st["steps"]),
                    rhs_evals=int(st["rhs_evals"]), success=bool(res.success),
                    linear_solver=st.get("linear_solver", ""))

    def percall(self, calls):
        s, t, y, out, fy, z, g = self.system, self.t, self.y, self.out, self.fy, self.z, self.gamma
        kernel, karg, jac, pre = self.kernel, self.karg, self.jac, self.pre
        return {
            "rhs_call_us": 1e6 * _per_call(lambda: s(t, y, out), calls),
            "rhs_kernel_us": 1e6 * _per_call(lambda: kernel(y, out, *karg), calls),
            "jacobian_us": 1e6 * _per_call(lambda: jac.evaluate(t, y, fy), max(7, calls // 50)),
            "precond_setup_us": 1e6 * _per_call(lambda: pre.setup(t, y, fy, True, [0], g),
                                                max(7, calls // 20)),
            "precond_solve_us": 1e6 * _per_call(lambda: pre.solve(t, y, fy, fy, z, g, 0.0, 1), calls),
        }


def worker_main(make=None):
    """Answer one JSON command per stdin line with one MARK-prefixed JSON line: ``init``
    makes the worker (``make(**fields)``, the command's other fields, default
    :class:`_Worker`: ``n``, ``t_end``) and answers its ``info()``; any other command but
    ``quit`` calls the worker's method of that name with the command's other fields."""
    # An editable install of rodmol adds a finder that serves, for any module a
    # tree lacks, the installed checkout's (rodmol.discretise for the old tree):
    # drop it so that only the tree on PYTHONPATH is seen.
    sys.meta_path[:] = [f for f in sys.meta_path if "editable" not in getattr(f, "__name__", type(f).__name__).lower()]
    w = None
    for line in sys.stdin:
        cmd = json.loads(line)
        name = cmd.pop("cmd")
        try:
            if name == "init":
                w = (make or _Worker)(**cmd)
                answer = w.info()
            elif name == "quit":
                break
            else:
                answer = getattr(w, name)(**cmd)
        except Exception as exc:  # noqa: BLE001  (hand any failure to the parent)
            import traceback

            answer = dict(error=f"{type(exc).__name__}: {exc}", traceback=traceback.format_exc())
        sys.stdout.write(MARK + json.dumps(answer) + "\n")
        sys.stdout.flush()


# --------------------------------------------------------------------------- parent


class Version:
    """A worker subprocess running the rodmol of ``tree`` (the ``--worker`` of ``script``,
    by default this file)."""

    def __init__(self, label, tree, stderr_path, script=None):
        env = dict(os.environ, PYTHONPATH=tree)
        for var in ("OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "OMP_NUM_THREADS"):
            env[var] = "1"
        self.label, self.tree = label, tree
        self._err = open(stderr_path, "w")  # noqa: SIM115  (open for the worker's lifetime)
        script = script or os.path.abspath(__file__)  # the worker's script: this one's, or another study's
        self.proc = subprocess.Popen([sys.executable, script, "--worker"], env=env,
                                     stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=self._err,
                                     text=True, cwd=tree)

    def ask(self, **cmd):
        self.proc.stdin.write(json.dumps(cmd) + "\n")
        self.proc.stdin.flush()
        for line in self.proc.stdout:
            if line.startswith(MARK):
                answer = json.loads(line[len(MARK):])
                if "error" in answer:
                    raise RuntimeError(f"{self.label} worker: {answer['error']}\n{answer['traceback']}")
                return answer
        self._err.flush()
        with open(self._err.name) as f:
            raise RuntimeError(f"{self.label} worker exited:\n{f.read()[-4000:]}")

    def close(self):
        try:
            self.proc.stdin.write(json.dumps(dict(cmd="quit")) + "\n")
            self.proc.stdin.close()
            self.proc.wait(timeout=30)
        except Exception:  # noqa: BLE001  (a worker that will not quit is killed)
            self.proc.kill()
            self.proc.wait()
        self._err.close()


def git(*args):
    return subprocess.run(["git", "-C", ROOT, *args], check=True, capture_output=True, text=True).stdout.strip()


def split_option(argv, name, default=None):
    """(the other arguments, the value of ``--name REV`` or ``--name=REV``, else ``default``)."""
    rest, value, it = [], default, iter(argv)
    for a in it:
        if a == f"--{name}":
            value = next(it)
        elif a.startswith(f"--{name}="):
            value = a.split("=", 1)[1]
        else:
            rest.append(a)
    return rest, value


def summary(C, values):
    a = C.np.asarray(values, dtype=float)
    return float(a.min()), float(C.np.median(a))


def main(argv=None):
    import _common as C  # the parent runs with this checkout (header, file writers)

    argv, commit = split_option(sys.argv[1:] if argv is None else list(argv), "commit", OLD_COMMIT)
    args = C.parse_args(__doc__.splitlines()[0], argv)
    if not any(a == "--reps" or a.startswith("--reps=") for a in argv):
        args.reps = C.pick(args, 7, 5, 1)
    n = C.pick(args, 100, 100, 8)
    t_end = C.pick(args, 6.0, 6.0, 0.2)
    calls = C.pick(args, 2000, 1000, 70)
    rounds = max(1, args.reps)
    np = C.np

    old_tree, old_sha = C.package_tree(commit)
    head_sha = git("rev-parse", "HEAD")
    dirty = bool(git("status", "--porcelain", "--untracked-files=no", "--", "rodmol"))
    header = C.header_lines(args, SCRIPT) + [
        f"old: {old_sha[:10]} (git archive); new: working tree at {head_sha[:10]}"
        + (" with uncommitted changes under rodmol/" if dirty else ""),
        f"bending test, N = {n}, rodmol.simulate(model, {t_end:g}) with default options; "
        f"{args.reps} interleaved repetitions per version"]

    tmp = tempfile.mkdtemp(prefix="rodmol-core-speed-")
    versions = []
    try:
        for label, tree in (("old", old_tree), ("new", ROOT)):
            versions.append(Version(label, tree, os.path.join(tmp, f"{label}.stderr")))
        info = {}
        for v in versions:  # one after the other: compilation wants a core
            t0 = time.perf_counter()
            info[v.label] = v.ask(cmd="init", n=n, t_end=t_end)
            print(f"{v.label}: {info[v.label]['rodmol_file']} ready in {time.perf_counter() - t0:.1f} s "
                  f"(linear solver {info[v.label]['linear_solver']})", flush=True)
            expected = os.path.realpath(v.tree)
            if not os.path.realpath(info[v.label]["rodmol_file"]).startswith(expected + os.sep):
                raise RuntimeError(f"{v.label} worker imported {info[v.label]['rodmol_file']}, not from {expected}")
            if info[v.label]["foreign_modules"]:
                raise RuntimeError(f"{v.label} worker imported modules from outside its tree: "
                                   f"{info[v.label]['foreign_modules']}")
            if info[v.label]["version"] != v.label:
                raise RuntimeError(f"{v.label} worker found the {info[v.label]['version']} layout")

        runs = []
        for rep in range(args.reps):
            order = versions if rep % 2 == 0 else versions[::-1]
            for v in order:
                tip_path = os.path.join(tmp, f"tip_{v.label}.npy") if rep == 0 else None
                r = v.ask(cmd="simulate", tip_path=tip_path)
                runs.append(dict(rep=rep, version=v.label, **r))
                print(f"rep {rep} {v.label}: solver {r['wall_time_s']:.4f} s, simulate {r['simulate_s']:.4f} s, "
                      f"{r['steps']} steps, {r['rhs_evals']} RHS", flush=True)
        calls_rows = []
        for rnd in range(rounds):
            order = versions if rnd % 2 == 0 else versions[::-1]
            for v in order:
                calls_rows.append(dict(round=rnd, version=v.label, **v.ask(cmd="percall", calls=calls)))
        tips = {v.label: np.load(os.path.join(tmp, f"tip_{v.label}.npy")) for v in versions}
    finally:
        for v in versions:
            v.close()
        shutil.rmtree(tmp, ignore_errors=True)

    # Tip trajectories.
    length = C.rodmol.scenarios.get("bending").model(n).rod.length
    a, b = tips["old"], tips["new"]
    same_times = a.shape == b.shape and np.allclose(a[:, 0], b[:, 0])
    m = min(len(a), len(b))
    tip_diff = float(np.max(np.linalg.norm(a[:m, 1:] - b[:m, 1:], axis=1)))
    tip_range = float(np.max(np.linalg.norm(a[:m, 1:] - a[0, 1:], axis=1)))

    quantities = [
        ("integration wall time (stats wall_time_s) [s]", "wall_time_s", runs, ".4f"),
        ("whole rodmol.simulate call [s]", "simulate_s", runs, ".4f"),
        ("steps", "steps", runs, "d"),
        ("RHS evaluations", "rhs_evals", runs, "d"),
        ("right-hand side, SemiDiscrete call [us]", "rhs_call_us", calls_rows, ".2f"),
        ("right-hand side, bare compiled kernel [us]", "rhs_kernel_us", calls_rows, ".2f"),
        ("compiled Jacobian (blocks) [us]", "jacobian_us", calls_rows, ".1f"),
        ("preconditioner setup (factorisation) [us]", "precond_setup_us", calls_rows, ".1f"),
        ("preconditioner solve [us]", "precond_solve_us", calls_rows, ".2f"),
    ]
    rows = []
    for label, key, source, fmt in quantities:
        o_min, o_med = summary(C, [r[key] for r in source if r["version"] == "old"])
        n_min, n_med = summary(C, [r[key] for r in source if r["version"] == "new"])
        # Each repetition (round) ran the two versions back to back: their ratio
        # sees the same load, so the median of these paired ratios drifts least.
        pair = "rep" if "rep" in source[0] else "round"
        by = {}
        for r in source:
            by.setdefault(r[pair], {})[r["version"]] = r[key]
        paired = float(np.median([d["new"] / d["old"] for d in by.values() if d.get("old")]))
        rows.append(dict(quantity=label, key=key, old_min=o_min, old_median=o_med, new_min=n_min,
                         new_median=n_med, ratio_new_old_min=n_min / o_min if o_min else float("nan"),
                         ratio_new_old_median=n_med / o_med if o_med else float("nan"),
                         ratio_new_old_paired=paired, fmt=fmt))
        print(f"{label:48s} old {o_med:10.4g}  new {n_med:10.4g}  new/old {rows[-1]['ratio_new_old_median']:.3f}",
              flush=True)
    print(f"tip trajectories: max |old - new| = {tip_diff:.3e} m"
          + (f" ({tip_diff / length:.2e} L)" if length else "") + f"; same output times: {same_times}", flush=True)

    base = os.path.join(args.out, "core_speed")
    csv_rows = [{k: v for k, v in r.items() if k != "fmt"} for r in rows]
    csv_rows.append(dict(quantity="tip trajectory, max |old - new| [m]", key="tip_max_diff_m",
                         old_min="", old_median="", new_min="", new_median=tip_diff,
                         ratio_new_old_min="", ratio_new_old_median="", ratio_new_old_paired=""))
    note = [f"linear solver: old {info['old']['linear_solver']}, new {info['new']['linear_solver']}; "
            f"per-call figures: best of 7 batches per round, min / median over {rounds} rounds; "
            "'median of pairs': the median over repetitions (rounds) of new/old within the same "
            "repetition, the two versions having run back to back"]
    C.write_csv(base + ".csv", csv_rows, header + note)
    C.write_csv(base + "_runs.csv", runs, header)
    C.write_csv(base + "_calls.csv", calls_rows, header)

    def cell(v, fmt):
        return format(int(round(v)), "d") if fmt == "d" else format(v, fmt)

    lines = ["| quantity | 9fce6d7 min | 9fce6d7 median | current min | current median | new/old (min) "
             "| new/old (median) | new/old (median of pairs) |", "|---|---|---|---|---|---|---|---|"]
    for r in rows:
        f = r["fmt"]
        lines.append(f"| {r['quantity']} | {cell(r['old_min'], f)} | {cell(r['old_median'], f)} | "
                     f"{cell(r['new_min'], f)} | {cell(r['new_median'], f)} | {r['ratio_new_old_min']:.3f} | "
                     f"{r['ratio_new_old_median']:.3f} | {r['ratio_new_old_paired']:.3f} |")
    table = "\n".join(lines) + "\n"
    tips_text = (f"Largest distance between the two `Result.tip` trajectories over the {m} output frames: "
                 f"**{tip_diff:.2e} m**" + (f" ({tip_diff / length:.2e} L)" if length else "")
                 + f"; the tip travels up to {tip_range:.3f} m from its start"
                 + ("" if same_times else "; the output times differ") + ".\n")
    sections = [
        ("Bending test, old against new", "\n".join(note) + "\n\n" + table),
        ("Tip trajectories", tips_text),
    ]
    C.write_markdown(base + ".md", "Core speed: before (9fce6d7) and after the refactor", header, sections)
    print("wrote", base + ".{csv,md}", "and", base + "_{runs,calls}.csv")


if __name__ == "__main__":
    if sys.argv[1:] == ["--worker"]:
        worker_main()
    else:
        main()
