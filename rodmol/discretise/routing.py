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
        c = self.path_vectors(q, k)
        norm = np.linalg.norm(c, axis=-1, keepdims=True)
        tau = c / norm
        # d|c|/dt = tau . (q_t + k_t x p): the path's stretch rate per unit s.
        stretch_rate = np.sum(tau * (q_t[None] + np.cross(k_t[None], self.geometry[..., :3])), axis=-1)
        beyond = np.cumsum((self.weights * stretch_rate)[:, ::-1], axis=1)[:, ::-1] * self.ds
        sigma = -beyond / np.sqrt(beyond**2 + self.slip_speed[:, None] ** 2)
        dtau = np.gradient(tau, self.ds, axis=1) if self.n > 1 else np.zeros_like(tau)
        kappa = np.linalg.norm(dtau + np.cross(k[None], tau), axis=-1)
        turn = self.friction[:, None] * sigma * kappa * self.weights * self.ds
        exponent = np.cumsum(turn, axis=1) - 0.5 * turn  # to the middle of each cell
        return np.exp(-exponent)

    def friction_factors_of(self, q, k, v, w, base_velocities):
        """:meth:`friction_factors` of a state: strains q, k and velocities v, w
        (N, 3), base velocities (v0, w0) (6,); the strain rates come from the
        compatibility laws with the velocities averaged over each cell (in
        both schemes: they only give the sliding direction)."""
        v_prev = np.vstack([base_velocities[:3], v[:-1]])
        w_prev = np.vstack([base_velocities[3:], w[:-1]])
        v_bar, w_bar = 0.5 * (v + v_prev), 0.5 * (w + w_prev)
        q_t = (v - v_prev) / self.ds + np.cross(k, v_bar) - np.cross(w_bar, q)
        k_t = (w - w_prev) / self.ds + np.cross(k, w_bar)
        return self.friction_factors(q, k, q_t, k_t)


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
