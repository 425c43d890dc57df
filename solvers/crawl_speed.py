"""rodmol/OctopusCrawl-v0's cost per simulated second, main against this tree, side by side.

Two versions of the package, each in its own worker process (``core_speed.Version``):
``main``, the merge base of this branch (``--main REV``), and ``new``, this
working tree, which also runs its environment at the scheme's default
tolerance (``rtol=3e-5``, main's) to part what the tolerance buys from what
the code does. Each runs the environment at its defaults (N = 6, 0.05 s
periods) from ``reset()`` over 40 periods (2 s) under three action sequences:

* ``slack``: all tensions zero;
* ``gait``: the crawl of ``examples/octopus.py`` (the three front arms' cables
  2 and 4 pulsed, 2 N), sampled at each period's start and held over it;
* ``random``: uniform in [0, 2 N], the same seeded sequence in every run.

Every round runs every case in every configuration, the versions' order
alternating; reported: the median CPU time per simulated second (below 1:
faster than real time), the integrator's steps and right-hand sides, the
median over rounds of the paired ratio new / main, and how far each
configuration's head positions and rewards are from a run at rtol = 3e-6.

    python solvers/crawl_speed.py [--quick | --smoke] [--out DIR] [--reps K] [--main REV]
"""

import importlib.util
import os
import shutil
import sys
import tempfile
import time

import core_speed

SCRIPT = "crawl_speed.py"
HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
CASES = ("slack", "gait", "random")
PERIODS = 40
SCHEME_RTOL = 3e-5  # the default scheme's rtol: main's environment's
REFERENCE_RTOL = 3e-6

# --------------------------------------------------------------------------- worker


class _Worker:
    def __init__(self, mode="full", configs=()):
        import numpy as np

        import rodmol
        from rodmol.control import crawl
        from rodmol.control.octopus import arm_angle

        self.np, self.crawl, self.rodmol = np, crawl, rodmol
        self.periods = PERIODS if mode != "smoke" else 2
        small = {} if mode != "smoke" else dict(n_elements=3, settle=0.05)
        self.envs = {name: crawl.OctopusCrawlEnv(**small, **options) for name, options in configs}
        example = _example()
        period = next(iter(self.envs.values())).period
        times = example.SETTLE + period * np.arange(self.periods)
        gait = np.zeros((self.periods, 16))
        for i in range(crawl.ARMS):
            for j, cable in enumerate(crawl.CABLES):
                tension = example.crawl(arm_angle(i)).get(cable)
                if tension is not None:
                    gait[:, len(crawl.CABLES) * i + j] = [tension(t) for t in times]
        self.actions = {"slack": np.zeros((self.periods, 16)), "gait": gait,
                        "random": np.random.default_rng(0).uniform(0.0, 2.0, (self.periods, 16))}
        for name in self.envs:  # compiles (or loads) the kernels before anything is timed
            self.run(name, "gait", periods=2)

    def info(self):
        return dict(rodmol_file=self.rodmol.__file__)

    def run(self, config, case, periods=None, trace=False):
        env, np = self.envs[config], self.np
        env.reset()
        before = dict(env.sim.stats)
        heads, rewards = [], []
        cpu = time.process_time()
        for action in self.actions[case][:periods or self.periods]:
            obs, reward, terminated, truncated, info = env.step(action.astype(np.float32))
            heads.append(obs[:3].tolist())
            rewards.append(float(reward))
            if terminated:
                raise RuntimeError(f"{config} {case}: {info['failure']}")
        cpu = time.process_time() - cpu
        after = env.sim.stats
        answer = dict(cpu_per_sim_s=cpu / (len(rewards) * env.period),
                      steps=after["steps"] - before["steps"], rhs_evals=after["rhs_evals"] - before["rhs_evals"])
        if trace:
            answer.update(heads=heads, rewards=rewards)
        return answer


def _example():
    """examples/octopus.py (its crawl gait), loaded under its own name."""
    spec = importlib.util.spec_from_file_location("octopus_example", os.path.join(ROOT, "examples", "octopus.py"))
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


# --------------------------------------------------------------------------- parent



