"""Output cost of long runs: the README's fetching run and a 600 s run, streamed.

Each case runs ``examples/fetching.toml`` (N = 100, default settings, output
every 10 ms) in a fresh subprocess as ``rodmol run`` does (the scenario's
``simulate`` with a :class:`rodmol.output.stream.RunWriter`), after a short
warm-up run there (numba's cache). It reports the solver's own wall time
(``stats["wall_time_s"]``), the writer's (the time the run spends in the
writer: computing each chunk's stresses, loads and view arrays, handing the
chunk to the writer's thread, and waiting for it), the peak resident memory
of the subprocess and the files and bytes left. The same run without output
(``none``: the Result in memory) gives the wall time the output adds to the
whole run, ``added_s`` (the writer's thread runs beside the solver, and the
two share the machine). ``--format vtp`` cases (the old path: the whole
Result in memory, then result.npz and one .vtp per frame and part) are timed
for the README run only.
The smoke run (0.5 s, N = 10) runs the README run's cases only.

    python solvers/long_output.py [--quick | --smoke] [--out DIR]
"""

import json
import os
import subprocess
import sys
import tempfile
import textwrap
import time

import _common as C
import numpy as np

SCRIPT = "long_output.py"
FETCHING = os.path.join(os.path.dirname(C.HERE), "examples", "fetching.toml")

CHILD = textwrap.dedent("""
    import json, resource, sys, time
    sys.path.insert(0, sys.argv[1])
    import rodmol
    from rodmol.scenario.file import Override, load_scenario
    from rodmol.output.stream import RunWriter
    scenario, t_end, out, fmt = sys.argv[2], float(sys.argv[3]), sys.argv[4], sys.argv[5]
    overrides = {"solver.t_end": Override(t_end, "--t-end")}
    if sys.argv[6] != "0":
        overrides["discretization.n_elements"] = Override(int(sys.argv[6]), "--n-elements")
    spec = load_scenario(scenario, overrides=overrides)
    rodmol.simulate(spec.model, 0.02)  # compile or load the kernels: not part of the run
    started = time.perf_counter()
    if fmt == "xdmf":
        writer = RunWriter(out, overwrite=True)
        result = spec.simulate(out=writer)
        writing = writer.seconds
    elif fmt == "none":
        result, writing = spec.simulate(), 0.0
    else:
        from rodmol.output.formats import write_series
        result = spec.simulate()
        begun = time.perf_counter()
        write_series(result, out, format="vtp")
        writing = time.perf_counter() - begun
    total = time.perf_counter() - started
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0  # kB -> MB (Linux)
    from rodmol.discretise.layout import StateLayout
    print(json.dumps(dict(frames=len(result.t), success=result.success, solver_s=result.stats["wall_time_s"],
                          writing_s=writing, total_s=total, peak_rss_mb=peak, N=spec.model.n_elements,
                          state_size=StateLayout(spec.model.n_elements).size)))
""")


def run_case(t_end, fmt, n_elements=0):
    with tempfile.TemporaryDirectory(prefix="rodmol_long_") as tmp:
        out = os.path.join(tmp, "out")
        proc = subprocess.run([sys.executable, "-c", CHILD, os.path.dirname(C.HERE), FETCHING, str(t_end), out,
                               fmt, str(n_elements)], capture_output=True, text=True, timeout=7200)
        if proc.returncode != 0:
            raise RuntimeError(proc.stderr[-3000:])
        row = json.loads(proc.stdout.strip().splitlines()[-1])
        files = [os.path.join(d, f) for d, _, names in os.walk(out) for f in names]
        sizes = [os.path.getsize(f) for f in files]
        row.update(files=len(files), megabytes=sum(sizes) / 1e6,
                   raw_disk_s=raw_disk_time(sizes, tmp) if sizes else 0.0)
    return row


def raw_disk_time(sizes, folder):
    """Wall time [s] to write files of ``sizes`` bytes with plain ``write`` calls: what the
    disk alone costs for the run's bytes, with the run's own writes flushed first."""
    os.sync()
    largest = np.zeros(max(sizes), dtype=np.uint8)
    started = time.perf_counter()
    for i, size in enumerate(sizes):
        with open(os.path.join(folder, f"raw_{i}"), "wb") as handle:
            handle.write(memoryview(largest)[:size])
    elapsed = time.perf_counter() - started
    for i in range(len(sizes)):
        os.unlink(os.path.join(folder, f"raw_{i}"))
    return elapsed


def main(argv=None):
    args = C.parse_args(__doc__.splitlines()[0], argv)
    header = C.header_lines(args, SCRIPT)
    n = C.pick(args, 0, 0, 10)  # 0: the file's N = 100
    long = C.pick(args, 600.0, 60.0, None)  # the smoke run: the README run's cases only
    short = C.pick(args, 8.0, 8.0, 0.5)
    # The README run is short and its ratio noisy on a shared machine: several runs of it.
    repeats = C.pick(args, 5, 2, 1)
    cases = [(short, "vtp"), (short, "none"), *[(short, "xdmf")] * repeats]
    cases += [(long, "none"), (long, "xdmf")] if long else []
    rows, plain = [], {}
    for t_end, fmt in cases:
        row = dict(t_end_s=t_end, format=fmt, **run_case(t_end, fmt, n))
        if fmt == "none":
            plain[t_end] = row
        row["writing_over_solver"] = row["writing_s"] / row["solver_s"]
        # What the output adds to the whole run's wall time, against the solver's time without output.
        if fmt == "xdmf" and t_end in plain:
            row["added_s"] = row["total_s"] - plain[t_end]["total_s"]
            row["added_over_plain_solver"] = row["added_s"] / plain[t_end]["solver_s"]
        # The disk's share, and what the exact state history alone (float64) weighs.
        row["raw_disk_over_solver"] = row["raw_disk_s"] / row["solver_s"]
        row["states_mb"] = row["frames"] * row.pop("state_size") * 8 / 1e6
        rows.append(row)
        added = f", {row['added_s']:.2f} s added to the run" if "added_s" in row else ""
        print(f"t_end = {t_end:g} s, {fmt}: solver {row['solver_s']:.2f} s, writing {row['writing_s']:.2f} s "
              f"({row['writing_over_solver']:.2f}x{added}), peak {row['peak_rss_mb']:.0f} MB, {row['files']} files, "
              f"{row['megabytes']:.0f} MB (plain writes of as many bytes: {row['raw_disk_s']:.2f} s)", flush=True)
    C.write_results(args, "long_output", "Long runs and output (examples/fetching.toml)", header, rows,
                    [("Solver and writing wall time, peak memory, files", C.markdown_table(rows))])


if __name__ == "__main__":
    main()
