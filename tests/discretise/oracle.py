"""An independent numpy implementation of the semi-discrete right-hand side.

Written from the equations of the paper's upwind scheme and of the centred
scheme (docs/model.md), not from rodmol's compiled functions: the sectional
data are sampled here from the rod, the material and the medium; cables, base motion, Munk moment and every
external load kind (point and distributed forces and moments in both frames,
plane and capsule contact with the C1-smoothed penalty, damping ramp and
regularised Coulomb friction) are evaluated here, vectorised over the nodes.
Only the *inputs* are read through rodmol: the user's time signals (tension
and load ``value(t)``, base velocity callables) and the state packing.

State (see rodmol.discretise.layout): base u0 (3), Q0 (4), then per element
b = 0..N-1 the block [u, Q, q, k, v, w] (pose and velocities of velocity node
b + 1, strains of strain node b).

Used only by the tests, to check the compiled system.
"""

import numpy as np

import rodmol

#: The constants the scheme is documented to use (rodmol.discretise.system).
RESTORING = 1.0
DRAG_SMOOTHING_SPEED = 1e-6
#: Default contact smoothing depth, fraction of the section radius.
SMOOTHING_FRACTION = 0.01

HEADER, BLOCK = 7, 19
FIELDS = {"u": slice(0, 3), "Q": slice(3, 7), "q": slice(7, 10), "k": slice(10, 13),
          "v": slice(13, 16), "w": slice(16, 19)}


# ----------------------------------------------------------------------------- algebra

def cross(a, b):
    return np.cross(a, b)


def dot(a, b):
    return np.einsum("...i,...i->...", a, b)


def rotation_matrices(quat):
    """R (..., 3, 3) of (possibly non-unit) quaternions: the rotation of Q/|Q|."""
    quat = np.asarray(quat, dtype=float)
    unit = quat / np.linalg.norm(quat, axis=-1, keepdims=True)
    a, b, c, d = np.moveaxis(unit, -1, 0)
    return np.stack([
        np.stack([a * a + b * b - c * c - d * d, 2 * (b * c - a * d), 2 * (b * d + a * c)], -1),
        np.stack([2 * (b * c + a * d), a * a - b * b + c * c - d * d, 2 * (c * d - a * b)], -1),
        np.stack([2 * (b * d - a * c), 2 * (c * d + a * b), a * a - b * b - c * c + d * d], -1),
    ], -2)


def quaternion_rate(quat, w):
    """Q (x) (0, w) / 2 + restoring (1 - |Q|^2) Q (Hamilton product)."""
    a = quat[..., :1]
    vec = quat[..., 1:]
    scalar = -0.5 * dot(vec, w)[..., None]
    vector = 0.5 * (a * w + cross(vec, w))
    pull = RESTORING * (1.0 - dot(quat, quat))[..., None]
    return np.concatenate([scalar, vector], axis=-1) + pull * quat


def global_to_local(r, x):
    return np.einsum("...ji,...j->...i", r, x)


def local_to_global(r, x):
    return np.einsum("...ij,...j->...i", r, x)


# ----------------------------------------------------------------------------- model data

