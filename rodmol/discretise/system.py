"""The semi-discrete right-hand side dy/dt = f(t, y) of eq. (12), paper's upwind scheme.

Forward differences (toward the tip) for v and w in the compatibility laws,
backward differences (toward the base) for the stresses in the balance laws.
The plain numpy implementation here, vectorised over nodes, is the reference
(``balance``/``stresses`` also serve post-processing with a leading time
axis); by default ``SemiDiscrete.__call__`` runs the same equations compiled
by numba (:mod:`rodmol.kernels`), which is what the time integrators call.
"""

import warnings

import numpy as np

from . import centreline, upwind, body_loads, rotations
from ..cables import ConstantTension
from ..errors import ParameterError
from .layout import FIELDS, HEADER, StateLayout
from ..model import Q_STAR

#: Implementations of ``SemiDiscrete.__call__``.
KERNELS = ("numba", "numpy")

#: Rate [1/s] at which the quaternion norm is pulled back to 1; the exact
#: dynamics keep |Q| = 1, so this only damps integration drift.
QUATERNION_RESTORING_RATE = 1.0


class StateView:
    """Read-only view of a state vector, handed to feedback tensions.

    Attributes are computed on access: ``t`` [s], ``positions`` (N+1, 3) [m]
    global (rebuilt from the strains, as ``Result.positions``), ``tip`` (3,)
    [m], ``rotations`` (N+1, 3, 3), ``q``, ``k``, ``v``, ``w`` (N, 3) local.
    """

    def __init__(self, layout, t, y, ds):
        self.t, self._layout, self._y, self._ds = t, layout, y, ds

    def __getattr__(self, name):
        if name in ("q", "k", "v", "w"):
            return self._layout.field(self._y, name)
        if name == "rotations":
            return rotations.matrices(self._quaternions())
        if name == "positions":
            return centreline.positions(self._y[:3], self._quaternions(), self.q, self.k, self._ds)
        if name == "tip":
            return self.positions[-1]
        raise AttributeError(name)

    def _quaternions(self):
        return np.vstack([self._y[3:7], self._layout.field(self._y, "Q")])


