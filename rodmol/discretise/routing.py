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
from . import physics
from .physics import jit
from .sampling import cable_weights
from .stencil import CENTRED, compatibility


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
        self.weights = np.array(cable_weights(model), dtype=float).reshape(len(cables), n)
        self.geometry = np.array([cell_geometry(c.offset, model.s_nodes, s_cells, c.name)
                                  for c in cables]).reshape(len(cables), n, 6)
        self.friction = np.array([c.friction for c in cables])
        self.slip_speed = np.array([c.slip_speed for c in cables])
        self.index = {c.name: i for i, c in enumerate(cables)}

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
        _friction_factors(*(np.asarray(a, dtype=float) for a in (q, k, q_t, k_t)), self.geometry,
                          self.weights, self.friction, self.slip_speed, self.ds, out)
        return out

    def friction_factors_of(self, q, k, v, w, base_velocities):
        """:meth:`friction_factors` of a state: strains q, k and velocities v, w
        (N, 3), base velocities (v0, w0) (6,); the strain rates come from the
        compatibility laws with the velocities averaged over each cell (in
        both schemes: they only give the sliding direction)."""
        q_t, k_t = np.empty((self.n, 3)), np.empty((self.n, 3))
        _strain_rates(*(np.asarray(a, dtype=float) for a in (q, k, v, w, base_velocities)), self.ds, q_t, k_t)
        return self.friction_factors(q, k, q_t, k_t)


@jit
def _strain_rates(q, k, v, w, base_velocities, ds, q_t, k_t):
    # The stencil's compatibility law, with v, w averaged over each cell (v0, w0 before the first).
    for i in range(q.shape[0]):
        if i == 0:
            v_prev = (base_velocities[0], base_velocities[1], base_velocities[2])
            w_prev = (base_velocities[3], base_velocities[4], base_velocities[5])
        else:
            v_prev, w_prev = _row(v, i - 1), _row(w, i - 1)
        q_t[i], k_t[i] = compatibility(_row(q, i), _row(k, i), _row(v, i), _row(w, i), v_prev, w_prev, ds, CENTRED)


@jit
def _row(a, i):
    return a[i, 0], a[i, 1], a[i, 2]


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
                path = physics.path_vector(_row(q[f], i), _row(k[f], i), (g[0], g[1], g[2]), (g[3], g[4], g[5]))
                total += weights[c, i] * math.sqrt(physics.dot(path, path))
            out[f, c] = ds * total


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
            p = (g[0], g[1], g[2])
            path = physics.path_vector(_row(q, i), _row(k, i), p, (g[3], g[4], g[5]))
            tau[i] = physics.scale(1.0 / math.sqrt(physics.dot(path, path)), path)
            # d|c|/dt = tau . (q_t + k_t x p): the path's stretch rate per unit s.
            stretch[i] = physics.dot(_row(tau, i), physics.add(_row(q_t, i), physics.cross(_row(k_t, i), p)))
        for i in range(n):  # tau' by differences: central inside, one-sided at the ends
            lo, hi = max(i - 1, 0), min(i + 1, n - 1)
            span = max(hi - lo, 1) * ds  # a single cell: tau' = 0
            bend = physics.add(physics.scale(1.0 / span, physics.sub(_row(tau, hi), _row(tau, lo))),
                               physics.cross(_row(k, i), _row(tau, i)))
            kappa[i] = math.sqrt(physics.dot(bend, bend))
        beyond = 0.0
        for i in range(n - 1, -1, -1):  # the path's stretch from cell i to the anchor
            beyond += weights[c, i] * stretch[i] * ds
            stretch[i] = -beyond / math.sqrt(beyond * beyond + slip_speed[c] * slip_speed[c])  # sigma
        exponent = 0.0
        for i in range(n):
            turn = friction[c] * stretch[i] * kappa[i] * weights[c, i] * ds
            out[c, i] = math.exp(-(exponent + 0.5 * turn))  # to the middle of the cell
            exponent += turn
