"""Centreline positions rebuilt from the strains.

The discrete schemes keep the time-integrated positions (u_t = R v)
consistent with the strains (u' = R q) only to their order: the gap grows by
O(ds) (upwind) or O(ds^2) (centred) per unit time under sustained motion.
Positions are therefore rebuilt from the base position, the orientations and
the strains (the midpoint rule, second order), which is exact at rest. The static equilibrium imposes the same chords,
so at rest both positions agree.
"""

import numba
import numpy as np

from .compiling import jit, strided
from .physics import chord


def chords(quat, q, k, ds):
    """Element chords (..., N, 3) [m], global: element j runs from node j to
    node j+1 with constant strains q_j, k_j, and its chord is taken as
    ds R(mid) q_j with R(mid) = R_j exp(ds k_j / 2) (``physics.chord``).

    ``quat`` (..., N, 4) are the orientations of nodes 0..N-1.
    """
    # (frames, N, width) views, no copies: the strain fields are strided views of the states.
    quat, q, k = (np.asarray(a, dtype=float) for a in (quat, q, k))
    n = q.shape[-2]
    out = np.empty(q.shape)
    _chords(quat.reshape(-1, n, 4), q.reshape(-1, n, 3), k.reshape(-1, n, 3), float(ds), out.reshape(-1, n, 3))
    return out


@jit(signature=numba.types.void(strided(3), strided(3), strided(3), numba.types.float64, strided(3, writes=True)),
     ahead=True)
def _chords(quat, q, k, ds, out):
    for f in range(q.shape[0]):
        for j in range(q.shape[1]):
            out[f, j, 0], out[f, j, 1], out[f, j, 2] = chord(
                (quat[f, j, 0], quat[f, j, 1], quat[f, j, 2], quat[f, j, 3]), (q[f, j, 0], q[f, j, 1], q[f, j, 2]),
                (k[f, j, 0], k[f, j, 1], k[f, j, 2]), ds)


def positions(u0, quat, q, k, ds):
    """Node positions (..., N+1, 3) [m], global.

    Parameters
    ----------
    u0 : (..., 3) base position [m], global.
    quat : (..., N+1, 4) orientations of nodes 0..N (node 0 is the base).
    q, k : (..., N, 3) strains of strain nodes 0..N-1, local.
    ds : float, element length [m].
    """
    steps = chords(quat[..., :-1, :], q, k, ds)
    u0 = np.asarray(u0, dtype=float)[..., None, :]
    return np.concatenate([u0, u0 + np.cumsum(steps, axis=-2)], axis=-2)


def bracket(s_nodes, s):
    """(j, w): the nodes j, j + 1 of ``s_nodes`` around arc length ``s`` [m], and the weight
    of node j + 1 for a linear interpolation in s."""
    j = int(np.clip(np.searchsorted(s_nodes, s, side="right") - 1, 0, len(s_nodes) - 2))
    return j, (s - s_nodes[j]) / (s_nodes[j + 1] - s_nodes[j])


def section_points(positions, rotations, nodes, weights, offsets, dtype=float):
    """Material points of the sections (n_t, n, 3) [m], global: ``u + R p`` with the local
    offset p = (0, p_y, p_z) [m], at two nodes ``nodes`` (n, 2) interpolated with ``weights``
    (n, 2), the offsets (p_y, p_z) at those nodes ``offsets`` (n, 2, 2); for the frames'
    node positions (n_t, N+1, 3) and rotations (n_t, N+1, 3, 3). Markers and cables."""
    out = np.empty((len(positions), len(nodes), 3), dtype=dtype)
    if len(nodes):
        _section_points(np.asarray(positions, dtype=float), np.asarray(rotations, dtype=float),
                        np.asarray(nodes, dtype=np.int64), np.asarray(weights, dtype=float),
                        np.asarray(offsets, dtype=float), out)
    return out


@jit
def _section_points(positions, rotations, nodes, weights, offsets, out):
    for f in range(positions.shape[0]):
        for i in range(nodes.shape[0]):
            for c in range(3):
                total = 0.0
                for e in range(2):
                    n = nodes[i, e]
                    total += weights[i, e] * (positions[f, n, c] + offsets[i, e, 0] * rotations[f, n, c, 1]
                                              + offsets[i, e, 1] * rotations[f, n, c, 2])
                out[f, i, c] = total


def track(s_markers, offsets, s_nodes, positions, rotations):
    """Global marker positions (n_t, n_markers, 3) from nodal poses, for markers
    at arc lengths ``s_markers`` [m] with local offsets ``offsets`` (n_markers, 2),
    (p_y, p_z) [m].

    Each marker is ``u + R p`` evaluated at the two nodes around it and
    interpolated linearly in s (:func:`rodmol.discretise.section_points`).
    """
    pairs = [bracket(s_nodes, s) for s in s_markers]
    nodes = np.array([[j, j + 1] for j, _ in pairs], dtype=np.int64).reshape(-1, 2)
    weights = np.array([[1.0 - w, w] for _, w in pairs]).reshape(-1, 2)
    at_nodes = np.repeat(np.asarray(offsets, dtype=float).reshape(-1, 1, 2), 2, axis=1)  # the same at both
    return section_points(positions, rotations, nodes, weights, at_nodes)
