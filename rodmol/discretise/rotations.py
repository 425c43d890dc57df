"""Unit quaternions (scalar first) and rotation matrices, vectorised over rows."""

import numba
import numpy as np

from .compiling import jit, strided
from .physics import quaternion_product, rotation, rotation_vector_quaternion, to_global


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
        r = rotation((quat[n, 0], quat[n, 1], quat[n, 2], quat[n, 3]))
        for i in range(3):
            out[n, i, 0], out[n, i, 1], out[n, i, 2] = r[3 * i], r[3 * i + 1], r[3 * i + 2]


def normalise(quat):
    """Scale quaternions (..., m, 4) (a strided view, e.g. of states) to unit norm, in place."""
    _normalise(quat.reshape((-1,) + quat.shape[-2:]))


@jit(signature=numba.types.void(strided(3, writes=True)), ahead=True)
def _normalise(quat):
    # Compiled: the numpy version took a tenth of the solver's time on 6001
    # frames at N = 100 (temporaries per entry of a strided view).
    for i in range(quat.shape[0]):
        for j in range(quat.shape[1]):
            norm = np.sqrt(quat[i, j, 0] ** 2 + quat[i, j, 1] ** 2 + quat[i, j, 2] ** 2 + quat[i, j, 3] ** 2)
            for c in range(4):
                quat[i, j, c] /= norm


def rotate(matrices, vectors, out=None):
    """R v (n_t, n, 3) for rotation matrices R (n_t, n, 3, 3) and vectors v (n_t, n, 3): local
    vectors to the global frame. Strided arrays are read, and ``out`` written, in place."""
    matrices, vectors = np.asarray(matrices, dtype=float), np.asarray(vectors, dtype=float)
    out = np.empty(vectors.shape) if out is None else out
    _rotate(matrices.reshape(matrices.shape[:-2] + (9,)), vectors, out)  # rows of R: a view
    return out


@jit(signature=numba.types.void(strided(3), strided(3), strided(3, writes=True)), ahead=True)
def _rotate(m, v, out):
    for f in range(v.shape[0]):
        for n in range(v.shape[1]):
            out[f, n, 0], out[f, n, 1], out[f, n, 2] = to_global(m[f, n], (v[f, n, 0], v[f, n, 1], v[f, n, 2]))


def multiply(p, q):
    """Quaternion product p (x) q, rows broadcast (``physics.quaternion_product``)."""
    p, q = np.broadcast_arrays(np.asarray(p, dtype=float), np.asarray(q, dtype=float))
    out = np.empty(p.shape)
    _rows(np.ascontiguousarray(p).reshape(-1, 4), np.ascontiguousarray(q).reshape(-1, 4), out.reshape(-1, 4))
    return out


@jit
def _rows(p, q, out):
    for n in range(p.shape[0]):
        out[n, 0], out[n, 1], out[n, 2], out[n, 3] = quaternion_product(
            (p[n, 0], p[n, 1], p[n, 2], p[n, 3]), (q[n, 0], q[n, 1], q[n, 2], q[n, 3]))


def from_rotation_vector(theta):
    """Quaternion of the rotation exp([theta]x), theta (..., 3) [rad]
    (``physics.rotation_vector_quaternion``)."""
    theta = np.ascontiguousarray(theta, dtype=float)
    out = np.empty(theta.shape[:-1] + (4,))
    _exp_rows(theta.reshape(-1, 3), out.reshape(-1, 4))
    return out


@jit
def _exp_rows(theta, out):
    for n in range(theta.shape[0]):
        out[n, 0], out[n, 1], out[n, 2], out[n, 3] = rotation_vector_quaternion(
            (theta[n, 0], theta[n, 1], theta[n, 2]))


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
