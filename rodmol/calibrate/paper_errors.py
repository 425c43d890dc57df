"""The paper's evaluation: the errors of eq. (15) over time, their time
averages (Table IV, with the actuated phase) and the Fig. 8/9-style plots."""

from dataclasses import dataclass

import numpy as np

from .._files import claim
from ..analysis import marker_errors
from ..errors import ParameterError
from .measured import as_tracks  # noqa: F401 (its home before measured)
from .targets import of_result

#: A sample belongs to the actuated phase when the total cable tension
#: exceeds this fraction of its maximum (the paper's "actuated part" of the
#: bending test: while the cable pulls).
ACTUATED_FRACTION = 0.05


@dataclass(frozen=True)
class ErrorTable:
    """Errors of eq. (15) of one run against measured markers.

    ``t`` [s] are the measurement times, ``tip`` e_t(t) and ``mean`` e_m(t)
    (fractions of the arm length; NaN where a marker is missing or the run
    stopped early), ``actuated`` marks the samples of the actuated phase.
    """

    t: np.ndarray
    tip: np.ndarray
    mean: np.ndarray
    actuated: np.ndarray
    name: str = ""

    @classmethod
    def unknown(cls, t, name=""):
        """The table of a run that gave no frame at all: NaN at every time ``t`` [s]."""
        nan = np.full(len(t), np.nan)
        return cls(np.asarray(t, dtype=float), nan, nan.copy(), np.ones(len(t), bool), name)

    @property
    def tip_average(self):
        return _average(self.tip)

    @property
    def mean_average(self):
        return _average(self.mean)

    @property
    def actuated_tip_average(self):
        return _average(self.tip[self.actuated])

    @property
    def actuated_mean_average(self):
        return _average(self.mean[self.actuated])

    def row(self):
        """The Table IV row: time averages over the whole test and the actuated phase."""
        return dict(name=self.name, mean=self.mean_average, tip=self.tip_average,
                    actuated_mean=self.actuated_mean_average, actuated_tip=self.actuated_tip_average)


def _average(values):
    values = values[np.isfinite(values)]
    return float(np.mean(values)) if len(values) else float("nan")


def paper_errors(result, measured, times=None, actuated=None, name=""):
    """eq. (15) over time and its time averages (Table IV).

    Parameters
    ----------
    result : Result or SystemResult
        Its markers, in order, are compared with the measured ones; the
        last is the tip (the paper's order L1, L2, L3, L). A system's: the
        parts the measurement names (:mod:`rodmol.calibrate.targets`),
        distances in fractions of its longest rod.
    measured : MarkerTracks, CSV path or array (n_t, n_markers, 3) [m], global;
        a system's: MarkerTracks with their ``part``, or {part: tracks or path}
    times : (n_t,) [s], for an array ``measured``.
    actuated : None, (t_start, t_end) [s] or a boolean array (n_t,)
        The actuated phase; None: where the run's total cable tension exceeds
        ``ACTUATED_FRACTION`` of its maximum.
    """
    tracks, targets = of_result(result, measured, times)
    return errors_of(targets.view(result), tracks, actuated, name)


def errors_of(result, tracks, actuated=None, name=""):
    """:func:`paper_errors` of ``result`` (a Result, or a view of the parts
    measured: :meth:`rodmol.calibrate.targets.Targets.view`) against ``tracks``."""
    if tracks.xyz.shape[1] != result.markers.shape[1]:
        raise ParameterError(f"the measurement has {tracks.xyz.shape[1]} markers, the run "
                             f"{result.markers.shape[1]}")
    t = tracks.t
    tip, mean = np.full(len(t), np.nan), np.full(len(t), np.nan)
    inside = (t >= result.t[0] - 1e-12) & (t <= result.t[-1] + 1e-12) if len(result.t) else t < t[0]
    if np.any(inside):
        errors = marker_errors(result, tracks.xyz[inside], t[inside])
        tip[inside], mean[inside] = errors.tip, errors.mean
    return ErrorTable(t, tip, mean, _actuated(result, t, actuated), name)


def _actuated(result, t, actuated):
    if actuated is None:
        total = np.sum(result.tensions, axis=1) if result.tensions.size else np.zeros(len(result.t))
        if not len(total) or total.max() <= 0.0:
            return np.ones(len(t), dtype=bool)
        return np.interp(t, result.t, total) > ACTUATED_FRACTION * total.max()
    if isinstance(actuated, tuple) and len(actuated) == 2:
        return (t >= actuated[0]) & (t <= actuated[1])
    mask = np.asarray(actuated, dtype=bool)
    if mask.shape != t.shape:
        raise ParameterError(f"`actuated` must be (t_start, t_end) or {len(t)} booleans, got {actuated!r}")
    return mask


def table(rows, title="Model"):
    """A Markdown table of ErrorTables (Table IV/V style), errors in % of L."""
    lines = [f"| {title} | mean error | tip error | mean (actuated) | tip (actuated) |",
             "|---|---:|---:|---:|---:|"]
    for e in rows:
        r = e.row()
        lines.append(f"| {r['name']} | {100 * r['mean']:.2f}% | {100 * r['tip']:.2f}% | "
                     f"{100 * r['actuated_mean']:.2f}% | {100 * r['actuated_tip']:.2f}% |")
    return "\n".join(lines)


def plot_errors(tables, path, title=None, overwrite=False):
    """Mean and tip errors [% of L] against time, one line per ErrorTable
    (Fig. 8 style for one run, Fig. 9 style for the worsened models); PNG. A file
    already at ``path`` is kept unless ``overwrite`` (:func:`rodmol._files.claim`)."""
    claim([path], overwrite)
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(2, 1, figsize=(7, 5), sharex=True)
    for e in tables:
        axes[0].plot(e.t, 100 * e.mean, label=e.name or None)
        axes[1].plot(e.t, 100 * e.tip, label=e.name or None)
    axes[0].set_ylabel("mean error e_m [% L]")
    axes[1].set_ylabel("tip error e_t [% L]")
    axes[1].set_xlabel("t [s]")
    for ax in axes:
        ax.grid(alpha=0.3)
    if any(e.name for e in tables):
        axes[0].legend(loc="upper left", fontsize="small")
    if title:
        axes[0].set_title(title)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path
