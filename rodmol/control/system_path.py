"""Inverse statics of a :class:`rodmol.System` along a path of targets: each target
solved from the last one's inputs and equilibrium (continuation), as a rod's
:func:`rodmol.inverse_statics_path`."""

import numpy as np

from .. import _checks
from ..discretise.schemes import DEFAULT_SCHEME
from ..errors import ParameterError
from ._fitting import REACH_TOLERANCE
from .system_statics import SystemProblem
from .system_targets import SystemTargets, path_steps

#: The options of :func:`fit_system_path` besides its targets.
PATH_OPTIONS = ("bounds", "cables", "insertions", "driven", "travel", "t", "tol", "direction_weight", "start",
                "scheme", "max_iter")


def fit_system_path(system, tips=None, *, directions=None, poses=None, bounds=(0.0, np.inf), cables=None,
                    insertions=None, driven=None, travel=None, t=0.0, tol=REACH_TOLERANCE, direction_weight=None,
                    start=None, scheme=DEFAULT_SCHEME, max_iter=50):
    """:func:`fit_system` along a sequence of n targets, each from the solution of the
    one before (its inputs and its equilibrium): continuation along a path.

    Parameters
    ----------
    system : System
    tips, directions : dict, optional
        Rod name -> (n, 3) array: its tip's target positions [m] / its tip tangent's
        target directions, global, one row per target.
    poses : dict, optional
        Body name -> n poses, each a position (3,) [m] or (position, rotation (3, 3)),
        global (an (n, 3) array: positions). At least one of the three; every
        sequence of the same length n.
    bounds, cables, insertions, driven, travel, t, tol, direction_weight, scheme, max_iter
        As for :func:`fit_system` (``max_iter`` >= 1).
    start : (n_inputs,) array, optional
        The first target's initial inputs.

    Returns
    -------
    list of SystemFit
        One per target. Every target is checked before any equilibrium is solved.
    """
    tol = _checks.positive("tol", tol, " m")
    max_iter = _checks.integer_at_least("max_iter", max_iter, 1)
    problem = SystemProblem(system, cables, insertions, driven, bounds, travel, t, scheme)
    targets = []
    for k, step in enumerate(path_steps(system, tips, directions, poses)):
        try:
            targets.append(SystemTargets(system, problem.assembly, step["tip"], step["direction"], None,
                                         step["pose"], direction_weight, 1.0))
        except ParameterError as exc:
            raise ParameterError(f"target {k} of the path: {exc}") from None
    inputs = problem.start(start)
    problem.check_held()
    fits = []
    for aimed in targets:
        fits.append(problem.fit(aimed, inputs, tol, max_iter))
        inputs = fits[-1].values
    return fits
