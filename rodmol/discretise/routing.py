"""The cables of a system on its cells: routing geometry, path lengths and
the friction factors of the capstan law (docs/model.md, "Cables").

Cell i carries, per cable, p at the cell's sampling point and p' across the
cell (:func:`rodmol.cable_routing.cell_geometry`), the local tangent of the
path tau = c / |c| with c = q + k x p + p' (u_c' = R c), and the share
``weights[c, i]`` of the cell that lies on the path (1 before the anchor, the
anchor's fraction in its cell). These are the quantities the compiled
kernel's cable stress reads; here they are evaluated in numpy for the laws
that read the whole path (displacement control, friction).
"""

import math

import numpy as np

from ..cable_routing import cell_geometry
from .physics import jit


class CableRouting:
    """Routing of all cables of ``model`` on cells sampled at ``s_cells`` [m].

    Attributes
    ----------
    geometry : (n_cables, N, 6) rows [0, p_y, p_z, 0, p_y', p_z'] [m, -], local.
    weights : (n_cables, N) share of each cell on the path.
    """

    def __init__(self, model, s_cells):
        n, cables = model.n_elements, model.cables
        self.ds, self.n = model.ds, n
        self.geometry = np.array([cell_geometry(c.offset, model.s_nodes, s_cells, c.name)
                                  for c in cables]).reshape(len(cables), n, 6)
        self.weights = np.array(model.cable_weights, dtype=float).reshape(len(cables), n)
        self.friction = np.array([c.friction for c in cables])
        self.slip_speed = np.array([c.slip_speed for c in cables])
        self.index = {c.name: i for i, c in enumerate(cables)}

    def path_vectors(self, q, k):
        """c = q + k x p + p' (..., n_cables, N, 3), local frame, for strains q, k (..., N, 3)."""
        p, dp = self.geometry[..., :3], self.geometry[..., 3:]
        return q[..., None, :, :] + np.cross(k[..., None, :, :], p) + dp

    def lengths(self, q, k):
        """Path lengths [m] from the base to each anchor, (..., n_cables), for strains q, k (..., N, 3)."""
        q, k = np.asarray(q, dtype=float), np.asarray(k, dtype=float)
        frames, n_cables = int(np.prod(q.shape[:-2])), len(self.weights)  # explicit: 0 cables is common
        out = np.empty((frames, n_cables))
        _path_lengths(np.ascontiguousarray(q).reshape(frames, self.n, 3),
                      np.ascontiguousarray(k).reshape(frames, self.n, 3), self.geometry, self.weights, self.ds, out)
        return out.reshape(q.shape[:-2] + (n_cables,))

    def friction_factors(self, q, k, q_t, k_t):
        """T(cell) / T(base) of each cable (n_cables, N) under the regularised capstan law.

        The path's curvature per cell is |tau' + k x tau| (tau' by differences
        between neighbouring cells), so the wrap angle is exact on circular
        arcs. The cable slides at s with the rate of change of the path
        length from s to its anchor (it is held there); friction opposes the
        sliding, with the sign regularised as x / sqrt(x^2 + slip_speed^2):
        T(s) = T(0) exp(-mu int_0^s sigma kappa ds).
        """
        out = np.empty(self.weights.shape)
        _friction_factors(*(np.ascontiguousarray(a, dtype=float) for a in (q, k, q_t, k_t)), self.geometry,
                          self.weights, self.friction, self.slip_speed, self.ds, out)
        return out

    def friction_factors_of(self, q, k, v, w, base_velocities):
        """:meth:`friction_factors` of a state: strains q, k and velocities v, w
        (N, 3), base velocities (v0, w0) (6,); the strain rates come from the
        compatibility laws with the velocities averaged over each cell (in
        both schemes: they only give the sliding direction)."""
        q_t, k_t = np.empty((self.n, 3)), np.empty((self.n, 3))
        _strain_rates(*(np.ascontiguousarray(a, dtype=float) for a in (q, k, v, w, base_velocities)),
                      self.ds, q_t, k_t)
        return self.friction_factors(q, k, q_t, k_t)


