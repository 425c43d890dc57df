"""The semi-discrete right-hand side dy/dt = f(t, y) of eq. (12), paper's upwind scheme.

Forward differences (toward the tip) for v and w in the compatibility laws,
backward differences (toward the base) for the stresses in the balance laws.
This is the plain numpy reference implementation, vectorised over nodes.
"""

import numpy as np

from . import loads, rotations
from .layout import FIELDS, HEADER, StateLayout
from .model import Q_STAR

#: Rate [1/s] at which the quaternion norm is pulled back to 1; the exact
#: dynamics keep |Q| = 1, so this only damps integration drift.
QUATERNION_RESTORING_RATE = 1.0


class StateView:
    """Read-only view of a state vector, handed to feedback tensions.

    Attributes are computed on first access: ``t`` [s], ``positions`` (N+1, 3)
    [m] global, ``rotations`` (N+1, 3, 3), ``q``, ``k``, ``v``, ``w`` (N, 3)
    local, ``tip`` (3,) [m].
    """

    def __init__(self, layout, t, y):
        self.t, self._layout, self._y = t, layout, y

    def __getattr__(self, name):
        if name in ("q", "k", "v", "w"):
            return self._layout.field(self._y, name)
        if name == "positions":
            return np.vstack([self._y[:3], self._layout.field(self._y, "u")])
        if name == "rotations":
            quat = np.vstack([self._y[3:7], self._layout.field(self._y, "Q")])
            return rotations.matrices(quat)
        if name == "tip":
            return self._layout.field(self._y, "u")[-1]
        raise AttributeError(name)


class SemiDiscrete:
    """Right-hand side of the method-of-lines system of a :class:`rodmol.Model`."""

    def __init__(self, model):
        self.model = model
        self.layout = StateLayout(model.n_elements)
        self.size = self.layout.size

    def stresses(self, q, k, q_t, k_t, tensions):
        """Total internal stress at the strain nodes: Kelvin-Voigt plus cable actuation.

        Returns (N_el, M_el, N_tot, M_tot), each (N, 3), local frame [N, N m].
        """
        m = self.model
        n_el = m.kl * (q - Q_STAR) + m.vl * q_t
        m_el = m.kth * k + m.vth * k_t
        n_tot, m_tot = n_el.copy(), m_el.copy()
        for p, tension, weight in zip(m.cable_offsets, np.moveaxis(tensions, -1, 0),
                                      m.cable_weights):
            if np.any(tension):
                n_a, m_a = loads.cable_stress(q, k, p, tension, weight)
                n_tot += n_a
                m_tot += m_a
        return n_el, m_el, n_tot, m_tot

    def balance(self, q, k, quat, v, w, v0, w0, tensions, gravity):
        """Strain rates and the net force/torque densities at the velocity nodes.

        Returns (q_t, k_t, force, torque), each (N, 3), local frame; the
        accelerations are force / mass and torque / inertia. Every argument
        may carry a leading time axis: fields (n_t, N, 3), base velocities
        (n_t, 3), tensions (n_t, n_cables).
        """
        m = self.model
        ds = m.ds
        v_str = _prepend(v0, v[..., :-1, :])  # velocities at strain nodes 0..N-1
        w_str = _prepend(w0, w[..., :-1, :])
        q_t = (v - v_str) / ds + loads.cross(k, v_str) - loads.cross(w_str, q)
        k_t = (w - w_str) / ds + loads.cross(k, w_str)
        _, _, n_tot, m_tot = self.stresses(q, k, q_t, k_t, tensions)

        # Values at velocity nodes 1..N; at the tip the total stress vanishes.
        zero = np.zeros(3)
        n_next = _append(n_tot[..., 1:, :], zero)
        m_next = _append(m_tot[..., 1:, :], zero)
        k_next = _append(k[..., 1:, :], zero)
        q_next = _append(q[..., 1:, :], Q_STAR)

        force = (n_next - n_tot) / ds + loads.cross(k_next, n_next)
        force += loads.gyroscopic_force(w, m.mass, v)
        if np.any(gravity) and np.any(m.net_mass):
            force += loads.gravity_buoyancy(rotations.matrices(quat), m.net_mass, gravity)
        if m.drag:
            force += loads.drag(v, m.drag_coefficient)
        torque = ((m_next - m_tot) / ds + loads.cross(k_next, m_next)
                  + loads.cross(q_next, n_next) + loads.gyroscopic_torque(w, m.inertia))
        if m.munk_moment:
            torque += loads.munk_torque(v, m.added)
        return q_t, k_t, force, torque

    def tensions(self, t, y):
        m = self.model
        state = StateView(self.layout, t, y) if m.feedback else None
        return m.tensions(t, state)

    def __call__(self, t, y, out=None):
        """dy/dt at (t, y); writes into ``out`` if given (CVODE's ``yp``)."""
        m, lay = self.model, self.layout
        out = np.empty(self.size) if out is None else out
        b = lay.blocks(y)
        quat, q, k, v, w = (b[:, FIELDS[f]] for f in ("Q", "q", "k", "v", "w"))
        v0, w0 = m.base.velocities(t)
        q_t, k_t, force, torque = self.balance(q, k, quat, v, w, v0, w0,
                                               self.tensions(t, y), m.gravity)
        ob = lay.blocks(out)
        ob[:, FIELDS["q"]] = q_t
        ob[:, FIELDS["k"]] = k_t
        ob[:, FIELDS["v"]] = force / m.mass
        ob[:, FIELDS["w"]] = torque / m.inertia
        ob[:, FIELDS["u"]] = np.einsum("nij,nj->ni", rotations.matrices(quat), v)
        ob[:, FIELDS["Q"]] = _quaternion_rate(quat, w)
        quat0 = y[3:7]
        out[:3] = rotations.matrices(quat0) @ v0
        out[3:HEADER] = _quaternion_rate(quat0, w0)
        return out


def _prepend(row, rows):
    row = np.broadcast_to(np.expand_dims(row, -2), rows.shape[:-2] + (1, 3))
    return np.concatenate([row, rows], axis=-2)


def _append(rows, row):
    row = np.broadcast_to(np.expand_dims(row, -2), rows.shape[:-2] + (1, 3))
    return np.concatenate([rows, row], axis=-2)


def _quaternion_rate(quat, omega):
    norm2 = np.sum(quat * quat, axis=-1, keepdims=True)
    return rotations.rate(quat, omega) + QUATERNION_RESTORING_RATE * (1.0 - norm2) * quat
