"""The derivative of a number read from one frame of a run by the frame's state: one rule.

A loss reads a run through its result's post-processing (the tip, the
markers, a body's position): functions of the state that the result
computes for every frame at once. Their gradient by the state is ONE rule,
:func:`frame_gradient`: central differences, every entry of the state moved
up and down by its own step, all 2 n moved frames post-processed together by
the result of the model's own kind (one vectorised pass, no per-column
Python loop). The frames are projected as a run's are (unit quaternions,
:meth:`~rodmol.discretise.protocol.Discretised.project_quaternions`), so the
gradient is that of the loss of the frames ``simulate`` returns.
"""

import numpy as np

#: Relative step of the differences: h_j = STEP * max(|y_j|, scale_j); the
#: post-processing is smooth, so the O(h^2) error is ~1e-12 relative and the
#: round-off ~eps / STEP ~ 1e-10.
STEP = 1e-6


def frame_gradient(kind, system, t, y, read):
    """d read / d y at the frame ``y`` (size,) at time ``t`` [s].

    Parameters
    ----------
    kind : rodmol.run_kinds.RunKind
        The model's kind: ``kind.result`` post-processes the moved frames.
    system : Discretised
        The run's system.
    t : float
        The frame's time [s].
    y : (size,) array
        The frame's state (projected, as a run's frames are).
    read : callable
        ``read(result)`` -> (n_frames,) the number of each frame of ``result``.

    Returns
    -------
    (size,) array
        The gradient [unit of read per unit of each entry].
    """
    y = np.asarray(y, dtype=float)
    n = len(y)
    h = STEP * np.maximum(np.abs(y), np.asarray(system.atol_scale(), dtype=float))
    frames = np.repeat(y[None, :], 2 * n, axis=0)
    index = np.arange(n)
    frames[index, index] += h
    frames[n + index, index] -= h
    system.project_quaternions(frames)
    result = kind.result(system, np.full(2 * n, float(t)), frames, True, "", {})
    values = np.asarray(read(result), dtype=float)
    return (values[:n] - values[n:]) / (2.0 * h)
