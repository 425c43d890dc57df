"""Shared helpers of the solver studies: command line, machine header, timing,
output files (CSV + Markdown + PNG under ``solvers/results/``).

Import this module before numpy: it pins OpenBLAS/MKL/OpenMP to one thread.
Their worker threads spin for a while after each call (e.g. in the static
equilibrium's banded solve), and on a 2-core machine they take the core the
solver is timed on.
"""

import argparse
import csv
import datetime
import os
import platform
import shutil
import subprocess
import sys
import tempfile
import time

for _var in ("OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "OMP_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import matplotlib  # noqa: E402
import matplotlib.ticker  # noqa: E402

matplotlib.use("Agg")  # no display on the CI machine
import matplotlib.pyplot as plt  # noqa: E402,F401  (re-exported for the scripts)
import numpy as np  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, ROOT)  # run from a checkout without installing

import rodmol  # noqa: E402
from rodmol.discretise.layout import BLOCK, HEADER, StateLayout  # noqa: E402
from rodmol.discretise.system import SemiDiscrete  # noqa: E402,F401
from rodmol.result import from_states  # noqa: E402
from rodmol.simulate import default_atol  # noqa: E402,F401
from rodmol.solve.backends import cvode, rk23  # noqa: E402,F401

RESULTS = os.path.join(HERE, "results")


def parse_args(description, argv=None):
    """--quick (small sizes), --smoke (seconds, for the tests), --out DIR."""
    parser = argparse.ArgumentParser(description=description)
    mode = parser.add_mutually_exclusive_group()
    mode.add_argument("--quick", action="store_true", help="smaller sizes, about a minute")
    mode.add_argument("--smoke", action="store_true", help="tiny sizes, a few seconds (tests)")
    parser.add_argument("--out", default=None,
                        help="output directory (default solvers/results, or solvers/results/smoke)")
    parser.add_argument("--reps", type=int, default=None, help="timed repetitions (median)")
    args = parser.parse_args(argv)
    args.mode = "smoke" if args.smoke else "quick" if args.quick else "full"
    if args.out is None:
        args.out = os.path.join(RESULTS, "smoke") if args.smoke else RESULTS
    os.makedirs(args.out, exist_ok=True)
    if args.reps is None:
        args.reps = 1 if args.smoke else 3
    return args


def package_tree(commit):
    """(folder, full hash): a folder holding the package ``rodmol/`` as of ``commit``, for a
    worker subprocess to import (PYTHONPATH), the old side of a before/after study.

    Extracted with ``git archive`` once and kept in the user's cache folder
    (``$XDG_CACHE_HOME`` or ``~/.cache``, then ``rodmol/trees/<hash>``): a commit's files
    never change, and numba caches the old kernels' machine code beside them, so the
    next run loads it instead of compiling every kernel again (tens of seconds)."""
    sha = subprocess.run(["git", "-C", ROOT, "rev-parse", "--verify", commit + "^{commit}"], check=True,
                         capture_output=True, text=True).stdout.strip()
    cache = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    folder = os.path.join(cache, "rodmol", "trees", sha)
    if not os.path.isdir(folder):
        os.makedirs(os.path.dirname(folder), exist_ok=True)
        staging = tempfile.mkdtemp(prefix=f".{sha[:10]}-", dir=os.path.dirname(folder))
        archive = subprocess.run(["git", "-C", ROOT, "archive", sha, "rodmol"], check=True,
                                 capture_output=True).stdout
        subprocess.run(["tar", "-x", "-C", staging], input=archive, check=True)
        try:
            os.rename(staging, folder)  # whole or not at all, should another run extract it too
        except OSError:
            shutil.rmtree(staging, ignore_errors=True)
    return folder, sha


def paired_ratio(runs, key, new, base, pair="rep"):
    """Median over rounds (``pair``) of ``runs``' ``key`` of version ``new`` over version ``base``:
    the two ran back to back within a round, so their ratio sees the same load."""
    by = {}
    for r in runs:
        by.setdefault(r[pair], {})[r["version"]] = r[key]
    return float(np.median([d[new] / d[base] for d in by.values() if d.get(base)]))