class Sampled:
    """Sectional data of a model on its staggered grid, sampled from the rod:
    the upwind scheme samples the cells at their base-side node, the centred
    one at their midpoint, where its tip node stands for half a cell."""

    def __init__(self, model, scheme="upwind"):
        rod, mat, med = model.rod, model.rod.material, model.medium
        n = model.n_elements
        self.n, self.ds = n, rod.length / n
        self.centred = scheme == "centred"
        s = np.linspace(0.0, rod.length, n + 1)
        self.s = s
        s_str, s_vel = s[:-1], s[1:]
        self.lengths = np.full(n, self.ds)
        if self.centred:
            self.lengths[-1] = self.ds / 2
        s_cell = s_str + self.ds / 2 if self.centred else s_str
        r_str = np.asarray(rod.radius_at(s_cell))
        r_vel = np.asarray(rod.radius_at(s_vel))
        a_str, a_vel = np.pi * r_str**2, np.pi * r_vel**2
        j_str, j_vel = np.pi * r_str**4 / 4, np.pi * r_vel**4 / 4
        self.kl = a_str[:, None] * np.array([mat.E, mat.G, mat.G])
        self.kth = j_str[:, None] * np.array([2 * mat.G, mat.E, mat.E])
        mu = mat.mu if model.viscosity else 0.0
        self.vl = mu * a_str[:, None] * np.array([3.0, 1.0, 1.0])
        self.vth = mu * j_str[:, None] * np.array([2.0, 3.0, 3.0])
        given = mat.viscosity if model.viscosity and mat.viscosity is not None else None
        if given is not None:  # per-component viscosities [Pa s]: Vl = A eta, Vth = J eta
            eta_l = np.asarray(given.get("shear_extension", (3 * mu, mu, mu)))
            eta_th = np.asarray(given.get("bending_torsion", (mu, 3 * mu, 3 * mu)))
            self.vl = a_str[:, None] * eta_l
            self.vth = j_str[:, None] * np.array([2.0, 1.0, 1.0]) * eta_th
        added = (med.rho * a_vel[:, None] * np.array([0.0, med.By, med.Bz]) if model.added_mass
                 else np.zeros((n, 3)))
        self.added = added
        self.mass = mat.rho * a_vel[:, None] + added
        self.inertia = mat.rho * j_vel[:, None] * np.array([2.0, 1.0, 1.0])
        self.net_mass = (mat.rho - med.rho) * a_vel
        self.drag = (med.rho * r_vel[:, None] * np.array([0.5 * np.pi * med.Cx, med.Cy, med.Cz])
                     if model.drag else np.zeros((n, 3)))
        self.componentwise = model.drag and model.drag_law == "componentwise"
        if self.componentwise:  # C v|v| per component replaces the medium's drag
            self.drag = np.tile(np.asarray(model.drag_coefficients, dtype=float), (n, 1))
        # Rest strains q*, k* (the user's input, read through rodmol) where the cells are sampled.
        self.rest_q, self.rest_k = rod.rest_strains_at(s_cell)
        self.radius = r_vel  # at velocity nodes 1..N
        self.gravity = np.asarray(model.gravity, dtype=float)
        self.munk = bool(model.munk_moment)
        # Routing p(s) (the user's input, read through rodmol): p at the cell's
        # sampling point, p' as the difference of p across the cell.
        self.offsets = np.zeros((len(model.cables), n, 3))
        self.slopes = np.zeros((len(model.cables), n, 3))
        for j, c in enumerate(model.cables):
            self.offsets[j, :, 1:] = c.offset_at(s_cell)
            self.slopes[j, :, 1:] = np.diff(c.offset_at(s), axis=0) / self.ds
        anchors = np.array([c.anchor for c in model.cables]).reshape(-1, 1)
        self.cable_weights = np.clip((anchors - s_str[None, :]) / self.ds, 0.0, 1.0)


def unpack(y, n):
    blocks = np.asarray(y)[HEADER:].reshape(n, BLOCK)
    return {f: blocks[:, sl] for f, sl in FIELDS.items()}


# ----------------------------------------------------------------------------- laws

def strain_rates(q, k, v, w, v0, w0, ds, centred=False):
    """Compatibility (eq. 2), differences across each cell (cell 0 starts at
    the base); the other terms with the base-side node's velocities
    (upwind) or the average of both nodes' (centred)."""
    v_str = np.vstack([v0, v[:-1]])
    w_str = np.vstack([w0, w[:-1]])
    v_bar, w_bar = ((v + v_str) / 2, (w + w_str) / 2) if centred else (v_str, w_str)
    q_t = (v - v_str) / ds + cross(k, v_bar) - cross(w_bar, q)
    k_t = (w - w_str) / ds + cross(k, w_bar)
    return q_t, k_t


def cable_stress(q, k, p, dp, tension):
    """N_a = T tau, tau = (q + k x p + p')/|q + k x p + p'|, M_a = p x N_a;
    p, p' (n, 3) and tension (n,) per cell."""
    c = q + cross(k, p) + dp
    n_a = tension[:, None] * c / np.linalg.norm(c, axis=1, keepdims=True)
    return n_a, cross(p, n_a)