@jit
def _strain_rates(q, k, v, w, base_velocities, ds, q_t, k_t):
    # q_t = v' + k x v - w x q, k_t = w' + k x w with v, w averaged over each cell.
    for i in range(q.shape[0]):
        if i == 0:
            v0, v1, v2 = base_velocities[0], base_velocities[1], base_velocities[2]
            w0, w1, w2 = base_velocities[3], base_velocities[4], base_velocities[5]
        else:
            v0, v1, v2 = v[i - 1, 0], v[i - 1, 1], v[i - 1, 2]
            w0, w1, w2 = w[i - 1, 0], w[i - 1, 1], w[i - 1, 2]
        vb0, vb1, vb2 = 0.5 * (v[i, 0] + v0), 0.5 * (v[i, 1] + v1), 0.5 * (v[i, 2] + v2)
        wb0, wb1, wb2 = 0.5 * (w[i, 0] + w0), 0.5 * (w[i, 1] + w1), 0.5 * (w[i, 2] + w2)
        kv = _cross(k[i, 0], k[i, 1], k[i, 2], vb0, vb1, vb2)
        wq = _cross(wb0, wb1, wb2, q[i, 0], q[i, 1], q[i, 2])
        kw = _cross(k[i, 0], k[i, 1], k[i, 2], wb0, wb1, wb2)
        q_t[i, 0] = (v[i, 0] - v0) / ds + kv[0] - wq[0]
        q_t[i, 1] = (v[i, 1] - v1) / ds + kv[1] - wq[1]
        q_t[i, 2] = (v[i, 2] - v2) / ds + kv[2] - wq[2]
        k_t[i, 0] = (w[i, 0] - w0) / ds + kw[0]
        k_t[i, 1] = (w[i, 1] - w1) / ds + kw[1]
        k_t[i, 2] = (w[i, 2] - w2) / ds + kw[2]


@jit
def _path_lengths(q, k, geometry, weights, ds, out):
    # ds sum_i w_i |q + k x p + p'| per frame and cable, in one pass (the numpy
    # form made (frames, cables, N, 3) temporaries; results keep it per frame).
    for f in range(q.shape[0]):
        for c in range(geometry.shape[0]):
            total = 0.0
            for i in range(q.shape[1]):
                if weights[c, i] == 0.0:
                    continue
                g = geometry[c, i]
                x = q[f, i, 0] + k[f, i, 1] * g[2] - k[f, i, 2] * g[1] + g[3]
                y = q[f, i, 1] + k[f, i, 2] * g[0] - k[f, i, 0] * g[2] + g[4]
                z = q[f, i, 2] + k[f, i, 0] * g[1] - k[f, i, 1] * g[0] + g[5]
                total += weights[c, i] * math.sqrt(x * x + y * y + z * z)
            out[f, c] = ds * total


@jit
def _cross(a0, a1, a2, b0, b1, b2):
    return a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0


@jit
def _friction_factors(q, k, q_t, k_t, geometry, weights, friction, slip_speed, ds, out):
    # One pass per cable over its cells (the numpy form cost about 12 right-hand
    # sides per call in temporaries): tangents, stretch rates, the sliding
    # beyond each cell, the path curvature, then the capstan exponent.
    n = q.shape[0]
    tau, stretch, kappa = np.empty((n, 3)), np.empty(n), np.empty(n)
    for c in range(geometry.shape[0]):
        for i in range(n):
            g = geometry[c, i]
            kx = _cross(k[i, 0], k[i, 1], k[i, 2], g[0], g[1], g[2])
            x, y, z = q[i, 0] + kx[0] + g[3], q[i, 1] + kx[1] + g[4], q[i, 2] + kx[2] + g[5]
            norm = math.sqrt(x * x + y * y + z * z)
            tau[i, 0], tau[i, 1], tau[i, 2] = x / norm, y / norm, z / norm
            kt = _cross(k_t[i, 0], k_t[i, 1], k_t[i, 2], g[0], g[1], g[2])
            stretch[i] = (tau[i, 0] * (q_t[i, 0] + kt[0]) + tau[i, 1] * (q_t[i, 1] + kt[1])
                          + tau[i, 2] * (q_t[i, 2] + kt[2]))
        for i in range(n):  # tau' by differences: central inside, one-sided at the ends
            lo, hi = max(i - 1, 0), min(i + 1, n - 1)
            span = max(hi - lo, 1) * ds  # a single cell: tau' = 0
            kt = _cross(k[i, 0], k[i, 1], k[i, 2], tau[i, 0], tau[i, 1], tau[i, 2])
            kappa[i] = math.sqrt(((tau[hi, 0] - tau[lo, 0]) / span + kt[0]) ** 2
                                 + ((tau[hi, 1] - tau[lo, 1]) / span + kt[1]) ** 2
                                 + ((tau[hi, 2] - tau[lo, 2]) / span + kt[2]) ** 2)
        beyond = 0.0
        for i in range(n - 1, -1, -1):  # the path's stretch from cell i to the anchor
            beyond += weights[c, i] * stretch[i] * ds
            stretch[i] = -beyond / math.sqrt(beyond * beyond + slip_speed[c] * slip_speed[c])  # sigma
        exponent = 0.0
        for i in range(n):
            turn = friction[c] * stretch[i] * kappa[i] * weights[c, i] * ds
            out[c, i] = math.exp(-(exponent + 0.5 * turn))  # to the middle of the cell
            exponent += turn