def started(version, **fields):
    """Initialise the worker ``version`` (a ``core_speed.Version``) with ``fields``; its answer,
    after checking that it imported rodmol from its own tree."""
    info = version.ask(cmd="init", **fields)
    if not os.path.realpath(info["rodmol_file"]).startswith(os.path.realpath(version.tree) + os.sep):
        raise RuntimeError(f"{version.label} worker imported {info['rodmol_file']}, not from {version.tree}")
    return info


def pick(args, full, quick, smoke):
    """The value of a setting for the run mode."""
    return {"full": full, "quick": quick, "smoke": smoke}[args.mode]


def machine():
    """CPU, cores and package versions, for the header of every output."""
    cpu = platform.processor() or platform.machine()
    try:
        with open("/proc/cpuinfo") as f:
            names = [line.split(":", 1)[1].strip() for line in f if line.startswith("model name")]
        cpu = names[0] if names else cpu
    except OSError:
        pass
    versions = {"python": platform.python_version(), "rodmol": rodmol.__version__}
    for name in ("numpy", "scipy", "sksundae", "numba", "matplotlib"):
        try:
            versions[name] = __import__(name).__version__
        except ImportError:
            versions[name] = "not installed"
    return dict(cpu=cpu, cores=os.cpu_count(), platform=platform.platform(),
                date=datetime.datetime.now().isoformat(timespec="seconds"), versions=versions,
                threads="OPENBLAS/MKL/OMP_NUM_THREADS=" + os.environ.get("OPENBLAS_NUM_THREADS", "?"))


def header_lines(args, script):
    m = machine()
    return [f"script: solvers/{script} (mode: {args.mode})",
            f"machine: {m['cpu']}, {m['cores']} cores, {m['platform']}",
            "packages: " + ", ".join(f"{k} {v}" for k, v in m["versions"].items()),
            f"{m['threads']}; date {m['date']}"]


def write_csv(path, rows, header):
    """rows: list of dicts (a key missing from a row leaves its cell empty); header
    lines go first as '# ...' comments."""
    with open(path, "w", newline="") as f:
        for line in header:
            f.write(f"# {line}\n")
        if rows:
            writer = csv.DictWriter(f, fieldnames=_columns(rows))
            writer.writeheader()
            writer.writerows(rows)
    return path


def _columns(rows):
    """The keys of all ``rows``, in the order they first appear."""
    return list(dict.fromkeys(key for row in rows for key in row))


def markdown_table(rows, columns=None, formats=None):
    """A Markdown table of dict rows; ``formats`` maps a column to a format spec."""
    if not rows:
        return "(no rows)\n"
    columns = columns or _columns(rows)
    formats = formats or {}

    def cell(row, c):
        v = row.get(c, "")
        if isinstance(v, float):
            return format(v, formats.get(c, ".4g"))
        return str(v)

    lines = ["| " + " | ".join(columns) + " |", "|" + "---|" * len(columns)]
    lines += ["| " + " | ".join(cell(r, c) for c in columns) + " |" for r in rows]
    return "\n".join(lines) + "\n"


def write_markdown(path, title, header, sections):
    """sections: list of (heading, text) pairs, text already Markdown."""
    with open(path, "w") as f:
        f.write(f"# {title}\n\n")
        for line in header:
            f.write(f"- {line}\n")
        for heading, text in sections:
            f.write(f"\n## {heading}\n\n{text}\n")
    return path


def write_results(args, name, title, header, rows, sections):
    """``name``.csv (``rows``) and ``name``.md (``title``, ``sections`` as for
    :func:`write_markdown`) in ``args.out``; says so and returns the common stem."""
    base = os.path.join(args.out, name)
    write_csv(base + ".csv", rows, header)
    write_markdown(base + ".md", title, header, sections)
    print(f"wrote {base}.{{csv,md}}")
    return base


def n_axis(ax, sizes):
    """Label a log N axis with the sizes themselves (no overlapping minor labels)."""
    ax.set_xticks(list(sizes))
    ax.set_xticklabels([str(int(n)) for n in sizes])
    ax.xaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())


def save_figure(fig, path):
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def initial_state(model, t=0.0, system=None):
    """The static equilibrium (the paper's start); ``system`` (a SemiDiscrete
    of ``model``) is reused if given. If the default residual tolerance
    (1e-10 of the load scale) is below the round-off floor of a fine grid,
    retry at 1e-9."""
    try:
        return rodmol.equilibrium(model if system is None else system, t)
    except rodmol.EquilibriumError:
        return rodmol.equilibrium(model if system is None else system, t, tol=1e-9)