def friction_factors(model, data, q, k, v, w, v0, w0):
    """T(cell) / T(base) per cable and cell (n_cables, N) of the regularised
    capstan law (docs/model.md), cell by cell: the path's curvature
    |tau' + k x tau| (tau' by central differences, one-sided at the ends),
    the sliding speed from the rate of change of the path length beyond the
    cell (strain rates of the compatibility laws with centred velocities),
    and the wrap to the middle of the cell."""
    n, ds = data.n, data.ds
    q_t, k_t = strain_rates(q, k, v, w, v0, w0, ds, centred=True)
    factors = np.ones((len(model.cables), n))
    for j, cable in enumerate(model.cables):
        tau, rate = np.zeros((n, 3)), np.zeros(n)
        for i in range(n):
            c = q[i] + np.cross(k[i], data.offsets[j, i]) + data.slopes[j, i]
            tau[i] = c / np.linalg.norm(c)
            rate[i] = tau[i] @ (q_t[i] + np.cross(k_t[i], data.offsets[j, i]))
        wrap = 0.0
        for i in range(n):
            if n == 1:
                dtau = np.zeros(3)
            elif i == 0:
                dtau = (tau[1] - tau[0]) / ds
            elif i == n - 1:
                dtau = (tau[-1] - tau[-2]) / ds
            else:
                dtau = (tau[i + 1] - tau[i - 1]) / (2 * ds)
            kappa = np.linalg.norm(dtau + np.cross(k[i], tau[i]))
            beyond = ds * np.sum(data.cable_weights[j, i:] * rate[i:])
            sigma = -beyond / np.hypot(beyond, cable.slip_speed)
            turn = cable.friction * sigma * kappa * data.cable_weights[j, i] * ds
            factors[j, i] = np.exp(-(wrap + turn / 2))
            wrap += turn
    return factors


def stresses(data, q, k, q_t, k_t, tensions):
    """(N_el, M_el, N_tot, M_tot) at the strain nodes."""
    n_el = data.kl * (q - data.rest_q) + data.vl * q_t
    m_el = data.kth * (k - data.rest_k) + data.vth * k_t
    n_tot, m_tot = n_el.copy(), m_el.copy()
    tensions = np.asarray(tensions, dtype=float)
    tensions = np.broadcast_to(tensions[:, None] if tensions.ndim == 1 else tensions, data.cable_weights.shape)
    for p, dp, tension, weight in zip(data.offsets, data.slopes, tensions, data.cable_weights):
        n_a, m_a = cable_stress(q, k, p, dp, tension * weight)
        n_tot += n_a
        m_tot += m_a
    return n_el, m_el, n_tot, m_tot


def penalty(depth, h):
    """(measure, ramp) of the C1 penalty: d - h/2 beyond h, d^2/(2h) below, 0 outside."""
    depth = np.asarray(depth, dtype=float)
    measure = np.where(depth >= h, depth - 0.5 * h, 0.5 * depth**2 / h)
    ramp = np.where(depth >= h, 1.0, depth / h)
    inside = depth > 0.0
    return np.where(inside, measure, 0.0), np.where(inside, ramp, 0.0)


def contact_geometry(obstacle, u, radius):
    """Penetration depth (n,) and global outward normal (n, 3) of tube sections at u."""
    if isinstance(obstacle, rodmol.PlaneContact):
        nrm = np.asarray(obstacle.normal, dtype=float)
        depth = radius - (u - np.asarray(obstacle.point)) @ nrm
        return depth, np.broadcast_to(nrm, u.shape)
    a, b = np.asarray(obstacle.start, dtype=float), np.asarray(obstacle.end, dtype=float)
    axis = b - a
    l2 = axis @ axis
    x = np.zeros(len(u)) if l2 == 0.0 else np.clip((u - a) @ axis / l2, 0.0, 1.0)
    d = u - (a + x[:, None] * axis)
    dist = np.linalg.norm(d, axis=1)
    return obstacle.radius + radius - dist, d / dist[:, None]


