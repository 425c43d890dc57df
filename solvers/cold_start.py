"""The README's first job in a fresh copy of the package (no numba cache) against the same
job again (warm cache), for this checkout's last commit and an older one, side by side.

``rodmol run examples/fetching.toml --out DIR`` in a new process, from a tree extracted by
``git archive`` (the package and examples as a fresh clone holds them; numba's cache goes
to that tree's ``__pycache__``): cold in a fresh tree, then warm in the same tree. Variants:
the older commit (default ``1c57c53``, the start of this work), this commit as it decides
(its helper process only where a core looks idle), and this commit with the helper on
however busy the machine (``RODMOL_COMPILE_AHEAD=1``) and off (``=0``). The repetitions alternate the
variants so they see the same load. Reported per run: the wall time from the process's
start, the CPU time of the run's own process (``self``: its critical path on a quiet
machine) and of its helper (``helper``: the children it waited for); medians over the
repetitions, and cold/warm ratios of each. On a shared machine the wall time counts the
other jobs' slices too; the CPU times do not.

    python solvers/cold_start.py [--quick | --smoke] [--out DIR] [--reps K] [--commit REV]
"""

import json
import os
import shutil
import subprocess
import sys
import tempfile
import time

import core_speed

SCRIPT = "cold_start.py"
OLD_COMMIT = "1c57c53"
JOB = os.path.join("examples", "fetching.toml")
#: Runs the job in the tree on sys.path[0] and writes its CPU times (self, children) as JSON.
_RUNNER = ("import json, resource, sys\n"
           "from rodmol.cli.commands import main\n"
           "code = main(sys.argv[2:])\n"
           "me, kids = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)\n"
           "with open(sys.argv[1], 'w') as f:\n"
           "    json.dump(dict(code=code, self_cpu_s=me.ru_utime + me.ru_stime,\n"
           "                   helper_cpu_s=kids.ru_utime + kids.ru_stime), f)\n")


def _tree(root, sha, folder):
    """``folder`` holding the package and examples of commit ``sha`` (no caches)."""
    os.makedirs(folder)
    archive = subprocess.run(["git", "-C", root, "archive", sha, "rodmol", "examples"], check=True,
                             capture_output=True).stdout
    subprocess.run(["tar", "-x", "-C", folder], input=archive, check=True)
    return folder


def _run(tree, t_end, helper=None):
    """(wall [s], self CPU [s], helper CPU [s]) of the job in ``tree``; ``helper``: the value
    of ``RODMOL_COMPILE_AHEAD`` ("0" off, "1" on however busy the machine, None: rodmol decides)."""
    env = dict(os.environ, PYTHONPATH=tree, OPENBLAS_NUM_THREADS="1")
    env.pop("RODMOL_COMPILE_AHEAD", None)
    if helper is not None:
        env["RODMOL_COMPILE_AHEAD"] = helper
    out = os.path.join(tree, "out")
    record = os.path.join(tree, "cpu.json")
    command = [sys.executable, "-c", f"import sys; sys.path.insert(0, {tree!r})\n" + _RUNNER, record,
               "run", JOB, "--out", out, "--overwrite", "--t-end", repr(t_end)]
    t0 = time.perf_counter()
    done = subprocess.run(command, cwd=tree, env=env, capture_output=True, text=True, timeout=900, check=False)
    wall = time.perf_counter() - t0
    if done.returncode != 0:
        raise RuntimeError(f"the job failed in {tree}:\n{done.stderr[-2000:]}")
    with open(record) as f:
        cpu = json.load(f)
    return wall, cpu["self_cpu_s"], cpu["helper_cpu_s"]


def main(argv=None):
    import _common as C

    argv, commit = core_speed.split_option(sys.argv[1:] if argv is None else list(argv), "commit", OLD_COMMIT)
    args = C.parse_args(__doc__.splitlines()[0], argv)
    if not any(a == "--reps" or a.startswith("--reps=") for a in argv):
        args.reps = C.pick(args, 5, 3, 1)
    np = C.np
    t_end = C.pick(args, 8.0, 8.0, 0.2)

    def sha_of(rev):
        return subprocess.run(["git", "-C", C.ROOT, "rev-parse", "--verify", rev + "^{commit}"], check=True,
                              capture_output=True, text=True).stdout.strip()

    variants = [(f"{commit} (before)", sha_of(commit), None), ("this commit", sha_of("HEAD"), None),
                ("this commit, helper on", sha_of("HEAD"), "1"), ("this commit, helper off", sha_of("HEAD"), "0")]
    if args.mode == "smoke":
        variants = variants[1:2]
    rows = []
    scratch = tempfile.mkdtemp(prefix="rodmol-cold-")
    try:
        for rep in range(args.reps):
            order = variants if rep % 2 == 0 else variants[::-1]
            for name, sha, helper in order:
                tree = _tree(C.ROOT, sha, os.path.join(scratch, f"{rep}-{len(rows)}"))
                for state in ("cold", "warm"):
                    wall, own, kids = _run(tree, t_end, helper)
                    rows.append(dict(variant=name, commit=sha[:7], state=state, rep=rep, wall_s=wall,
                                     self_cpu_s=own, helper_cpu_s=kids, load=os.getloadavg()[0]))
                    print(f"{name:24s} {state} rep {rep}: wall {wall:6.2f} s, self {own:6.2f} s, "
                          f"helper {kids:5.2f} s CPU", flush=True)
                shutil.rmtree(tree, ignore_errors=True)
    finally:
        shutil.rmtree(scratch, ignore_errors=True)

    summary = []
    for name, sha, _ in variants:
        med = {state: {key: float(np.median([r[key] for r in rows if r["variant"] == name and r["state"] == state]))
                       for key in ("wall_s", "self_cpu_s", "helper_cpu_s")} for state in ("cold", "warm")}
        summary.append({"variant": name, "commit": sha[:7],
                        "cold wall [s]": med["cold"]["wall_s"], "warm wall [s]": med["warm"]["wall_s"],
                        "cold/warm wall": med["cold"]["wall_s"] / med["warm"]["wall_s"],
                        "cold self CPU [s]": med["cold"]["self_cpu_s"], "cold helper CPU [s]": med["cold"]["helper_cpu_s"],
                        "warm CPU [s]": med["warm"]["self_cpu_s"] + med["warm"]["helper_cpu_s"],
                        "cold/warm self CPU": med["cold"]["self_cpu_s"] / (med["warm"]["self_cpu_s"]
                                                                           + med["warm"]["helper_cpu_s"])})
    loads = [r["load"] for r in rows]
    text = C.markdown_table(summary, formats={k: ".2f" for k in summary[0] if k not in ("variant", "commit")})
    notes = (f"Medians of {args.reps} repetitions; the job to t = {t_end:g} s. Load average (1 min) during "
             f"the runs: {min(loads):.1f}-{max(loads):.1f} on {os.cpu_count()} cores. `self`: the run's own "
             "process, its critical path on a quiet machine; `helper`: the process compiling beside it.")
    C.write_results(args, "cold_start", "Cold start of the README job", C.header_lines(args, SCRIPT), rows,
                    [("Cold and warm, side by side", text + "\n\n" + notes)])
    print(text)
    return summary


if __name__ == "__main__":
    main()
