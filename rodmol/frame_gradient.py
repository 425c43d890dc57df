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

Entries the post-processing does not read (a rod's velocities, for its tip
and markers) are found first by a probe: the entries are split into
:data:`PROBE_GROUPS` residue classes (a rod's entries per element: each class
one component of one field of every element), each class moved at once with
random signs; a class whose move
leaves the number exactly as it was is not read, and its entries are not
differenced (half the frames for the tip, measured on the arm).
"""

import numpy as np

from .discretise.layout import BLOCK

#: Relative step of the differences: h_j = STEP * max(|y_j|, scale_j); the
#: post-processing is smooth, so the O(h^2) error is ~1e-12 relative and the
#: round-off ~eps / STEP ~ 1e-10.
STEP = 1e-6
#: Residue classes of the probe: a rod's entries per element (a System's rods start at
#: other offsets, so there a class mixes fields: fewer entries are left out, none wrongly).
PROBE_GROUPS = BLOCK


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
    h = STEP * np.maximum(np.abs(y), np.asarray(system.atol_scale(), dtype=float))
    index = _read_entries(kind, system, t, y, h, read)
    m = len(index)
    frames = np.repeat(y[None, :], 2 * m, axis=0)
    frames[np.arange(m), index] += h[index]
    frames[m + np.arange(m), index] -= h[index]
    values = _values(kind, system, t, frames, read)
    out = np.zeros(len(y))
    out[index] = (values[:m] - values[m:]) / (2.0 * h[index])
    return out


def _values(kind, system, t, frames, read):
    """``read`` of the frames (projected as a run's), all at time ``t``."""
    system.project_quaternions(frames)
    result = kind.result(system, np.full(len(frames), float(t)), frames, True, "", {})
    return np.asarray(read(result), dtype=float)


def _read_entries(kind, system, t, y, h, read):
    """The entries of the state that ``read`` may depend on (see the module docstring)."""
    classes = np.arange(len(y)) % PROBE_GROUPS
    signs = np.random.default_rng(0).choice([-1.0, 1.0], size=len(y))
    frames = np.repeat(y[None, :], PROBE_GROUPS + 1, axis=0)
    for g in range(PROBE_GROUPS):
        frames[g + 1, classes == g] += signs[classes == g] * h[classes == g]
    values = _values(kind, system, t, frames, read)
    moved = values[1:] != values[0]
    return np.flatnonzero(moved[classes])