def contact_loads(obstacle, data, u, r, v, w):
    """Penalty force with damping ramp and regularised friction at the surface point;
    (force, moment) densities, local frame, (N, 3) each."""
    radius = data.radius
    h = (SMOOTHING_FRACTION * radius if obstacle.smoothing_depth is None
         else np.full(len(u), obstacle.smoothing_depth))
    depth, n_glob = contact_geometry(obstacle, u, radius)
    measure, ramp = penalty(depth, h)
    n = global_to_local(r, n_glob)
    arm = -radius[:, None] * n
    vp = v + cross(w, arm)
    vn = dot(vp, n)
    normal = obstacle.stiffness * measure - ramp * obstacle.damping * vn
    normal = np.where(measure > 0.0, np.maximum(normal, 0.0), 0.0)
    vt = vp - vn[:, None] * n
    slip = np.sqrt(dot(vt, vt) + obstacle.slip_speed**2)
    f = normal[:, None] * n - (obstacle.friction * normal / slip)[:, None] * vt
    return f, cross(arm, f)


def point_shares(s, data):
    """Weight [1/m] of a point load at s on velocity nodes 1..N (hat functions
    over the length each node stands for)."""
    x = s / data.ds
    nodes = np.arange(1, data.n + 1)
    return np.maximum(0.0, 1.0 - np.abs(x - nodes)) / data.lengths


def external_loads(model, data, t, quat, u, v, w):
    """Sum of the external load densities at the velocity nodes, local frame."""
    r = rotation_matrices(quat)
    force, moment = np.zeros((data.n, 3)), np.zeros((data.n, 3))

    def add(target, values, frame):
        target += values if frame == "local" else global_to_local(r, values)

    for load in model.loads:
        if isinstance(load, (rodmol.PointForce, rodmol.PointMoment)):
            is_force = isinstance(load, rodmol.PointForce)
            value = np.asarray((load.force if is_force else load.moment).value(t), dtype=float)
            values = point_shares(load.s, data)[:, None] * value
            add(force if is_force else moment, values, load.frame)
        elif isinstance(load, (rodmol.DistributedForce, rodmol.DistributedMoment)):
            is_force = isinstance(load, rodmol.DistributedForce)
            spec = load.force if is_force else load.moment
            s = data.s[1:]
            values = (np.broadcast_to(np.asarray(spec(s, t), dtype=float), (data.n, 3)) if callable(spec)
                      else np.tile(np.asarray(spec, dtype=float), (data.n, 1)))
            add(force if is_force else moment, values, load.frame)
        else:  # contact
            f, m = contact_loads(load, data, u, r, v, w)
            force += f
            moment += m
    return force, moment


def rates(model, t, y, tensions=None, scheme="upwind"):
    """dy/dt of the upwind or the centred scheme at (t, y)."""
    data = Sampled(model, scheme)
    n, ds = data.n, data.ds
    fld = unpack(y, n)
    u, quat, q, k, v, w = (fld[f] for f in ("u", "Q", "q", "k", "v", "w"))
    v0, w0 = (np.asarray(x, dtype=float) for x in model.base.velocities(t))
    if tensions is None:
        tensions = np.array([c.tension_at(t) for c in model.cables])

    q_t, k_t = strain_rates(q, k, v, w, v0, w0, ds, data.centred)
    if any(c.friction > 0 for c in model.cables):  # tension per cell
        tensions = np.asarray(tensions, dtype=float)[:, None] * friction_factors(model, data, q, k, v, w, v0, w0)
    _, _, n_tot, m_tot = stresses(data, q, k, q_t, k_t, tensions)

    # Velocity nodes 1..N: differences of the total stress of the cells
    # around them; it vanishes beyond the tip, and so do its products.
    zero = np.zeros((1, 3))
    n_next, m_next = np.vstack([n_tot[1:], zero]), np.vstack([m_tot[1:], zero])
    k_next, q_next = np.vstack([k[1:], zero]), np.vstack([q[1:], zero])
    f_cells = cross(k_next, n_next)
    t_cells = cross(k_next, m_next) + cross(q_next, n_next)
    if data.centred:
        f_cells = (f_cells + cross(k, n_tot)) / 2
        t_cells = (t_cells + cross(k, m_tot) + cross(q, n_tot)) / 2
        f_cells[-1] *= 2  # the tip node's half cell: its one cell's product
        t_cells[-1] *= 2
    r = rotation_matrices(quat)
    f_ext, m_ext = external_loads(model, data, t, quat, u, v, w)
    lengths = data.lengths[:, None]

    if data.componentwise:  # |v_i| per component
        speed = np.sqrt(v * v + DRAG_SMOOTHING_SPEED**2)
    else:
        speed = np.sqrt(dot(v, v) + DRAG_SMOOTHING_SPEED**2)[:, None]
    force = ((n_next - n_tot) / lengths + f_cells
             - cross(w, data.mass * v)
             + data.net_mass[:, None] * global_to_local(r, data.gravity)
             - speed * data.drag * v
             + f_ext)
    torque = ((m_next - m_tot) / lengths + t_cells
              - cross(w, data.inertia * w) + m_ext)
    if data.munk:
        torque -= cross(v, data.added * v)

    out = np.empty(len(y))
    ob = out[HEADER:].reshape(n, BLOCK)
    ob[:, FIELDS["u"]] = local_to_global(r, v)
    ob[:, FIELDS["Q"]] = quaternion_rate(quat, w)
    ob[:, FIELDS["q"]] = q_t
    ob[:, FIELDS["k"]] = k_t
    ob[:, FIELDS["v"]] = force / data.mass
    ob[:, FIELDS["w"]] = torque / data.inertia
    quat0 = np.asarray(y[3:7])
    out[:3] = rotation_matrices(quat0) @ v0
    out[3:7] = quaternion_rate(quat0, w0)
    return out