class SemiDiscrete:
    """Right-hand side of the method-of-lines system of a :class:`rodmol.Model`.

    Parameters
    ----------
    model : Model
    kernel : "numba" or "numpy"
        Implementation of :meth:`__call__`: the compiled loops of
        :mod:`rodmol.kernels` (default; falls back to numpy with a warning
        if numba is not installed) or the vectorised numpy reference.
    """

    def __init__(self, model, kernel="numba"):
        if kernel not in KERNELS:
            raise ParameterError(f"unknown `kernel` {kernel!r}; valid: {list(KERNELS)}")
        if kernel == "numba" and not upwind.AVAILABLE:
            warnings.warn("numba is not installed: using the (slower) numpy right-hand side",
                          RuntimeWarning, stacklevel=2)
            kernel = "numpy"
        self.model = model
        self.layout = StateLayout(model.n_elements)
        self.size = self.layout.size
        self.kernel = kernel
        self._feedback = model.feedback  # a property that loops over the cables: read it once
        self._classify_cables()
        if kernel == "numba":
            self._setup_compiled()

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
                n_a, m_a = body_loads.cable_stress(q, k, p, tension, weight)
                n_tot += n_a
                m_tot += m_a
        return n_el, m_el, n_tot, m_tot

    def strain_rates(self, q, k, v, w, v0, w0):
        """Compatibility laws (eq. 2) with forward differences of v and w.

        Returns (q_t, k_t) at the strain nodes, (..., N, 3), local frame.
        """
        ds = self.model.ds
        v_str = _prepend(v0, v[..., :-1, :])  # velocities at strain nodes 0..N-1
        w_str = _prepend(w0, w[..., :-1, :])
        q_t = (v - v_str) / ds + body_loads.cross(k, v_str) - body_loads.cross(w_str, q)
        k_t = (w - w_str) / ds + body_loads.cross(k, w_str)
        return q_t, k_t

    def balance(self, q, k, quat, v, w, v0, w0, tensions, gravity, rates=None):
        """Strain rates and the net force/torque densities at the velocity nodes.

        Returns (q_t, k_t, force, torque), each (N, 3), local frame; the
        accelerations are force / mass and torque / inertia. Every argument
        may carry a leading time axis: fields (n_t, N, 3), base velocities
        (n_t, 3), tensions (n_t, n_cables). ``rates`` = (q_t, k_t) skips
        the compatibility laws when the strain rates are known (zero at rest).
        """
        m = self.model
        ds = m.ds
        q_t, k_t = self.strain_rates(q, k, v, w, v0, w0) if rates is None else rates
        _, _, n_tot, m_tot = self.stresses(q, k, q_t, k_t, tensions)

        # Values at velocity nodes 1..N; at the tip the total stress vanishes.
        zero = np.zeros(3)
        n_next = _append(n_tot[..., 1:, :], zero)
        m_next = _append(m_tot[..., 1:, :], zero)
        k_next = _append(k[..., 1:, :], zero)
        q_next = _append(q[..., 1:, :], Q_STAR)

        force = (n_next - n_tot) / ds + body_loads.cross(k_next, n_next)
        force += body_loads.gyroscopic_force(w, m.mass, v)
        if np.any(gravity) and np.any(m.net_mass):
            force += body_loads.gravity_buoyancy(rotations.matrices(quat), m.net_mass, gravity)
        if m.drag:
            force += body_loads.drag(v, m.drag_coefficient)
        torque = ((m_next - m_tot) / ds + body_loads.cross(k_next, m_next)
                  + body_loads.cross(q_next, n_next) + body_loads.gyroscopic_torque(w, m.inertia))
        if m.munk_moment:
            torque += body_loads.munk_torque(v, m.added)
        return q_t, k_t, force, torque

    def tensions(self, t, y):
        """Tensions of all cables at (t, y), shape (n_cables,) [N]."""
        if self._feedback:
            return self.model.tensions(t, StateView(self.layout, t, y, self.model.ds))
        full = self._constant_tensions.copy()
        for i, cable in self._others:
            full[i] = cable.tension_at(t)
        return full

    def _classify_cables(self):
        """Sort the cables by how their tension is evaluated, once.

        The right-hand side needs the tensions at every call: constant
        tensions are read once here (slack cables are dropped from the kernel)
        and only the time-dependent ones are called each time. Feedback
        tensions read the state, so then every cable goes the general way.
        """
        cables = self.model.cables
        self._constant_tensions = np.zeros(len(cables))
        self._others, active = [], []
        for i, c in enumerate(cables):
            if isinstance(c.tension, ConstantTension):
                self._constant_tensions[i] = c.tension.value
                if c.tension.value == 0.0:
                    continue
            else:
                self._others.append((i, c))
            active.append(i)
        # Cables the kernel sees: all of them with feedback, else the non-slack ones.
        self._active = np.arange(len(cables)) if self._feedback else np.array(active, dtype=int)

    def __call__(self, t, y, out=None):
        """dy/dt at (t, y); writes into ``out`` if given (CVODE's ``yp``)."""
        if self.kernel == "numba":
            return self._compiled(t, y, out)
        return self._reference(t, y, out)

    def rates(self, t, states):
        """dy/dt at each of the frames ``states`` (n_t, size) at times ``t`` (n_t,).

        With the numba kernel this costs a few microseconds per frame.
        """
        states = np.asarray(states, dtype=float)
        out = np.empty_like(states)
        for i, (ti, yi) in enumerate(zip(np.asarray(t, dtype=float), states)):
            self(float(ti), yi, out[i])
        return out

    def _setup_compiled(self):
        """Pack the model for the compiled kernel, once (parameter arrays,
        cable geometry of the cables the kernel sees, input buffers)."""
        m = self.model
        self._params, self._consts, offsets, weights = upwind.pack_model(
            m, QUATERNION_RESTORING_RATE, body_loads.DRAG_SMOOTHING_SPEED)
        self._work = np.empty((m.n_elements, 6))
        self.base_velocities = np.zeros(6)
        self._fixed_base = m.base.fixed
        self._offsets = np.ascontiguousarray(offsets[self._active])
        self._weights = np.ascontiguousarray(weights[self._active])
        self.tension_values = np.ascontiguousarray(self._constant_tensions[self._active])
        # Positions in tension_values of the cables evaluated per call.
        where = {int(i): j for j, i in enumerate(self._active)}
        self._kernel_others = [(where[i], c) for i, c in self._others]

    def update_inputs(self, t, y=None):
        """Evaluate the time-dependent inputs of the compiled kernel at t, in place.

        Fills ``self.tension_values`` (the cables the kernel sees) and
        ``self.base_velocities`` (v0, w0). ``y`` (storage layout) is only
        read by feedback tensions.
        """
        tensions = self.tension_values
        if self._feedback:
            tensions[:] = self.model.tensions(t, StateView(self.layout, t, y, self.model.ds))
        else:
            for j, cable in self._kernel_others:
                tensions[j] = cable.tension_at(t)
        if not self._fixed_base:
            v0, w0 = self.model.base.velocities(t)
            self.base_velocities[:3], self.base_velocities[3:] = v0, w0

    def kernel_arguments(self):
        """Arguments of :func:`rodmol.upwind.rhs` after (y, out): the packed
        model, the input arrays refreshed by :meth:`update_inputs`, scratch."""
        return (self._params, self._consts, self._offsets, self._weights, self.tension_values,
                self.base_velocities, self._work)

    def _compiled(self, t, y, out=None):
        if out is None:
            out = np.empty(self.size)
        self.update_inputs(t, y)
        upwind.rhs(y, out, self._params, self._consts, self._offsets, self._weights,
                    self.tension_values, self.base_velocities, self._work)
        return out

    def _reference(self, t, y, out=None):
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
