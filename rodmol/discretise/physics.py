"""The per-node physics of the Cosserat rod, written once, compiled by numba.

Small functions of 3-vectors (tuples of floats, so that numba keeps them in
registers) that every driver calls: the scheme's compiled loop
(:mod:`rodmol.discretise.stencil`) for integration, and through it the static
equilibrium and the post-processing. All vectors are in the local (material)
frame unless the name says global; ``R`` (a 9-tuple, row major) maps local to
global. Loads are densities per unit of reference arc length: forces [N/m],
moments [N m/m].

``tests/discretise/oracle.py`` holds an independent numpy implementation of the same
equations, used only to test these.
"""

import numpy as np

from .compiling import jit

# --------------------------------------------------------------------------- vectors

@jit
def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


@jit
def dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


@jit
def add(a, b):
    return (a[0] + b[0], a[1] + b[1], a[2] + b[2])


@jit
def sub(a, b):
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


@jit
def scale(c, a):
    return (c * a[0], c * a[1], c * a[2])


@jit
def mul(a, b):
    """Component-wise product (a diagonal matrix times a vector)."""
    return (a[0] * b[0], a[1] * b[1], a[2] * b[2])


@jit
def rotation(quat):
    """R (9-tuple, row major) of a quaternion (a, b, c, d), normalised on the fly:
    dividing by |Q|^2 keeps R orthogonal if the integrated quaternion drifts."""
    a, b, c, d = quat
    f = 2.0 / (a * a + b * b + c * c + d * d)
    return (1.0 - f * (c * c + d * d), f * (b * c - a * d), f * (b * d + a * c),
            f * (b * c + a * d), 1.0 - f * (b * b + d * d), f * (c * d - a * b),
            f * (b * d - a * c), f * (c * d + a * b), 1.0 - f * (b * b + c * c))


@jit
def to_global(r, x):
    """R x."""
    return (r[0] * x[0] + r[1] * x[1] + r[2] * x[2],
            r[3] * x[0] + r[4] * x[1] + r[5] * x[2],
            r[6] * x[0] + r[7] * x[1] + r[8] * x[2])


@jit
def to_local(r, x):
    """R^T x."""
    return (r[0] * x[0] + r[3] * x[1] + r[6] * x[2],
            r[1] * x[0] + r[4] * x[1] + r[7] * x[2],
            r[2] * x[0] + r[5] * x[1] + r[8] * x[2])


@jit
def quaternion_product(p, q):
    """p (x) q of quaternions (a, b, c, d), scalar first."""
    a1, b1, c1, d1 = p
    a2, b2, c2, d2 = q
    return (a1 * a2 - b1 * b2 - c1 * c2 - d1 * d2,
            a1 * b2 + b1 * a2 + c1 * d2 - d1 * c2,
            a1 * c2 - b1 * d2 + c1 * a2 + d1 * b2,
            a1 * d2 + b1 * c2 - c1 * b2 + d1 * a2)


@jit
def rotation_vector_quaternion(theta):
    """The quaternion of the rotation exp([theta]x), theta [rad]."""
    angle = np.sqrt(dot(theta, theta))
    half = 0.5 * angle
    # sin(x/2)/x without the 0/0 at x = 0
    f = np.sin(half) / angle if angle > 1e-8 else 0.5 - angle * angle / 48.0
    return (np.cos(half), f * theta[0], f * theta[1], f * theta[2])


@jit
def chord(quat, q, k, ds):
    """Chord [m], global, of an element of length ds from a node of orientation
    ``quat`` with constant strains q, k: ds R(mid) q with R(mid) = R exp(ds k / 2)
    (the midpoint rule: second order, exact for the straight rod)."""
    mid = quaternion_product(quat, rotation_vector_quaternion(scale(0.5 * ds, k)))
    return scale(ds, to_global(rotation(mid), q))


