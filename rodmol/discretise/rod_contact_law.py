"""The compiled law of contact between rods (:class:`rodmol.RodContact`):
its broad phase (sort and sweep of the segments' boxes) and its narrow phase
(sampled segments against the other rod's segment capsules).

A rod's centreline is the polyline of its nodes 0..N (the base and the
velocity nodes' integrated positions u), each segment a capsule whose radius
runs linearly between its nodes'. Each segment of one rod is sampled at
``samples`` points (the midpoints of equal parts, each standing for its
part's rest length w); a sample p is tested against a segment of the other
rod when that segment is the nearest of its neighbours (strictly nearer
than the previous one, no farther than the next: each sample is pushed by
one segment of a straight stretch, whatever its vertices). At depth
d = r_p + r_q - |p - q| (q the segment's nearest point) the sample feels,
along n = (p - q) / |p - q|, the obstacles' law
(:func:`rodmol.discretise.external.penalty`) with half the stiffness and
damping per unit length (each side samples the other), times w:

    f_n = max(0, k/2 w P(d) - ramp(d) c/2 w v_n),
    f_t = -mu f_n v_t / sqrt(|v_t|^2 + v_s^2),

with (v_n, v_t) the velocity of p relative to q, both interpolated on the
centrelines. The force acts on p's segment (shared by its two nodes as p
lies between them) and its opposite on q's: equal and opposite, through the
centrelines (no moment: rolling is not resisted, and the slip is the
centrelines'). The elastic part is the gradient of
sum k/2 w Phi(d) (:func:`contact_energy`'s density, exact where the radius
is uniform); the damping and friction only dissipate.

A rod touching itself skips, for each sample, the segments within
``cutoff`` along the rod (arc length from the sample to the segment's
nearest end).
"""

import numpy as np

from .external import penalty
from .physics import jit

#: What the narrow phase returns besides the forces: the elastic energy [J],
#: the least surface gap met [m] (inf if no candidate) and the active segment pairs.
ENERGY, LEAST_GAP, ACTIVE = 0, 1, 2


@jit
def boxes(pos, first, n_segments, reach, out):
    """The boxes (lo x, y, z, hi x, y, z) of segments ``first``..``first +
    n_segments - 1`` (segment g joins nodes g, g + 1 of ``pos``) grown by
    ``reach`` [m], into ``out`` (n_segments, 6)."""
    for g in range(n_segments):
        for i in range(3):
            a, b = pos[first + g, i], pos[first + g + 1, i]
            out[g, i] = min(a, b) - reach
            out[g, 3 + i] = max(a, b) + reach


@jit
def sweep(box_a, box_b, same, pairs):
    """The pairs (segment of a, segment of b) whose boxes overlap, by sort and
    sweep along the axis of largest spread, each box tested against the other
    rod's boxes still open there only; ``same``: a rod with itself (each
    unordered pair once, neighbours left out). Writes them into ``pairs``
    (capacity, 2) and returns their number, or minus it if ``pairs`` is too small."""
    na, nb = box_a.shape[0], box_b.shape[0]
    n = na if same else na + nb
    lo, hi = np.empty((n, 3)), np.empty((n, 3))
    owner, index = np.empty(n, np.int64), np.empty(n, np.int64)
    for k in range(n):
        src, g = (box_a, k) if k < na else (box_b, k - na)
        owner[k], index[k] = 0 if k < na else 1, g
        for i in range(3):
            lo[k, i], hi[k, i] = src[g, i], src[g, 3 + i]
    axis, spread = 0, -1.0
    for i in range(3):
        extent = np.max(hi[:, i]) - np.min(lo[:, i])
        if extent > spread:
            axis, spread = i, extent
    order = np.argsort(lo[:, axis])
    open_boxes = np.empty((2, n), np.int64)  # each owner's boxes not yet passed
    opened = np.zeros(2, np.int64)
    count, capacity = 0, pairs.shape[0]
    for x in range(n):
        k = order[x]
        other = owner[k] if same else 1 - owner[k]
        kept = 0
        for z in range(opened[other]):
            m = open_boxes[other, z]
            if hi[m, axis] < lo[k, axis]:
                continue  # passed: closed for every later box too
            open_boxes[other, kept] = m
            kept += 1
            if same and abs(index[k] - index[m]) < 2:
                continue
            if (lo[m, 0] > hi[k, 0] or lo[k, 0] > hi[m, 0] or lo[m, 1] > hi[k, 1] or lo[k, 1] > hi[m, 1]
                    or lo[m, 2] > hi[k, 2] or lo[k, 2] > hi[m, 2]):
                continue
            if count < capacity:
                i, j = (k, m) if owner[k] == 0 else (m, k)
                if same and index[i] > index[j]:
                    i, j = j, i
                pairs[count, 0], pairs[count, 1] = index[i], index[j]
            count += 1
        opened[other] = kept
        open_boxes[owner[k], opened[owner[k]]] = k
        opened[owner[k]] += 1
    return count if count <= capacity else -count


@jit
def _point(pos, node, t):
    """The point at parameter ``t`` of segment ``node``, ``node + 1`` of ``pos`` (a 3-tuple)."""
    return ((1.0 - t) * pos[node, 0] + t * pos[node + 1, 0], (1.0 - t) * pos[node, 1] + t * pos[node + 1, 1],
            (1.0 - t) * pos[node, 2] + t * pos[node + 1, 2])


