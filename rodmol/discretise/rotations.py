"""Unit quaternions (scalar first) and rotation matrices, vectorised over rows."""

import numpy as np

from .physics import jit


def matrices(quat):
    """Rotation matrices (..., 3, 3) of quaternions (..., 4), normalised on the fly.

    Dividing by |Q|^2 keeps R exactly orthogonal even if the integrated
    quaternion has drifted off the unit sphere.
    """
    quat = np.asarray(quat, dtype=float)
    out = np.empty(quat.shape[:-1] + (3, 3))
    _matrices(np.ascontiguousarray(quat).reshape(-1, 4), out.reshape(-1, 3, 3))
    return out


@jit
def _matrices(quat, out):
    # One pass over the rows (the numpy version made nine temporaries per
    # entry): post-processing calls this on every frame of long runs.
    for n in range(quat.shape[0]):
        a, b, c, d = quat[n, 0], quat[n, 1], quat[n, 2], quat[n, 3]
        f = 2.0 / (a * a + b * b + c * c + d * d)
        out[n, 0, 0] = 1.0 - f * (c * c + d * d)
        out[n, 0, 1] = f * (b * c - a * d)
        out[n, 0, 2] = f * (b * d + a * c)
        out[n, 1, 0] = f * (b * c + a * d)
        out[n, 1, 1] = 1.0 - f * (b * b + d * d)
        out[n, 1, 2] = f * (c * d - a * b)
        out[n, 2, 0] = f * (b * d - a * c)
        out[n, 2, 1] = f * (c * d + a * b)
        out[n, 2, 2] = 1.0 - f * (b * b + c * c)


def rate(quat, omega):
    """dQ/dt = Q (x) (0, omega) / 2 for a body-frame angular velocity omega (..., 3)."""
    a, b, c, d = (quat[..., i] for i in range(4))
    w1, w2, w3 = (omega[..., i] for i in range(3))
    out = np.empty(quat.shape)
    out[..., 0] = -0.5 * (b * w1 + c * w2 + d * w3)
    out[..., 1] = 0.5 * (a * w1 + c * w3 - d * w2)
    out[..., 2] = 0.5 * (a * w2 + d * w1 - b * w3)
    out[..., 3] = 0.5 * (a * w3 + b * w2 - c * w1)
    return out


def multiply(p, q):
    """Quaternion product p (x) q, rows broadcast."""
    a1, b1, c1, d1 = (p[..., i] for i in range(4))
    a2, b2, c2, d2 = (q[..., i] for i in range(4))
    return np.stack([
        a1 * a2 - b1 * b2 - c1 * c2 - d1 * d2,
        a1 * b2 + b1 * a2 + c1 * d2 - d1 * c2,
        a1 * c2 - b1 * d2 + c1 * a2 + d1 * b2,
        a1 * d2 + b1 * c2 - c1 * b2 + d1 * a2,
    ], axis=-1)


def from_rotation_vector(theta):
    """Quaternion of the rotation exp([theta]x), theta (..., 3) [rad]."""
    angle = np.linalg.norm(theta, axis=-1)
    half = 0.5 * angle
    # sin(x/2)/x without the 0/0 at x = 0
    scale = np.where(angle > 1e-8, np.sin(half) / np.where(angle > 1e-8, angle, 1.0),
                     0.5 - angle**2 / 48.0)
    return np.concatenate([np.cos(half)[..., None], scale[..., None] * theta], axis=-1)


def from_matrix(r):
    """Quaternion (4,) of a rotation matrix (3, 3) (Shepperd's method)."""
    r = np.asarray(r, dtype=float)
    tr = np.trace(r)
    i = int(np.argmax([tr, r[0, 0], r[1, 1], r[2, 2]]))
    if i == 0:
        s = 2.0 * np.sqrt(1.0 + tr)
        q = [0.25 * s, (r[2, 1] - r[1, 2]) / s, (r[0, 2] - r[2, 0]) / s, (r[1, 0] - r[0, 1]) / s]
    elif i == 1:
        s = 2.0 * np.sqrt(1.0 + 2 * r[0, 0] - tr)
        q = [(r[2, 1] - r[1, 2]) / s, 0.25 * s, (r[0, 1] + r[1, 0]) / s, (r[0, 2] + r[2, 0]) / s]
    elif i == 2:
        s = 2.0 * np.sqrt(1.0 + 2 * r[1, 1] - tr)
        q = [(r[0, 2] - r[2, 0]) / s, (r[0, 1] + r[1, 0]) / s, 0.25 * s, (r[1, 2] + r[2, 1]) / s]
    else:
        s = 2.0 * np.sqrt(1.0 + 2 * r[2, 2] - tr)
        q = [(r[1, 0] - r[0, 1]) / s, (r[0, 2] + r[2, 0]) / s, (r[1, 2] + r[2, 1]) / s, 0.25 * s]
    q = np.array(q)
    return q if q[0] >= 0 else -q
