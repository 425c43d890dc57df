"""Cost of writing a long ``.vtp`` series: the ``.pvd`` collections, before and after.

Before, :class:`rodmol.output.writers.SeriesWriter` wrote its three ``.pvd``
collections anew (XML of every entry, renamed into place) every half second
of writing, O(frames^2) in all; after, it adds the new entries into room kept
in each file (:mod:`rodmol.output.pvd`), O(frames). ``Rewriting`` below is the
before: the same writer whose flush writes each collection whole, as it did.

Two cases, both policies in the same run:

* ``series``: the whole series of a small rod (``examples/uniform_arm_air.toml``,
  N = 4, a cable and markers: three parts) of a given number of frames, written
  by ``SeriesWriter`` with its half-second flushes (the least CPU time of
  ``--reps`` runs, the policies in turn); the wall and CPU time, the time spent
  in the collections (``collections_s``: the flushes and the close, what the
  policies differ by; the rest, the frame files, is the same work and on a
  shared machine mostly the other processes' load), the bytes written to the
  collections and how many times one was written whole;
* ``collections``: the collections alone (the frame files not written, so that
  60,001 frames need no 800 MB of ``.vtp``), flushed every F frames, F the
  frames the ``series`` case writes in half a second: what the collections cost
  a run of that length; ``estimated_total_s`` adds the frame files' measured
  cost per frame (the ``series`` case's wall time less its collections').

    python solvers/vtp_series_cost.py [--quick | --smoke] [--out DIR]
"""

import os
import tempfile
import time
import xml.etree.ElementTree as ET
from pathlib import Path
from types import SimpleNamespace

import _common as C
import numpy as np

SCRIPT = "vtp_series_cost.py"
ARM = os.path.join(os.path.dirname(C.HERE), "examples", "uniform_arm_air.toml")


def rewriting_writer():
    """The writer of before: every flush writes each collection whole (XML, renamed into place)."""
    from rodmol._files import write_atomically
    from rodmol.output.writers import SeriesWriter

    class Rewriting(SeriesWriter):
        def __init__(self, *args, **kwargs):
            super().__init__(*args, **kwargs)
            self.rewrites, self.pvd_bytes = 0, 0

        def flush(self):
            for part, collection in self.collections.items():
                collection.entries += collection.queued
                collection.queued = []
                root = ET.Element("VTKFile", type="Collection", version="0.1", byte_order="LittleEndian")
                listed = ET.SubElement(root, "Collection")
                for t, file in collection.entries:
                    ET.SubElement(listed, "DataSet", timestep=repr(float(t)), group="", part="0", file=str(file))
                ET.indent(root)
                write_atomically(self.pvd(part), lambda handle, root=root: ET.ElementTree(root).write(
                    handle, encoding="utf-8", xml_declaration=True))
                self.rewrites += 1
                self.pvd_bytes += self.pvd(part).stat().st_size
            self.flushed = time.monotonic()

        close = flush

    return Rewriting


def counts(writer):
    """(bytes written to the collections, times one was written whole) of a finished writer."""
    if hasattr(writer, "rewrites"):
        return writer.pvd_bytes, writer.rewrites
    collections = writer.collections.values()
    return sum(c.written for c in collections), sum(c.rewrites for c in collections)


def small_run(frames):
    """A Result of the small rod with ``frames`` output frames (its frames repeated past the
    run's end: the cost of writing one does not depend on its values)."""
    model = C.rodmol.load_scenario(ARM).model.replace(n_elements=4)
    result = C.rodmol.simulate(model, 0.2, output_dt=0.01)
    run = result.select(np.arange(frames) % len(result.t))
    run.t = 0.001 * np.arange(frames)  # distinct times for the collections
    return run


def timed(policy):
    """``policy`` (a writer class) that adds the time [s] spent in its collections (its flushes
    and its close) up in ``collections_s``."""

    class Timed(policy):
        collections_s = 0.0

        def flush(self):
            started = time.perf_counter()
            super().flush()
            self.collections_s += time.perf_counter() - started

        def close(self):
            started = time.perf_counter()
            super().close()
            self.collections_s += time.perf_counter() - started

    return Timed


