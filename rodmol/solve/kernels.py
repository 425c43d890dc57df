"""Getting the compiled kernels ready before a run, so the wait is announced
and not booked as integration time.

numba compiles each kernel on its first call (several seconds in a fresh
install) and later processes load the machine code from the disk cache
(well under a second). :func:`prepare` makes those first calls with a run
of a microsecond by the run's own backend and options, so every kernel it
will use (right-hand side, Jacobian, preconditioner, Newton loop, state
scan, post-processing) is ready; once per backend and options in a process. (User inputs are
read at the preparing run's times too, as the initial equilibrium reads them.)
"""

import contextlib

import numpy as np

from ..discretise import compiling, stencil
from ..discretise.kernel_cache import cached
from ..result import ARRAYS, from_states

#: Span [s] of the preparing run.
SPAN = 1e-6
_prepared = set()


def _key(run, options):
    return run, repr(sorted(options.items()))


def ready(run, options):
    """True once :func:`prepare` has run for this backend and options in this process."""
    return _key(run, options) in _prepared


def stage_text():
    """What the preparing stage does, for the progress line: compiling (the first run after
    installing rodmol or editing its kernels' sources; once, its machine code is cached; on
    two cores where a helper process takes part) or loading the kernels from the disk cache."""
    if cached(stencil.rhs) is False:
        cores = " on 2 cores" if compiling.helper_wanted() else ""
        return (f"compiling the kernels (right-hand side, Jacobian, preconditioner, post-processing) "
                f"once{cores}: later runs load them from the cache")
    return "preparing the compiled kernels"


def prepare(system, t, y, run, rtol, atol, options):
    """A run of :data:`SPAN` from state ``y`` at time ``t`` [s]; its result is dropped."""
    key = _key(run, options)
    if key in _prepared:
        return
    y = np.array(y, dtype=float)
    raw = run(system, y, np.array([t, t + SPAN]), rtol=rtol, atol=atol, **options)
    # A run that short may not need a linear solve (the Newton residual of a
    # rod at rest can vanish): call the preconditioner's kernels directly.
    with contextlib.suppress(ValueError):  # structures the block elimination does not take
        preconditioner = system.preconditioner(np.ones(system.size))
        fy = system(t, y)
        preconditioner.setup(t, y, fy, False, np.zeros(1, dtype=int), 1e-3)
        preconditioner.apply(fy)
    # The post-processing of the frames: every array of a Result (stresses, loads, poses, path lengths).
    result = from_states(system, raw.t, raw.y, raw.success, raw.message, raw.stats)
    for name in ARRAYS:
        getattr(result, name)
    _prepared.add(key)
