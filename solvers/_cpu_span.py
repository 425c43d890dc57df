"""CPU time over the span a run's ``wall_time_s`` measures, for studies on a shared machine.

On a machine shared with other jobs the wall time counts their time slices too;
the CPU time of a single-threaded process does not. rodmol's runs time
themselves from the output store's start (``rodmol.solve.outputs.Outputs``) to
their solution; :func:`cpu_span` patches those two methods for the length of a
``with`` block, so the CPU time is taken over the same span. It imports no
rodmol itself: the before/after studies' workers (another tree's rodmol) use it
too.
"""

import contextlib
import time


@contextlib.contextmanager
def cpu_span(outputs):
    """``with cpu_span(rodmol.solve.outputs) as span:`` run; then ``span["cpu_s"]`` is the
    CPU time [s] of the runs' steps (summed over the runs, or a run's chunks, in the block)."""
    init, solution, span = outputs.Outputs.__init__, outputs.Outputs.solution, {"cpu_s": 0.0}

    def starting(store, *args, **kwargs):
        init(store, *args, **kwargs)
        span["start"] = time.process_time()

    def ending(store, *args, **kwargs):
        span["cpu_s"] += time.process_time() - span["start"]
        return solution(store, *args, **kwargs)

    outputs.Outputs.__init__, outputs.Outputs.solution = starting, ending
    try:
        yield span
    finally:
        outputs.Outputs.__init__, outputs.Outputs.solution = init, solution
