"""Twist, writhe and link of a rod held at both ends (Calugareanu-White-Fuller:
Lk = Tw + Wr), re-exported by :mod:`rodmol.analysis`.

An open rod has no linking number of its own; it gets one here by a closure
(docs/systems.md, "Twist, writhe and link"): the centreline is extended
from each end along that end section's axis (the column 0 of its rotation)
by ``far`` times the rod's extent, and the two far points are joined by a
path that runs ``far`` extents out to the side, parallel to the line
between them, so that it never comes near the rod. The writhe is the Gauss
double integral of that closed polygon (exact per pair of straight
segments); the twist is the rotation of the sections' y axis about the
centreline, summed along the rod only. Held at both ends (positions and
end sections fixed) the closure is fixed, and Tw + Wr changes only by the
turns of an end about its axis, or when the rod passes through itself.
Limits: the far path's share falls as 1 / ``far`` (1e4: well under 1e-3
turns for any rod within its extent); an end whose axis turns during a
run moves the closure and the link with it (Fuller: by the solid angle
its axis sweeps); the twist counts the turn between two neighbouring
sections modulo one half turn, so a grid must resolve it.
"""

import numpy as np

from .errors import ParameterError

#: The closure's reach in extents of the rod (its share of the writhe falls as 1 / FAR).
FAR = 1e4


def _frames(positions, rotations):
    """Positions (..., N+1, 3) and rotations (..., N+1, 3, 3) as float arrays, checked."""
    x, r = np.asarray(positions, dtype=float), np.asarray(rotations, dtype=float)
    if x.ndim < 2 or x.shape[-1] != 3 or x.shape[-2] < 2:
        raise ParameterError(f"`positions` must be (..., N+1, 3) with N >= 1, got shape {x.shape}")
    if r.shape != x.shape + (3,):
        raise ParameterError(f"`rotations` must be {x.shape + (3,)} to match `positions`, got {r.shape}")
    if not (np.all(np.isfinite(x)) and np.all(np.isfinite(r))):
        raise ParameterError("`positions` and `rotations` must be finite")
    return x, r


def _unit(v):
    n = np.linalg.norm(v, axis=-1, keepdims=True)
    return v / np.where(n > 0, n, 1.0)


def _signed_angle(a, b, axis):
    """Angle [rad] from unit ``a`` to ``b`` about ``axis``, both normal to it."""
    return np.arctan2(np.einsum("...i,...i", np.cross(a, b), axis), np.einsum("...i,...i", a, b))


def _transport(u, t0, t1):
    """``u`` carried by the least rotation that takes unit tangent ``t0`` to ``t1`` (parallel transport)."""
    b = np.cross(t0, t1)
    c = np.einsum("...i,...i", t0, t1)[..., None]
    # Rodrigues with sin = |b|, cos = c: u cos + (b x u) + b (b.u) (1 - cos) / sin^2
    return u * c + np.cross(b, u) + b * np.einsum("...i,...i", b, u)[..., None] / (1.0 + c)


def twist(positions, rotations):
    """Twist Tw [turns] of a rod: the turn of its sections' y axis about the
    centreline, from the base section to the tip section.

    Parameters
    ----------
    positions : (..., N+1, 3) centreline nodes [m].
    rotations : (..., N+1, 3, 3) the sections' local-to-global rotations
        (columns: the section's axes; x along the rod).

    Returns
    -------
    float or array (...): the twist [turns]. The tangents are the end
    sections' axes and the polyline's segments between them; each node's y
    axis, normal to the mean of its tangents, is compared with its
    neighbour's carried along the bend (parallel transport).
    """
    x, r = _frames(positions, rotations)
    seg = _unit(np.diff(x, axis=-2))
    tangents = np.concatenate([r[..., :1, :, 0], seg, r[..., -1:, :, 0]], axis=-2)  # N+2
    node_t = _unit(tangents[..., :-1, :] + tangents[..., 1:, :])  # each node's: between its two
    y = r[..., :, 1]
    y = _unit(y - node_t * np.einsum("...i,...i", y, node_t)[..., None])
    # node i -> its segment -> node i+1: each hop a transport then the turn about the arriving tangent
    mid = _transport(y[..., :-1, :], node_t[..., :-1, :], seg)
    ahead = _transport(mid, seg, node_t[..., 1:, :])
    return np.sum(_signed_angle(ahead, y[..., 1:, :], node_t[..., 1:, :]), axis=-1) / (2 * np.pi)


