"""One run of a scenario with overrides, as a task a worker executes, and
what it sends back (:class:`Outcome`). Everything here pickles: the task and
its extractors are module-level classes holding plain data."""

import json
import time
import warnings
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from ..result import Result
from .paper_errors import errors_of
from .variants import apply


@dataclass
class Outcome:
    """A run's overrides, whether it reached its end (``success``, ``message``),
    its wall time [s] and solver statistics, what the task extracted
    (``value``) and the Result (None if not kept)."""

    overrides: dict
    success: bool
    message: str
    wall: float
    stats: dict = field(default_factory=dict)
    value: object = None
    result: object = None


@dataclass(frozen=True)
class Task:
    """Run ``spec`` with one set of overrides and apply ``extract(result, spec)``.

    ``keep`` returns the Result too (it pickles as its raw states: the
    client computes what it reads from it). ``options``: (name, value) pairs of
    :func:`rodmol.simulate`'s options for the run (e.g. its ``sensitivities``).
    """

    spec: object
    extract: object = None
    keep: bool = True
    options: tuple = ()

    def __call__(self, overrides):
        started = time.perf_counter()
        try:
            spec = apply(self.spec, overrides)  # the batch checked the overrides; a run may still refuse
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", RuntimeWarning)  # the outcome carries the message
                result = spec.simulate(**dict(self.options))
            value = self.extract(result, spec) if self.extract is not None else None
        # No equilibrium, absurd values, a user function that raised: this run failed, not the batch.
        except Exception as exc:  # noqa: BLE001
            return failed_run(overrides, exc, time.perf_counter() - started)
        return Outcome(dict(overrides), result.success, result.message, time.perf_counter() - started,
                       dict(result.stats), value, result if self.keep else None)


def failed_run(overrides, exc, wall=0.0):
    """The :class:`Outcome` of a run that raised ``exc`` (or whose worker died every
    time it ran it, ``distributed``'s KilledWorker): failed, with the exception as its message."""
    return Outcome(dict(overrides), False, f"{type(exc).__name__}: {exc}", wall)


@dataclass(frozen=True)
class MarkersAt:
    """The simulated markers (n_t, n_markers, 3) [m] at ``times`` [s], linearly
    interpolated; NaN after the end of a run that stopped early. ``targets``
    (:class:`rodmol.calibrate.targets.Targets`) picks them: a system's parts;
    None, a single rod's markers."""

    times: np.ndarray
    targets: object = None

    def __call__(self, result, spec):
        markers = result.markers if self.targets is None else self.targets.markers(result)
        out = np.full((len(self.times),) + markers.shape[1:], np.nan)
        if len(result.t) < 2:
            return out
        inside = self.times <= result.t[-1] + 1e-12
        flat = markers.reshape(len(result.t), -1)
        sim = np.stack([np.interp(self.times[inside], result.t, col) for col in flat.T], axis=1)
        out[inside] = sim.reshape((int(np.sum(inside)),) + markers.shape[1:])
        return out


@dataclass(frozen=True)
class MarkersAndSlopes:
    """:class:`MarkersAt`'s markers and, for each parameter of ``keys`` (a run with
    those ``sensitivities``), their derivative by it, the same way: (markers,
    {key: d markers / d key}) [m, m per unit of the key]."""

    times: np.ndarray
    targets: object = None
    keys: tuple = ()

    def __call__(self, result, spec):
        at = MarkersAt(self.times, self.targets)
        return at(result, spec), {key: at(result.sensitivity(key), spec) for key in self.keys}


@dataclass(frozen=True)
class Errors:
    """The errors of eq. (15) against ``measured`` (MarkerTracks of the parts
    ``targets``, :func:`rodmol.calibrate.targets.of_spec`), named ``name``."""

    measured: object
    targets: object
    name: str = ""

    def __call__(self, result, spec):
        return errors_of(self.targets.view(result), self.measured, name=self.name)


@dataclass(frozen=True)
class Summary:
    """A sweep run's summary row: end time, steps (if counted), final tip position [m]
    (global) and the tip's largest travel [m] (a system's: of each rod,
    ``<rod>.tip_x`` ..., and each body's origin, ``<body>.x`` ...); with
    ``measured`` (MarkerTracks of the parts ``targets``), the time averages
    of eq. (15)."""

    measured: object = None
    targets: object = None

    def __call__(self, result, spec):
        row = dict(t_end=float(result.t[-1]) if len(result.t) else 0.0)
        if "steps" in result.stats:  # (a system's CVODE run does not count them)
            row["steps"] = int(result.stats["steps"])
        if len(result.t):
            if isinstance(result, Result):
                row.update(_travel(result.tip, "tip_"))
            else:
                for name in spec.model.given_rods:
                    row.update(_travel(result[name].tip, f"{name}.tip_"))
                for name in spec.model.given_bodies:
                    row.update(_travel(result[name].position, f"{name}."))
        if self.measured is not None:
            errors = errors_of(self.targets.view(result), self.measured)
            row.update(mean_error=errors.mean_average, tip_error=errors.tip_average)
        return row


#: Where a batch's run ``i`` is saved in its directory: ``run_<i>/result.npz`` (a glob of them all).
RUN_FILES = "run_[0-9][0-9][0-9][0-9]*/result.npz"


def run_file(out, index):
    """The path of run ``index``'s result in the directory ``out`` (one of :data:`RUN_FILES`)."""
    return Path(out) / f"run_{index:04d}" / "result.npz"
#: Beside a system's run in a batch's directory (``run_<i>/``, a run directory): its overrides.
OVERRIDES = "overrides.json"


def _travel(path, prefix):
    """The final position of a path (n_t, 3) [m] and its largest distance from the start, named ``prefix`` + x ..."""
    return {f"{prefix}x": float(path[-1, 0]), f"{prefix}y": float(path[-1, 1]), f"{prefix}z": float(path[-1, 2]),
            f"{prefix}travel": float(np.max(np.linalg.norm(path - path[0], axis=1)))}


def run_indexed(task, item):
    """``task(overrides)`` for ``item = (index, overrides, out)``; saves the result
    to ``out/run_<index>/result.npz`` when ``out`` is set (module level so it pickles)."""
    index, overrides, out = item
    outcome = (task if out is None else replace(task, keep=True))(overrides)
    if out is not None and outcome.result is not None:
        path = run_file(out, index)
        path.parent.mkdir(parents=True, exist_ok=True)
        given = {k: repr(v) for k, v in overrides.items()}
        if isinstance(outcome.result, Result):
            outcome.result.meta.update(overrides=given)
            outcome.result.save(path)  # the sweep claimed its directory (rodmol.calibrate.sweep)
        else:  # a system's run directory (rodmol.load_result reads it), its overrides beside it
            from ..output.formats import write_series

            write_series(outcome.result, path.parent)
            (path.parent / OVERRIDES).write_text(json.dumps(given, indent=1), encoding="utf-8")
            path = path.parent
        outcome.value = dict(outcome.value or {}, path=str(path))
        if not task.keep:
            outcome.result = None  # read back from the file when needed
    return outcome


def failed_item(item, exc):
    """:func:`failed_run` for an ``item`` of :func:`run_indexed` (the executors' ``failed``)."""
    return failed_run(item[1], exc)