def outputs(t_end, dt=0.01):
    """Output times 0, dt, ..., t_end (as rodmol.simulate makes them)."""
    n = int(np.floor(t_end / dt + 1e-9))
    return np.unique(np.append(np.arange(n + 1) * dt, t_end))


def tip(raw, model=None):
    """(n_t, 3) tip position [m] of a raw solution: rebuilt from the strains if
    ``model`` is given (as ``Result.tip``; use it to compare grids), else the
    time-integrated u(L), which is cheaper and fine on one grid."""
    if model is None:
        y = np.asarray(raw.y)
        return y[:, StateLayout((y.shape[1] - HEADER) // BLOCK).tip_slice("u")]
    return from_states(SemiDiscrete(model), raw.t, np.asarray(raw.y), True, "", {}).tip


def run(backend, system, y0, t_out, rtol, **options):
    """One integration; atol from rodmol's default_atol unless given."""
    atol = options.pop("atol", None)
    if atol is None:
        atol = default_atol(system.model, rtol)
    return backend(system, y0, t_out, rtol=rtol, atol=atol, **options)


def run_cpu(backend, system, y0, t_out, rtol, **options):
    """One integration (:func:`run`) and its CPU time [s] over the span of its ``wall_time_s``
    (the steps, not building the solver; :func:`_cpu_span.cpu_span`)."""
    from _cpu_span import cpu_span

    from rodmol.solve import outputs

    with cpu_span(outputs) as span:
        raw = run(backend, system, y0, t_out, rtol, **options)
    return raw, span["cpu_s"]


def timed(backend, system, y0, t_out, rtol, reps, **options):
    """Median wall time [s] of ``reps`` runs (solver only, as in its stats) and the last run."""
    walls, raw = [], None
    for _ in range(max(1, reps)):
        raw = run(backend, system, y0, t_out, rtol, **dict(options))
        walls.append(raw.stats["wall_time_s"])
    return float(np.median(walls)), raw


def timed_simulate(model, t_end, reps, **options):
    """The last of ``reps`` runs of ``rodmol.simulate`` (50 output frames) and their median
    solver wall time [s] (as in its stats)."""
    walls = []
    for _ in range(max(1, reps)):
        result = rodmol.simulate(model, t_end, output_dt=t_end / 50, **options)
        walls.append(result.stats["wall_time_s"])
    return result, float(np.median(walls))


def drift_row(run, wall, gap, reference, reference_wall, against, **fields):
    """A row of a joint's cost and drift (``gap`` over the frames, a fraction of a length): ``fields``,
    the run's reach and right-hand sides, its solver wall time ``wall`` [s], each also as a ratio
    to the ``reference`` run's (columns ``rhs_over_<against>``, ``solver_over_<against>``); printed."""
    row = dict(fields, success=run.success, t_reached_s=float(run.t[-1]), max_drift_over_L=float(gap.max()),
               end_drift_over_L=float(gap[-1]), rhs=run.stats["rhs_evals"])
    row[f"rhs_over_{against}"] = run.stats["rhs_evals"] / reference.stats["rhs_evals"]
    row.update(solver_s=wall, **{f"solver_over_{against}": wall / reference_wall})
    print({k: (f"{v:.4g}" if isinstance(v, float) else v) for k, v in row.items()}, flush=True)
    return row


def warm_up(system, y0, **options):
    """Compile (or load) the kernels a configuration uses, outside the timings."""
    t_out = np.array([0.0, 1e-3, 2e-3])
    run(cvode, system, y0, t_out, 1e-6, **options)


class Stopwatch:
    def __enter__(self):
        self.start = time.perf_counter()
        return self

    def __exit__(self, *exc):
        self.seconds = time.perf_counter() - self.start


def explicit_limits(model):
    """The paper's explicit stability limits [s]: ds / sqrt(E / rho) and ds^2 / (3 mu / rho)."""
    mat = model.rod.material
    ds = model.ds
    wave = ds / np.sqrt(mat.E / mat.rho)
    viscous = ds**2 / (3.0 * mat.mu / mat.rho) if mat.mu > 0 else np.inf
    return wave, viscous