def closure(positions, rotations, far=FAR):
    """The closed polygon (..., N+5, 3) [m] the writhe is taken of: the rod's
    nodes, a far point along the tip section's axis, two far to the side, a
    far point back along the base section's axis (then back to the base)."""
    x, r = _frames(positions, rotations)
    extent = np.max(np.linalg.norm(x - x[..., :1, :], axis=-1), axis=-1)[..., None, None]
    extent = np.where(extent > 0, extent, 1.0)
    reach = far * extent[..., 0, :]
    head = x[..., -1, :] + reach * r[..., -1, :, 0]
    tail = x[..., 0, :] - reach * r[..., 0, :, 0]
    axis = _unit(head - tail)
    # to the side: away from the rod's middle, so the path never comes near it; any normal if straight
    centre = np.mean(x, axis=-2) - tail
    side = centre - axis * np.einsum("...i,...i", centre, axis)[..., None]
    fallback = np.cross(axis, np.where(np.abs(axis[..., :1]) < 0.9, [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]))
    small = np.linalg.norm(side, axis=-1, keepdims=True) <= 1e-12 * extent[..., 0, :]
    side = _unit(np.where(small, fallback, side))
    out = [x, head[..., None, :], (head + reach * side)[..., None, :], (tail + reach * side)[..., None, :],
           tail[..., None, :]]
    return np.concatenate(out, axis=-2)


def _closed_writhe(p):
    """Writhe of the closed polygon ``p`` (M, 3): the Gauss integral summed
    over pairs of segments, each pair's exactly (its signed solid angle over
    4 pi)."""
    a, b = p, np.roll(p, -1, axis=0)
    i, j = np.triu_indices(len(p), k=2)
    keep = ~((i == 0) & (j == len(p) - 1))  # the last segment meets the first
    i, j = i[keep], j[keep]
    p1, p2, p3, p4 = a[i], b[i], a[j], b[j]
    r13, r14, r23, r24 = p3 - p1, p4 - p1, p3 - p2, p4 - p2
    n = [_unit(np.cross(u, v)) for u, v in ((r13, r14), (r14, r24), (r24, r23), (r23, r13))]
    omega = sum(np.arcsin(np.clip(np.einsum("ki,ki->k", n[m], n[(m + 1) % 4]), -1.0, 1.0)) for m in range(4))
    sign = np.sign(np.einsum("ki,ki->k", np.cross(p4 - p3, p2 - p1), r13))
    return 2.0 * float(np.sum(omega * sign)) / (4.0 * np.pi)


def writhe(positions, rotations, far=FAR):
    """Writhe Wr [turns] of a rod closed far away (:func:`closure`).

    Same arguments as :func:`twist` (only the end sections' axes of
    ``rotations`` matter: they carry the closure); ``far`` [-] is the
    closure's reach in extents of the rod.
    """
    p = closure(positions, rotations, far)
    flat = p.reshape(-1, *p.shape[-2:])
    out = np.array([_closed_writhe(q) for q in flat])
    return out.reshape(p.shape[:-2]) if p.ndim > 2 else float(out[0])


def link(positions, rotations, far=FAR):
    """Link Lk = Tw + Wr [turns] of a rod held at both ends (module docstring:
    its closure and limits). Returns (link, twist, writhe)."""
    tw, wr = twist(positions, rotations), writhe(positions, rotations, far)
    return tw + wr, tw, wr


def result_link(result, far=FAR):
    """(link, twist, writhe) [turns], each (n_t,), of a rod's :class:`rodmol.Result`."""
    return link(result.positions, result.rotations, far)