# ----------------------------------------------------------------------------- test states

def _contact_positions(model, y, rng):
    """Place the velocity nodes around each contact obstacle: outside, inside the
    smoothing layer and beyond it."""
    lay = rodmol.StateLayout(model.n_elements)
    u = lay.field(y, "u")
    radius = model.rod.radius_at(model.s_nodes[1:])
    for load in model.loads:
        if not isinstance(load, (rodmol.PlaneContact, rodmol.CapsuleContact)):
            continue
        h = 0.01 * radius if load.smoothing_depth is None else np.full(len(radius), load.smoothing_depth)
        depth = h * rng.choice([-5.0, 0.3, 0.7, 2.0, 10.0, 40.0], size=len(radius))
        if isinstance(load, rodmol.PlaneContact):
            n = load.normal
            tangent = rng.normal(size=(len(radius), 3)) * 0.1
            tangent -= np.outer(tangent @ n, n)
            u[:] = load.point + tangent + (radius - depth)[:, None] * n
        else:
            a, b = load.start, load.end
            x = rng.uniform(-0.2, 1.2, size=len(radius))
            centre = a + np.clip(x, 0.0, 1.0)[:, None] * (b - a)
            d = rng.normal(size=(len(radius), 3))
            if np.any(b != a):
                axis = (b - a) / np.linalg.norm(b - a)
                inner = (x > 0) & (x < 1)
                d[inner] -= np.outer(d[inner] @ axis, axis)  # lateral where the cylinder is
            d /= np.linalg.norm(d, axis=1, keepdims=True)
            u[:] = centre + (load.radius + radius - depth)[:, None] * d
    return y


def generic_state(model, rng, contact=True):
    """A perturbed straight rod, moving, with |Q| != 1 (and contact if any)."""
    n = model.n_elements
    lay = rodmol.StateLayout(n)
    y = rodmol.straight_state(model)
    b = lay.blocks(y)
    b[:, 3:7] += 0.2 * rng.normal(size=(n, 4))
    y[3:7] += 0.02 * rng.normal(size=4)
    lay.field(y, "q")[:] += 0.03 * rng.normal(size=(n, 3))
    lay.field(y, "k")[:] = 2.0 * rng.normal(size=(n, 3))
    lay.field(y, "v")[:] = 0.1 * rng.normal(size=(n, 3))
    lay.field(y, "w")[:] = 1.0 * rng.normal(size=(n, 3))
    lay.field(y, "u")[:] += 0.01 * rng.normal(size=(n, 3))
    return _contact_positions(model, y, rng) if contact else y