def write_series(policy, result, folder):
    """Write ``result``'s frames with ``policy`` (flushing every half second) into ``folder``;
    returns (wall [s], CPU [s], writer)."""
    started, cpu = time.perf_counter(), time.process_time()
    with timed(policy).for_result(result, folder) as writer:
        for k in range(len(result.t)):
            writer.write(result, k)
    return time.perf_counter() - started, time.process_time() - cpu, writer


def collections_only(policy, frames, flush_every, parts):
    """The collections of ``frames`` frames of ``parts`` alone (no frame files), flushed every
    ``flush_every`` frames: (wall [s], CPU [s], writer)."""
    from rodmol.output import writers

    saved = writers.save_vtp, dict(writers.MESHES)
    writers.save_vtp = lambda mesh, path: None
    writers.MESHES.update({part: (lambda result, k: None) for part in writers.MESHES})
    try:
        run = SimpleNamespace(t=0.001 * np.arange(frames), meta={})
        with tempfile.TemporaryDirectory(prefix="rodmol_pvd_") as tmp:
            started, cpu = time.perf_counter(), time.process_time()
            with policy(tmp, parts, flush_interval=float("inf")) as writer:
                for k in range(frames):
                    writer.write(run, k)
                    if (k + 1) % flush_every == 0:
                        writer.flush()
            return time.perf_counter() - started, time.process_time() - cpu, writer
    finally:
        writers.save_vtp = saved[0]
        writers.MESHES.clear()
        writers.MESHES.update(saved[1])


def measured(name, wall, cpu, writer, frames):
    """One policy's columns of a row."""
    written, whole = counts(writer)
    return {f"{name}_s": wall, f"{name}_cpu_s": cpu, f"{name}_ms_per_frame": 1e3 * wall / frames,
            f"{name}_pvd_mb": written / 1e6, f"{name}_whole_writes": whole}


def main(argv=None):
    args = C.parse_args(__doc__.splitlines()[0], argv)
    header = C.header_lines(args, SCRIPT)
    from rodmol.output.writers import SeriesWriter

    policies = {"before": rewriting_writer(), "after": SeriesWriter}
    rows, per_frame, parts = [], None, None
    for frames in C.pick(args, [1000, 10000], [1000, 5000], [200]):
        result = small_run(frames)
        row, best = dict(case="series", frames=frames), {}
        for _ in range(args.reps):  # the policies in turn, the least CPU of each kept: a shared machine's load
            for name, policy in policies.items():
                with tempfile.TemporaryDirectory(prefix="rodmol_vtp_") as tmp:
                    run = write_series(policy, result, Path(tmp))
                best[name] = min(best.get(name, run), run, key=lambda found: found[1])
        for name, (wall, cpu, writer) in best.items():
            row.update(measured(name, wall, cpu, writer, frames), **{f"{name}_collections_s": writer.collections_s})
        # the frame files' own cost per frame, for the cadence and the estimates below
        per_frame, parts = (best["after"][0] - best["after"][2].collections_s) / frames, best["after"][2].parts
        row["collections_before_over_after"] = row["before_collections_s"] / row["after_collections_s"]
        rows.append(row)
        print(f"series of {frames} frames: in the collections before {row['before_collections_s']:.2f} s, "
              f"after {row['after_collections_s']:.3f} s (all: {row['before_s']:.1f} s, {row['after_s']:.1f} s)",
              flush=True)
    flush_every = max(1, round(0.5 / per_frame))  # frames a half second of writing holds
    for frames in C.pick(args, [1000, 10000, 60001], [1000, 10000, 20000], [200, 1000]):
        row = dict(case="collections", frames=frames, flush_every_frames=flush_every)
        for name, policy in policies.items():
            wall, cpu, writer = collections_only(policy, frames, flush_every, parts)
            row.update(measured(name, wall, cpu, writer, frames),
                       **{f"{name}_estimated_total_s": wall + per_frame * frames})
        row["collections_before_over_after"] = row["before_s"] / row["after_s"]
        rows.append(row)
        print(f"collections of {frames} frames: before {row['before_s']:.2f} s, after {row['after_s']:.3f} s",
              flush=True)
    C.write_results(args, "vtp_series_cost", "Writing a .vtp series: the .pvd collections before and after",
                    header, rows, [("Wall and CPU time, time in the collections, bytes written to them and "
                                    "whole writes, by frames", C.markdown_table(rows))])


if __name__ == "__main__":
    main()