def main(argv=None):
    import _common as C  # the parent runs with this checkout (header, file writers)

    np = C.np
    argv, main_rev = core_speed.split_option(sys.argv[1:] if argv is None else list(argv), "main", "main")
    args = C.parse_args(__doc__.splitlines()[0], argv)
    if not any(a.startswith("--reps") for a in argv):
        args.reps = C.pick(args, 5, 3, 1)
    main_tree, main_sha = C.package_tree(core_speed.git("merge-base", main_rev, "HEAD"))
    head_sha = core_speed.git("rev-parse", "HEAD")
    dirty = bool(core_speed.git("status", "--porcelain", "--untracked-files=no", "--", "rodmol"))
    header = C.header_lines(args, SCRIPT) + [
        f"main: {main_sha[:10]}; new: working tree at {head_sha[:10]}"
        + (" with uncommitted changes under rodmol/" if dirty else ""),
        f"{args.reps} rounds; CPU time of {PERIODS} env.step calls after reset(); one BLAS thread"]
    configs = {"main": [("main", {})],
               "new": [("new", {}), ("new, rtol 3e-5", dict(rtol=SCHEME_RTOL)),
                       ("reference", dict(rtol=REFERENCE_RTOL))]}
    tmp = tempfile.mkdtemp(prefix="rodmol-crawl-speed-")
    versions, runs, traces = [], [], {}
    try:
        for label, tree in (("main", main_tree), ("new", ROOT)):
            versions.append(core_speed.Version(label, tree, os.path.join(tmp, f"{label}.stderr"),
                                               os.path.abspath(__file__)))
        for v in versions:
            t0 = time.perf_counter()
            file = C.started(v, mode=args.mode, configs=configs[v.label])["rodmol_file"]
            print(f"{v.label}: {file} ready in {time.perf_counter() - t0:.1f} s", flush=True)
        for case in CASES:  # the traces, and the reference (not timed)
            for v in versions:
                for name, _ in configs[v.label]:
                    traces[name, case] = v.ask(cmd="run", config=name, case=case, trace=True)
        for rep in range(args.reps):
            for case in CASES:
                order = versions if (rep + CASES.index(case)) % 2 == 0 else versions[::-1]
                for v in order:
                    for name, _ in configs[v.label]:
                        if name != "reference":
                            runs.append(dict(rep=rep, case=case, version=name,
                                             **v.ask(cmd="run", config=name, case=case)))
            print(f"round {rep + 1}/{args.reps} done", flush=True)
    finally:
        for v in versions:
            v.close()
        shutil.rmtree(tmp, ignore_errors=True)
    rows = []
    for case in CASES:
        reference = traces["reference", case]
        mine = [r for r in runs if r["case"] == case]
        for name in ("main", "new, rtol 3e-5", "new"):
            own = [r for r in mine if r["version"] == name]
            trace = traces[name, case]
            rows.append(dict(
                case=case, configuration=name,
                cpu_per_sim_s=float(np.median([r["cpu_per_sim_s"] for r in own])),
                steps=int(np.median([r["steps"] for r in own])),
                rhs_evals=int(np.median([r["rhs_evals"] for r in own])),
                vs_main=C.paired_ratio(mine, "cpu_per_sim_s", name, "main"),
                head_error_m=float(np.max(np.abs(np.subtract(trace["heads"], reference["heads"])))),
                reward_error=float(np.max(np.abs(np.subtract(trace["rewards"], reference["rewards"])))),
                head_travel_m=float(reference["heads"][-1][0] - reference["heads"][0][0])))
    for row in rows:
        print(row, flush=True)
    fmt = dict(cpu_per_sim_s=".3f", vs_main=".3f", head_error_m=".2e", reward_error=".2e", head_travel_m=".2e")
    C.write_results(args, "crawl_speed", "OctopusCrawl-v0 per simulated second, main against this tree",
                    header, rows, [("Results", C.markdown_table(rows, None, fmt))])
    C.write_csv(os.path.join(args.out, "crawl_speed_runs.csv"), runs, header)


if __name__ == "__main__":
    if sys.argv[1:] == ["--worker"]:
        core_speed.worker_main(_Worker)
    else:
        main()
