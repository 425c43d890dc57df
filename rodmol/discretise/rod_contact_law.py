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
def sweep(box, owner, index, contact_of, contact_rods, candidates):
    """The candidate segment pairs of every contact: the boxes ``box`` (n, 6) of
    every rod's segments (rod ``owner``, segment ``index``, each (n,)) that
    overlap, of two rods in contact (``contact_of`` (rods, rods): the contact's
    number, -1 for none; ``contact_rods`` (contacts, 2): its rods a and b), by
    sort and sweep along the axis of largest spread, each box tested against
    the boxes still open there only; a rod with itself: each unordered pair
    once, neighbours left out. Writes (contact, segment of a, segment of b)
    into ``candidates`` (capacity, 3) and returns their number, or minus it if
    ``candidates`` is too small."""
    n = box.shape[0]
    axis, spread = 0, -1.0
    for i in range(3):
        extent = np.max(box[:, 3 + i]) - np.min(box[:, i])
        if extent > spread:
            axis, spread = i, extent
    order = np.argsort(box[:, axis])
    open_boxes = np.empty(n, np.int64)  # the boxes not yet passed
    opened, count, capacity = 0, 0, candidates.shape[0]
    for x in range(n):
        k = order[x]
        kept = 0
        for z in range(opened):
            m = open_boxes[z]
            if box[m, 3 + axis] < box[k, axis]:
                continue  # passed: closed for every later box too
            open_boxes[kept] = m
            kept += 1
            c = contact_of[owner[k], owner[m]]
            if c < 0 or (owner[k] == owner[m] and abs(index[k] - index[m]) < 2):
                continue
            if (box[m, 0] > box[k, 3] or box[k, 0] > box[m, 3] or box[m, 1] > box[k, 4] or box[k, 1] > box[m, 4]
                    or box[m, 2] > box[k, 5] or box[k, 2] > box[m, 5]):
                continue
            i, j = (k, m) if owner[k] == contact_rods[c, 0] else (m, k)
            if owner[k] == owner[m] and index[i] > index[j]:
                i, j = j, i
            if count < capacity:
                candidates[count, 0], candidates[count, 1], candidates[count, 2] = c, index[i], index[j]
            count += 1
        opened = kept
        open_boxes[opened] = k
        opened += 1
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
def candidate_forces(pos, vel, radius, arc, rest, force, candidates, count, first, segments, contact_rods, samples,
                     laws, stats):
    """Add to ``force`` (nodes, 3) [N], global, the contact forces of the
    candidates ``candidates[:count]`` (contact, segment of a, segment of b):
    rod r's nodes from ``first[r]``, ``segments[r]`` segments; contact c
    between rods ``contact_rods[c]``, sampled ``samples[c]`` (of a, of b)
    times a segment, law ``laws[c]`` (k, c, mu, v_s, h, self-contact
    cut-off); ``stats`` (3,): energy, least gap and touching pairs (added
    to, the gap lowered)."""
    for x in range(count):
        c, ga, gb = candidates[x, 0], candidates[x, 1], candidates[x, 2]
        a, b = contact_rods[c, 0], contact_rods[c, 1]
        same, law = a == b, laws[c]
        one = _side(pos, vel, radius, arc, rest, force, first[a], segments[a], ga, first[b], segments[b], gb,
                    samples[c, 0], same, law, law[5], stats)
        other = _side(pos, vel, radius, arc, rest, force, first[b], segments[b], gb, first[a], segments[a], ga,
                      samples[c, 1], same, law, law[5], stats)
        if one or other:
            stats[ACTIVE] += 1.0
