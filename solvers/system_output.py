"""Writing a system's streamed run: the cost of a chunk against the run's length, before and after
``system.h5`` became an index of chunk files.

Two cable-driven arms (N = 30 each) on a free head, the system of
docs/systems.md's example, streamed by
:class:`rodmol.output.system_stream.SystemRunWriter` in chunks of
``--chunk`` frames (the sink protocol of :func:`rodmol.solve.chunked.run_chunked`:
``begin``, ``frames`` per chunk, ``end``), fed the same state at every
frame, so that only the writing is timed: each rod's files (a single rod's
writer, the same in both versions) and the system's own (``system.h5``,
``bodies.xdmf`` and, after, the chunk files). The old version (``--commit``,
default the last commit before the change, exported by ``git archive`` into
a kept folder, ``_common.package_tree``) rewrote ``system.h5`` whole at every chunk, holding
every frame so far; the new one writes each chunk once and a small index.
Each version runs in its own subprocess, with PYTHONPATH at its tree, after
a warm-up (numba's compilation).

Reported per version: the wall time of ``frames`` for the first chunks and
the last, their ratio (flat: a chunk costs the same however long the run),
the same for the system's own files alone (``system_*``: from the moment
the rods' chunks are on disk to the end of ``frames``), the whole run's
writing time, the size of ``system.h5`` (rewritten at every chunk) after
the first chunk and at the end, and the peak resident memory. The times
are the least over a window of chunks (10 at first, 10 at the end): the
machine is shared, and other jobs only add time.

    python solvers/system_output.py [--quick | --smoke] [--out DIR] [--commit REV] [--chunk N]
"""

import json
import os
import subprocess
import sys
import tempfile
import textwrap

from core_speed import split_option

SCRIPT = "system_output.py"
OLD_COMMIT = "06aa966"
HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)

CHILD = textwrap.dedent("""
    import json, resource, sys, time
    sys.path.insert(0, sys.argv[1])
    import numpy as np
    import rodmol
    from rodmol.discretise.assembly import Assembly
    from rodmol.output.system_stream import SystemRunWriter
    out, n_chunks, chunk = sys.argv[2], int(sys.argv[3]), int(sys.argv[4])
    material = rodmol.Material(E=1e5, nu=0.5, mu=300.0, rho=1080.0)
    rod = rodmol.Rod(0.2, radius=(0.012, 0.006), material=material)
    def arm(side):
        pull = rodmol.Cable((side * 0.005, 0.0), 0.2, tension=lambda t: 0.3 * min(t / 0.1, 1.0))
        return rodmol.Model(rod, 30, cables=[pull])
    head = rodmol.RigidBody(mass=0.3, inertia=(2e-4, 2e-4, 2e-4), volume=2.5e-4)
    turn = np.diag([-1.0, -1.0, 1.0])
    system = rodmol.System(rods={"right": arm(1.0), "left": arm(-1.0)}, bodies={"head": head},
                           joints=[rodmol.Joint(("head", (0.04, 0.0, 0.0)), ("right", "base")),
                                   rodmol.Joint(("head", (-0.04, 0.0, 0.0), turn), ("left", "base"))],
                           medium="water", gravity=(0.0, 0.0, -9.81))
    rodmol.simulate(system, 0.02, out=out + "_warm")  # compile or load the kernels, writing's too: not timed
    assembly = Assembly(system)
    y0 = assembly.undeformed_state()
    t_out = 0.01 * np.arange(n_chunks * chunk + 1)
    writer = SystemRunWriter(out, chunk_frames=chunk, overwrite=True)
    writer.begin(assembly, t_out)
    rods_done, flush = [], writer.flush  # frames() flushes the rods' writers, then writes the system's files
    writer.flush = lambda: (flush(), rods_done.append(time.perf_counter()))
    seconds, system, index, k = [], [], [], 0
    while k < len(t_out) - 1:
        stop = min((k // chunk + 1) * chunk, len(t_out) - 1)
        frames = np.arange(k if k == 0 else k + 1, stop + 1)
        started = time.perf_counter()
        writer.frames(t_out[frames], np.tile(y0, (len(frames), 1)))
        seconds.append(time.perf_counter() - started)
        system.append(time.perf_counter() - rods_done[-1])
        index.append(__import__("os").path.getsize(out + "/system.h5"))
        k = stop
    started = time.perf_counter()
    writer.end(True, "done", {})
    ending = time.perf_counter() - started
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0  # kB -> MB (Linux)
    print(json.dumps(dict(seconds=seconds, system_s=system, index_bytes=index, end_s=ending, peak_rss_mb=peak,
                          state_size=int(assembly.size))))
""")


