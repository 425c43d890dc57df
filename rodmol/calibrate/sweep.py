"""Batch runs of one scenario over a list or a grid of dotted overrides."""

import contextlib
import csv
import itertools
from dataclasses import dataclass
from functools import partial
from pathlib import Path

from .._files import OVERWRITE, claim, output_directory
from ..errors import ParameterError
from ..output import run_files
from .parallel import SERIAL, check_picklable, executor
from .runs import OVERRIDES, RUN_FILES, Summary, Task, failed_item, run_indexed
from .targets import of_spec
from .variants import apply, as_spec


def grid(axes):
    """Every combination of ``axes`` ({dotted key: list of values}), as a list of overrides."""
    keys = list(axes)
    values = [list(axes[k]) for k in keys]
    if any(not v for v in values):
        raise ParameterError(f"every grid axis needs at least one value, got {axes!r}")
    return [dict(zip(keys, combination)) for combination in itertools.product(*values)]


@dataclass
class Sweep:
    """The runs of a sweep (:class:`rodmol.calibrate.runs.Outcome`, in the order
    of the overrides): ``runs[i].result`` is the Result of run i and
    ``runs[i].value`` its summary row."""

    runs: list
    out: object = None

    def result(self, i):
        """The Result of run ``i``: kept in memory, or read from ``out``."""
        run = self.runs[i]
        if run.result is None and (run.value or {}).get("path"):
            from ..output.formats import load_result

            return load_result(run.value["path"])
        return run.result

    def rows(self):
        """One dict per run: index, overrides, success, wall time [s] and the summary."""
        rows = []
        for i, run in enumerate(self.runs):
            row = dict(index=i, **{k: v for k, v in run.overrides.items()}, success=run.success,
                       wall_s=round(run.wall, 3))
            row.update(run.value or {})
            if not run.success:
                row["message"] = run.message
            rows.append(row)
        return rows

    def table(self):
        """The summary as a Markdown table."""
        rows = self.rows()
        columns = list(dict.fromkeys(k for r in rows for k in r))
        lines = ["| " + " | ".join(columns) + " |", "|" + "---|" * len(columns)]
        lines += ["| " + " | ".join(_cell(r.get(c, "")) for c in columns) + " |" for r in rows]
        return "\n".join(lines)

    def write(self, directory, overwrite=False):
        """Write summary.csv and summary.md to ``directory``; returns their paths. Earlier
        ones there are kept unless ``overwrite`` (:func:`rodmol._files.claim`)."""
        directory = output_directory(directory, "directory")
        claim([directory / name for name in SUMMARY], overwrite)
        rows = self.rows()
        columns = list(dict.fromkeys(k for r in rows for k in r))
        with open(directory / "summary.csv", "w", newline="", encoding="utf-8") as handle:
            writer = csv.DictWriter(handle, columns)
            writer.writeheader()
            writer.writerows(rows)
        (directory / "summary.md").write_text(self.table() + "\n", encoding="utf-8")
        return directory / "summary.csv", directory / "summary.md"


#: The files of a sweep's summary in its directory.
SUMMARY = ("summary.csv", "summary.md")


def outputs(directory):
    """The files a sweep wrote in ``directory``: its summary and every run's result."""
    directory = Path(directory)
    systems = sorted(directory.glob(str(Path(RUN_FILES).parent / OVERRIDES)))  # a system's run each
    return [directory / name for name in SUMMARY] + sorted(directory.glob(RUN_FILES)) + systems


def claim_outputs(directory, overwrite, hint=OVERWRITE):
    """Before a sweep into ``directory``: refuse an earlier sweep's files there unless
    ``overwrite``, which removes them (and the runs' folders they leave empty)."""
    directory = output_directory(directory, "out")
    for path in claim(outputs(directory), overwrite, hint):
        if path.name == OVERRIDES:  # beside a system's run
            run_files.clear(path.parent)
        if path.name not in SUMMARY:
            with contextlib.suppress(OSError):  # holds files not the sweep's
                path.parent.rmdir()


def _cell(value):
    return f"{value:.6g}" if isinstance(value, float) else str(value)


def sweep(spec, overrides, *, client=None, out=None, measured=None, keep=None, progress=None,
          n_workers=None, overwrite=False):
    """Run ``spec`` once per set of ``overrides`` (a list of {dotted key: value}
    dicts, e.g. from :func:`grid`), in parallel on dask (see
    :mod:`rodmol.calibrate.parallel` for ``client``).

    Every override is checked before any run. With ``out``, each run's result
    goes to ``out/run_<i>/result.npz`` (a system's: its run directory
    ``out/run_<i>/``, with ``overrides.json``) and the summary to
    ``out/summary.csv`` and ``summary.md``; an earlier sweep's files there
    (:func:`outputs`) are kept: refused before any run unless ``overwrite=True``,
    which removes them all first. ``measured`` (marker tracks; a system's name
    their parts, :mod:`rodmol.calibrate.targets`) adds the averages of
    eq. (15) to the summary. ``keep`` brings every Result back to this process
    (default: only without ``out``; a Result ships its raw states, about
    size x n_t x 8 bytes). ``progress(done, total)`` is called as runs end.
    Returns a :class:`Sweep`.
    """
    spec = as_spec(spec)
    overrides = [dict(o) for o in overrides]
    if not overrides:
        raise ParameterError("a sweep needs at least one set of overrides ({} is the unchanged run)")
    for o in overrides:
        apply(spec, o)  # checks every key and value before the first run
    if client != SERIAL:
        check_picklable(spec)
    tracks, targets = of_spec(spec, measured) if measured is not None else (None, None)
    if out is None and overwrite:
        raise ParameterError("`overwrite=True` needs `out`, the directory of the sweep")
    if out is not None:
        claim_outputs(out, overwrite)
    task = Task(spec, Summary(tracks, targets), keep=out is None if keep is None else bool(keep))
    folder = None if out is None else str(Path(out).resolve())
    items = [(i, o, folder) for i, o in enumerate(overrides)]
    with executor(client, n_workers) as ex:
        runs = ex.map(partial(run_indexed, task), items, progress, failed=failed_item)
    result = Sweep(runs, out)
    if out is not None:
        result.write(out)
    return result
