"""The paper's worsened-model study (Table V, Fig. 9): the full model and
three models without one ingredient, run in parallel against the same
measured markers."""

from dataclasses import dataclass

from .paper_errors import ErrorTable, plot_errors, table
from .parallel import SERIAL, check_picklable, executor
from .runs import Errors, Task
from .targets import of_spec
from .variants import apply, as_spec

#: Table V's models as overrides of the full one: mu = 0 in eq. (5), no
#: added mass (By = Bz = 0 in eq. 9), no drag (Cx = Cy = Cz = 0 in eq. 8);
#: in a system, of every rod.
VARIANTS = {
    "full model": {},
    "linear elastic": {"material.mu": 0.0},
    "no added mass": {"medium.added_mass": False},
    "no drag": {"medium.drag": False},
}


@dataclass
class Study:
    """Errors of eq. (15) (``errors[name]``, ErrorTables) and the runs
    (``outcomes[name]``, with their Results) of each model variant."""

    errors: dict
    outcomes: dict

    def table(self):
        """Table V as Markdown (errors in % of the arm length)."""
        return table(self.errors.values(), title="Model")

    def plot(self, path, title="Worsened models", overwrite=False):
        """Fig. 9 style: mean and tip errors against time for every variant (PNG); a file
        already at ``path`` is kept unless ``overwrite``."""
        return plot_errors(list(self.errors.values()), path, title, overwrite)


def worsened_models(spec, measured, *, client=None, variants=None, progress=None, n_workers=None):
    """Run the full model and the worsened ones of Table V against ``measured``.

    Parameters
    ----------
    spec : RunSpec or scenario path, a rod's or a system's (its tensions
        should be the measured ones, e.g. ``apply(spec, log.overrides())`` for
        a tension log); a system's variants change every rod
    measured : MarkerTracks or CSV path of the measured markers (global frame);
        a system's name their parts (:func:`rodmol.calibrate.identify.identify`)
    client : see :mod:`rodmol.calibrate.parallel` (None: a LocalCluster)
    variants : {name: overrides}; default :data:`VARIANTS`.
    """
    spec = as_spec(spec)
    tracks, targets = of_spec(spec, measured)
    variants = dict(VARIANTS if variants is None else variants)
    for overrides in variants.values():
        apply(spec, overrides)
    if client != SERIAL:
        check_picklable(spec)
    tasks = [(name, Task(spec, Errors(tracks, targets, name), keep=True)) for name in variants]
    with executor(client, n_workers) as ex:
        outcomes = ex.map(_run_variant, [(task, variants[name]) for name, task in tasks], progress)
    named = dict(zip(variants, outcomes))
    errors = {name: o.value if o.value is not None else ErrorTable.unknown(tracks.t, name)
              for name, o in named.items()}  # a run that failed before its first frame
    return Study(errors, named)


def _run_variant(item):
    task, overrides = item
    return task(overrides)