@jit
def quaternion_rate(quat, w, restoring):
    """Q_t = Q (x) (0, w) / 2 + restoring (1 - |Q|^2) Q: the exact kinematics
    keep |Q| = 1, the second term only damps integration drift."""
    a, b, c, d = quat
    pull = restoring * (1.0 - (a * a + b * b + c * c + d * d))
    return (-0.5 * (b * w[0] + c * w[1] + d * w[2]) + pull * a,
            0.5 * (a * w[0] + c * w[2] - d * w[1]) + pull * b,
            0.5 * (a * w[1] + d * w[0] - b * w[2]) + pull * c,
            0.5 * (a * w[2] + b * w[1] - c * w[0]) + pull * d)


# --------------------------------------------------------------------------- sections

@jit
def strain_rate_terms(q, k, v, w):
    """The non-derivative terms of the compatibility laws (eq. 2):
    q_t = v' + (k x v - w x q), k_t = w' + k x w."""
    return sub(cross(k, v), cross(w, q)), cross(k, w)


@jit
def kelvin_voigt(kl, kth, vl, vth, q, k, q_t, k_t, rest_q, rest_k):
    """Sectional stress (eq. 5) measured from the rest strains q* = ``rest_q``
    [-] and k* = ``rest_k`` [1/m]: N = Kl (q - q*) + Vl q_t, M = Kth (k - k*)
    + Vth k_t; the diagonals are [N, N m^2, N s, N m^2 s]."""
    return add(mul(kl, sub(q, rest_q)), mul(vl, q_t)), add(mul(kth, sub(k, rest_k)), mul(vth, k_t))


@jit
def cable_stress(q, k, p, dp, tension):
    """Actuation stress of a cable at offset p (slope p' = ``dp`` along s)
    pulled with ``tension`` [N]: N_a = T tau, M_a = p x N_a,
    tau = (q + k x p + p') / |q + k x p + p'|.

    Its divergence in the balance laws is exactly the distributed load along
    the cable path plus the concentrated load at the anchor (docs/model.md).
    """
    c = path_vector(q, k, p, dp)
    n_a = scale(tension / np.sqrt(dot(c, c)), c)
    return n_a, cross(p, n_a)


@jit
def path_vector(q, k, p, dp):
    """c = q + k x p + p': the cable path's tangent u_c' = R c, local frame
    (its length is the path's stretch, its direction the cable's)."""
    return add(add(q, cross(k, p)), dp)


# --------------------------------------------------------------------------- body loads

@jit
def body_force(mass, net_mass, drag, r, gravity, v, w, smoothing2):
    """Force density on the body at rest in a fluid, local frame [N/m]:
    gyroscopic -w x (M v) with M = rho A + rho_w F (added mass); weight minus
    buoyancy (rho - rho_w) A R^T G (eq. 7); Morison drag -rho_w |v| D v
    (eq. 8, ``drag`` = rho_w diag D) with |v| smoothed by ``smoothing2`` [m^2/s^2]."""
    f = scale(-1.0, cross(w, mul(mass, v)))
    f = add(f, scale(net_mass, to_local(r, gravity)))
    speed = np.sqrt(dot(v, v) + smoothing2)
    return sub(f, scale(speed, mul(drag, v)))


@jit
def componentwise_drag(coefficients, v, smoothing2):
    """Drag law C v|v| per local component (Till's tendon robot), returned
    with the sign of v (subtract it) [N/m]; ``coefficients`` C [kg/m^2],
    |v_i| smoothed as sqrt(v_i^2 + ``smoothing2``)."""
    return (coefficients[0] * v[0] * np.sqrt(v[0] * v[0] + smoothing2),
            coefficients[1] * v[1] * np.sqrt(v[1] * v[1] + smoothing2),
            coefficients[2] * v[2] * np.sqrt(v[2] * v[2] + smoothing2))


@jit
def body_torque(inertia, added, munk, v, w):
    """Torque density [N m/m]: gyroscopic -w x (rho J w), and with ``munk``
    the Munk moment -v x (rho_w F v) of a Kirchhoff added-mass model."""
    t = scale(-1.0, cross(w, mul(inertia, w)))
    if munk:
        t = sub(t, cross(v, mul(added, v)))
    return t