@jit
def nearest(pos, node, p):
    """(distance [m], parameter t in [0, 1]) of the point of segment ``node``,
    ``node + 1`` of ``pos`` nearest to ``p``."""
    ax, ay, az = pos[node, 0], pos[node, 1], pos[node, 2]
    ex, ey, ez = pos[node + 1, 0] - ax, pos[node + 1, 1] - ay, pos[node + 1, 2] - az
    length2 = ex * ex + ey * ey + ez * ez
    t = 0.0
    if length2 > 0.0:
        t = min(1.0, max(0.0, ((p[0] - ax) * ex + (p[1] - ay) * ey + (p[2] - az) * ez) / length2))
    dx, dy, dz = p[0] - ax - t * ex, p[1] - ay - t * ey, p[2] - az - t * ez
    return np.sqrt(dx * dx + dy * dy + dz * dz), t


@jit
def _eligible(arc, first, n_segments, g, s_p, same, cutoff):
    """True if segment ``g`` (0..n_segments - 1, from node ``first``) may touch the sample at arc ``s_p``."""
    if g < 0 or g >= n_segments:
        return False
    if not same:
        return True
    a, b = arc[first + g], arc[first + g + 1]
    gap = a - s_p if s_p < a else (s_p - b if s_p > b else 0.0)
    return gap >= cutoff


@jit
def _side(pos, vel, radius, arc, rest, force, pa, na, ga, pb, nb, gb, samples, same, law, cutoff, stats):
    """The samples of segment ``ga`` of rod a (nodes from ``pa``, ``na`` segments)
    against segment ``gb`` of rod b (from ``pb``, ``nb``): adds their forces to
    ``force`` and their energy, least gap and activity to ``stats``; returns
    True if a sample touches."""
    k, c, mu, slip, h = law[0], law[1], law[2], law[3], law[4]
    i0, j0 = pa + ga, pb + gb
    w = rest[i0] / samples
    touched = False
    for m in range(samples):
        sigma = (m + 0.5) / samples
        p = _point(pos, i0, sigma)
        s_p = (1.0 - sigma) * arc[i0] + sigma * arc[i0 + 1]
        if not _eligible(arc, pb, nb, gb, s_p, same, cutoff):
            continue
        dist, t = nearest(pos, j0, p)
        if _eligible(arc, pb, nb, gb - 1, s_p, same, cutoff) and nearest(pos, j0 - 1, p)[0] <= dist:
            continue
        if _eligible(arc, pb, nb, gb + 1, s_p, same, cutoff) and nearest(pos, j0 + 1, p)[0] < dist:
            continue
        reach = (1.0 - sigma) * radius[i0] + sigma * radius[i0 + 1] + (1.0 - t) * radius[j0] + t * radius[j0 + 1]
        depth = reach - dist
        stats[LEAST_GAP] = min(stats[LEAST_GAP], -depth)
        measure, ramp = penalty(depth, h)
        if measure <= 0.0:
            continue
        q = _point(pos, j0, t)
        n = (0.0, 1.0, 0.0)
        if dist > 0.0:
            n = ((p[0] - q[0]) / dist, (p[1] - q[1]) / dist, (p[2] - q[2]) / dist)
        vp, vq = _point(vel, i0, sigma), _point(vel, j0, t)
        rel = (vp[0] - vq[0], vp[1] - vq[1], vp[2] - vq[2])
        vn = rel[0] * n[0] + rel[1] * n[1] + rel[2] * n[2]
        normal = 0.5 * w * (k * measure - ramp * c * vn)
        # Phi(d): the integral of P over the depth (external.contact_energy's density).
        if depth < h:
            stats[ENERGY] += 0.5 * w * k * depth ** 3 / (6.0 * h)
        else:
            stats[ENERGY] += 0.5 * w * k * (h * h / 6.0 + 0.5 * (depth - h) * (depth + h) - 0.5 * h * (depth - h))
        touched = True
        if normal <= 0.0:
            continue
        vt = (rel[0] - vn * n[0], rel[1] - vn * n[1], rel[2] - vn * n[2])
        drag = mu * normal / np.sqrt(vt[0] * vt[0] + vt[1] * vt[1] + vt[2] * vt[2] + slip * slip)
        for x in range(3):
            f = normal * n[x] - drag * vt[x]
            force[i0, x] += (1.0 - sigma) * f
            force[i0 + 1, x] += sigma * f
            force[j0, x] -= (1.0 - t) * f
            force[j0 + 1, x] -= t * f
    return touched


@jit
def pair_forces(pos, vel, radius, arc, rest, force, pairs, count, pa, na, pb, nb, samples_a, samples_b, same,
                law, cutoff, stats):
    """Add to ``force`` (nodes, 3) [N], global, the contact forces of the
    candidate segment pairs ``pairs[:count]`` of rods a and b (nodes from
    ``pa``, ``pb``; ``na``, ``nb`` segments, sampled ``samples_a``,
    ``samples_b`` times each), law (k, c, mu, v_s, h); ``stats`` (3,):
    energy, least gap and active pairs (added to, the gap lowered)."""
    for x in range(count):
        ga, gb = pairs[x, 0], pairs[x, 1]
        one = _side(pos, vel, radius, arc, rest, force, pa, na, ga, pb, nb, gb, samples_a, same, law, cutoff, stats)
        other = _side(pos, vel, radius, arc, rest, force, pb, nb, gb, pa, na, ga, samples_b, same, law, cutoff,
                      stats)
        if one or other:
            stats[ACTIVE] += 1.0
