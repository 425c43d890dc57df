"""Getting the compiled kernels ready before a run, so the wait is announced
and not booked as integration time.

numba compiles each kernel on its first call (several seconds in a fresh
install) and later processes load the machine code from the disk cache
(well under a second). :func:`prepare` makes those first calls on the run's
own system, once per process.
"""

import contextlib

import numpy as np

from .watch import state_problem

_prepared = False


def ready():
    """True once :func:`prepare` has run in this process."""
    return _prepared


def prepare(system, t, y):
    """Call every kernel a run uses once (right-hand side, Jacobian,
    preconditioner, state scan) at state ``y``, time ``t`` [s]."""
    global _prepared
    if _prepared:
        return
    y = np.array(y, dtype=float)
    scale = np.ones(system.size)
    fy = system(t, y)
    jacobian = system.jacobian(scale)
    jacobian(t, y, fy, np.zeros((system.size, system.size)))
    with contextlib.suppress(ValueError):  # structures the preconditioner does not take
        preconditioner = system.preconditioner(scale)
        preconditioner.setup(t, y, fy, False, np.zeros(1, dtype=int), 1e-3)
        preconditioner.apply(fy)
    state_problem(system.layout, system.model.ds, t, y)
    _prepared = True
