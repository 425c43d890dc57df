"""External and actuation loads, as small pure functions of nodal fields.

All inputs and outputs are local-frame (material-frame) arrays of shape
(..., n, 3) unless stated otherwise (a leading time axis is allowed), and all loads are densities per unit of
reference arc length s: forces [N/m], torques [N m/m].
"""

import numpy as np

#: Smoothing speed [m/s] of |v| in the drag law, so the implicit solver's
#: Newton iterations see a differentiable right-hand side near v = 0.
DRAG_SMOOTHING_SPEED = 1e-6


def cross(a, b):
    """Row-wise cross product of (n, 3) arrays (faster than ``np.cross`` for small n)."""
    out = np.empty(np.broadcast_shapes(a.shape, b.shape))
    out[..., 0] = a[..., 1] * b[..., 2] - a[..., 2] * b[..., 1]
    out[..., 1] = a[..., 2] * b[..., 0] - a[..., 0] * b[..., 2]
    out[..., 2] = a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]
    return out


def gravity_buoyancy(rotations, net_mass, gravity):
    """Weight minus buoyancy (eq. 7): ``(rho - rho_w) A R^T G``.

    Parameters
    ----------
    rotations : (n, 3, 3) local-to-global rotation matrices.
    net_mass : (n,) net mass per length ``(rho - rho_w) A`` [kg/m].
    gravity : (3,) acceleration G [m/s^2], global frame.
    """
    return net_mass[:, None] * np.einsum("...ji,j->...i", rotations, gravity)


def drag(v, coefficient):
    """Morison drag (eq. 8): ``-rho_w |v| D v`` with |v| smoothed near 0.

    ``coefficient`` is ``rho_w diag(D)`` = rho_w (pi r Cx / 2, r Cy, r Cz), (n, 3) [kg/m^2].
    """
    speed = np.sqrt(np.einsum("...i,...i->...", v, v) + DRAG_SMOOTHING_SPEED**2)
    return -coefficient * speed[..., None] * v


def gyroscopic_force(w, mass, v):
    """``-w x (M v)``, M = diag(rho A + rho_w F): body plus added-mass momentum."""
    return -cross(w, mass * v)


def gyroscopic_torque(w, inertia):
    """``-w x (rho J w)``."""
    return -cross(w, inertia * w)


def munk_torque(v, added_mass):
    """Munk moment ``-v x (rho_w F v)`` of a Kirchhoff added-mass model (optional)."""
    return -cross(v, added_mass * v)


def cable_stress(q, k, offset, tension, weight):
    """Actuation stress of one cable: ``N_a = T H tau``, ``M_a = p x N_a``.

    The distributed load along the cable path and the concentrated load at
    its anchor are exactly the divergence of this stress in the balance laws
    (see ``docs/model.md``), so it is added to the body's internal stress.

    Parameters
    ----------
    q, k : (..., n, 3) strains at the strain nodes.
    offset : (3,) cable offset p = (0, p_y, p_z) [m], local frame.
    tension : float or (...,) array, T [N].
    weight : (n,) share of each strain node on the cable path (1 inside,
        0 beyond the anchor, fractional in the anchor's cell).
    """
    path = q + cross(k, offset)
    tau = path / np.sqrt(np.einsum("...i,...i->...", path, path))[..., None]
    n_a = np.multiply.outer(tension, weight)[..., None] * tau
    return n_a, cross(offset, n_a)