def measure(tree, out, n_chunks, chunk):
    proc = subprocess.run([sys.executable, "-c", CHILD, tree, out, str(n_chunks), str(chunk)],
                          capture_output=True, text=True, timeout=3600)
    if proc.returncode != 0:
        raise RuntimeError(proc.stderr[-3000:])
    return json.loads(proc.stdout.strip().splitlines()[-1])


def main(argv=None):
    argv, commit = split_option(sys.argv[1:] if argv is None else list(argv), "commit", OLD_COMMIT)
    argv, chunk = split_option(argv, "chunk", "20")
    import _common as C

    args = C.parse_args(__doc__.splitlines()[0], argv)
    chunk = int(chunk)
    n_chunks = C.pick(args, 80, 30, 4)
    window = max(1, min(10, n_chunks // 4))
    rows = []
    with tempfile.TemporaryDirectory(prefix="rodmol_system_output_") as tmp:
        # The smoke run skips the old version: a first extraction of its tree compiles every kernel again.
        old_tree, sha = (None, None) if args.smoke else C.package_tree(commit)
        versions = [("new", ROOT)] if args.smoke else [("old", old_tree), ("new", ROOT)]
        for label, tree in versions:
            r = measure(tree, os.path.join(tmp, f"out_{label}"), n_chunks, chunk)
            s, own, size = (C.np.asarray(r[key]) for key in ("seconds", "system_s", "index_bytes"))
            # The least of a window of chunks: the machine is shared, and other jobs only add time.
            first, last = float(s[1:1 + window].min()), float(s[-window:].min())
            own_first, own_last = float(own[1:1 + window].min()), float(own[-window:].min())
            rows.append(dict(version=label, state_size=r["state_size"], chunks=len(s), frames=n_chunks * chunk + 1,
                             first_chunks_ms=1e3 * first, last_chunks_ms=1e3 * last, last_over_first=last / first,
                             system_first_ms=1e3 * own_first, system_last_ms=1e3 * own_last,
                             system_last_over_first=own_last / own_first,
                             index_first_kb=size[0] / 1e3, index_last_kb=size[-1] / 1e3,
                             writing_s=float(s.sum() + r["end_s"]), system_writing_s=float(own.sum()),
                             peak_rss_mb=r["peak_rss_mb"]))
            print(f"{label}: a chunk {1e3 * first:.1f} ms at first, {1e3 * last:.1f} ms at the end "
                  f"({last / first:.2f}x; the system's own files {1e3 * own_first:.1f} and {1e3 * own_last:.1f} ms); "
                  f"writing {rows[-1]['writing_s']:.2f} s; system.h5 {size[0] / 1e3:.0f} kB after the first chunk, "
                  f"{size[-1] / 1e3:.0f} kB at the end; peak {r['peak_rss_mb']:.0f} MB", flush=True)
    header = C.header_lines(args, SCRIPT) + [
        "old: not measured (smoke run)" if sha is None else f"old: {sha[:10]} (git archive); new: the working tree",
        f"two arms (N = 30 each) on a free head; {n_chunks} chunks of {chunk} frames, the same state at every "
        f"frame; first: least over chunks 2..{1 + window}, last: over the last {window}"]
    C.write_results(args, "system_output", "Writing a system's run: a chunk's cost against the run's length",
                    header, rows, [("Per-chunk writing time, old (system.h5 rewritten whole) and new (chunk files)",
                                    C.markdown_table(rows))])


if __name__ == "__main__":
    main()
