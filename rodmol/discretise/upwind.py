"""Compiled (numba) right-hand side of the semi-discrete system.

:class:`rodmol.semidiscrete.SemiDiscrete` keeps the vectorised numpy code as
the reference (``balance``/``stresses``, also used for post-processing with a
leading time axis); :func:`rhs` computes the same ``dy/dt`` in two loops over
the nodes, with no temporary arrays, which is what an implicit solver calling
it thousands of times needs. ``tests/test_kernels.py`` checks that both agree
to round-off. The compiled Jacobian and the block preconditioner of CVODE's
Newton systems built on it are in :mod:`rodmol.jacobian`.

numba is an optional-but-default dependency: without it, :data:`AVAILABLE` is
False, ``SemiDiscrete`` falls back to the numpy path with a warning and CVODE
to its band solver.

Packing of the sampled model (built once by :func:`pack_model`):

* ``params`` (N, 25): per element, the constant sectional data the loops read
  together, one row per element so that each row is one or two cache lines;
  columns given by the ``P_*`` offsets below.
* ``consts`` (7,): ds, quaternion restoring rate, drag smoothing speed^2,
  Munk switch (0/1), gravity (3).
* ``offsets`` (n_c, 3), ``weights`` (n_c, N): cable offsets and their share
  of each strain node's cell.
* ``tensions`` (n_c,) and ``base`` (6,) = (v0, w0): filled in place by the
  caller at every call (they are the only time-dependent inputs).
"""

import numpy as np

try:  # numba is optional: the numpy reference path works without it
    import numba
except ImportError:  # pragma: no cover - exercised only where numba is absent
    numba = None

from .layout import BLOCK, HEADER

#: True if the compiled kernels can be used.
AVAILABLE = numba is not None

# Column offsets of the per-element parameter rows.
P_KL, P_KTH, P_VL, P_VTH, P_MASS, P_INERTIA = 0, 3, 6, 9, 12, 15
P_NET_MASS, P_DRAG, P_ADDED = 18, 19, 22
N_PARAMS = 25

# Offsets inside an element block (rodmol.layout): the pose (u, Q) first,
# then (q, k, v, w), addressed from the start of q.
P_U, P_QUAT = 0, 3
A_Q, A_K, A_V, A_W = 0, 3, 6, 9
N_PASSIVE = 7


def _jit(fn=None, *, signature=None):
    """numba.njit, or the plain function without numba.

    cache=True: the machine code is stored on disk (next to this file, or in
    numba's user cache if that is read-only), so only the first process ever
    pays the compilation. error_model="numpy" drops the Python-style
    zero-division checks from the inner loops. An explicit ``signature``
    compiles once, at import, instead of once per argument type.
    """
    if fn is None:
        return lambda f: _jit(f, signature=signature)
    if numba is None:
        return fn
    if signature is None:
        return numba.njit(cache=True, error_model="numpy")(fn)
    return numba.njit(signature, cache=True, error_model="numpy")(fn)


def _rhs_signature():
    # The state comes read-only from CVODE and writable from everywhere else;
    # numba would compile the (large) kernel once for each. Typing it
    # read-only accepts both with a single compilation.
    if numba is None:
        return None
    f1, f2 = numba.types.float64[::1], numba.types.float64[:, ::1]
    return numba.types.void(f1.copy(readonly=True), f1, f2, f1, f2, f2, f1, f1, f2)


def pack_model(model, restoring_rate, drag_smoothing_speed):
    """Arrays (params, consts, offsets, weights) of ``model`` for :func:`rhs`."""
    n = model.n_elements
    params = np.empty((n, N_PARAMS))
    params[:, P_KL:P_KL + 3] = model.kl
    params[:, P_KTH:P_KTH + 3] = model.kth
    params[:, P_VL:P_VL + 3] = model.vl
    params[:, P_VTH:P_VTH + 3] = model.vth
    params[:, P_MASS:P_MASS + 3] = model.mass
    params[:, P_INERTIA:P_INERTIA + 3] = model.inertia
    params[:, P_NET_MASS] = model.net_mass
    params[:, P_DRAG:P_DRAG + 3] = model.drag_coefficient if model.drag else 0.0
    params[:, P_ADDED:P_ADDED + 3] = model.added
    consts = np.array([model.ds, restoring_rate, drag_smoothing_speed**2,
                       1.0 if model.munk_moment else 0.0, *model.gravity])
    offsets = np.ascontiguousarray(model.cable_offsets, dtype=float).reshape(-1, 3)
    weights = np.ascontiguousarray(model.cable_weights, dtype=float).reshape(len(offsets), n)
    return params, consts, offsets, weights


@_jit
def _quaternion_rate(y, j, w0, w1, w2, restoring, out):
    """Q_t = Q (x) (0, w) / 2 + rate (1 - |Q|^2) Q for the quaternion at y[j:j+4]."""
    a, b, c, d = y[j], y[j + 1], y[j + 2], y[j + 3]
    pull = restoring * (1.0 - (a * a + b * b + c * c + d * d))
    out[j] = -0.5 * (b * w0 + c * w1 + d * w2) + pull * a
    out[j + 1] = 0.5 * (a * w0 + c * w2 - d * w1) + pull * b
    out[j + 2] = 0.5 * (a * w1 + d * w0 - b * w2) + pull * c
    out[j + 3] = 0.5 * (a * w2 + b * w1 - c * w0) + pull * d


@_jit(signature=_rhs_signature())
def rhs(y, out, params, consts, offsets, weights, tensions, base, work):
    """dy/dt of the semi-discrete system into ``out``; ``work`` is (N, 6) scratch.

    Same equations and the same order of operations as
    ``SemiDiscrete.balance`` and ``SemiDiscrete.__call__`` (see there); the
    state is in the storage layout of :mod:`rodmol.layout`.
    """
    n = params.shape[0]
    ds = consts[0]
    restoring = consts[1]
    eps2 = consts[2]
    munk = consts[3] != 0.0
    g0, g1, g2 = consts[4], consts[5], consts[6]

    # Pass 1, strain nodes i = 0..N-1: strain rates (compatibility, forward
    # differences of v, w) and the Kelvin-Voigt stress, kept in work[i].
    for i in range(n):
        o = HEADER + BLOCK * i + N_PASSIVE  # element i's (q, k, v, w)
        q0, q1, q2 = y[o + A_Q], y[o + A_Q + 1], y[o + A_Q + 2]
        k0, k1, k2 = y[o + A_K], y[o + A_K + 1], y[o + A_K + 2]
        v0, v1, v2 = y[o + A_V], y[o + A_V + 1], y[o + A_V + 2]
        w0, w1, w2 = y[o + A_W], y[o + A_W + 1], y[o + A_W + 2]
        if i == 0:  # strain node 0 moves with the base
            a0, a1, a2 = base[0], base[1], base[2]
            b0, b1, b2 = base[3], base[4], base[5]
        else:
            p = o - BLOCK
            a0, a1, a2 = y[p + A_V], y[p + A_V + 1], y[p + A_V + 2]
            b0, b1, b2 = y[p + A_W], y[p + A_W + 1], y[p + A_W + 2]
        qt0 = (v0 - a0) / ds + (k1 * a2 - k2 * a1) - (b1 * q2 - b2 * q1)
        qt1 = (v1 - a1) / ds + (k2 * a0 - k0 * a2) - (b2 * q0 - b0 * q2)
        qt2 = (v2 - a2) / ds + (k0 * a1 - k1 * a0) - (b0 * q1 - b1 * q0)
        kt0 = (w0 - b0) / ds + (k1 * b2 - k2 * b1)
        kt1 = (w1 - b1) / ds + (k2 * b0 - k0 * b2)
        kt2 = (w2 - b2) / ds + (k0 * b1 - k1 * b0)
        out[o + A_Q], out[o + A_Q + 1], out[o + A_Q + 2] = qt0, qt1, qt2
        out[o + A_K], out[o + A_K + 1], out[o + A_K + 2] = kt0, kt1, kt2
        pr = params[i]
        work[i, 0] = pr[P_KL] * (q0 - 1.0) + pr[P_VL] * qt0
        work[i, 1] = pr[P_KL + 1] * q1 + pr[P_VL + 1] * qt1
        work[i, 2] = pr[P_KL + 2] * q2 + pr[P_VL + 2] * qt2
        work[i, 3] = pr[P_KTH] * k0 + pr[P_VTH] * kt0
        work[i, 4] = pr[P_KTH + 1] * k1 + pr[P_VTH + 1] * kt1
        work[i, 5] = pr[P_KTH + 2] * k2 + pr[P_VTH + 2] * kt2

    # Cables as actuation stress N_a = T H tau, M_a = p x N_a on their path.
    for c in range(offsets.shape[0]):
        t_c = tensions[c]
        if t_c == 0.0:
            continue
        p0, p1, p2 = offsets[c, 0], offsets[c, 1], offsets[c, 2]
        for i in range(n):
            wgt = weights[c, i]
            if wgt == 0.0:  # beyond the anchor
                continue
            o = HEADER + BLOCK * i + N_PASSIVE
            k0, k1, k2 = y[o + A_K], y[o + A_K + 1], y[o + A_K + 2]
            c0 = y[o + A_Q] + (k1 * p2 - k2 * p1)
            c1 = y[o + A_Q + 1] + (k2 * p0 - k0 * p2)
            c2 = y[o + A_Q + 2] + (k0 * p1 - k1 * p0)
            norm = np.sqrt(c0 * c0 + c1 * c1 + c2 * c2)
            s = t_c * wgt
            na0, na1, na2 = s * (c0 / norm), s * (c1 / norm), s * (c2 / norm)
            work[i, 0] += na0
            work[i, 1] += na1
            work[i, 2] += na2
            work[i, 3] += p1 * na2 - p2 * na1
            work[i, 4] += p2 * na0 - p0 * na2
            work[i, 5] += p0 * na1 - p1 * na0

    # Pass 2, velocity nodes 1..N (element i): balance laws with backward
    # differences of the stress; beyond the tip the total stress vanishes
    # and the strains are the reference ones.
    for i in range(n):
        op = HEADER + BLOCK * i  # element i's (u, Q)
        o = op + N_PASSIVE
        n0, n1, n2 = work[i, 0], work[i, 1], work[i, 2]
        m0, m1, m2 = work[i, 3], work[i, 4], work[i, 5]
        if i + 1 < n:
            nn0, nn1, nn2 = work[i + 1, 0], work[i + 1, 1], work[i + 1, 2]
            mn0, mn1, mn2 = work[i + 1, 3], work[i + 1, 4], work[i + 1, 5]
            x = o + BLOCK
            kn0, kn1, kn2 = y[x + A_K], y[x + A_K + 1], y[x + A_K + 2]
            qn0, qn1, qn2 = y[x + A_Q], y[x + A_Q + 1], y[x + A_Q + 2]
        else:
            nn0 = nn1 = nn2 = mn0 = mn1 = mn2 = 0.0
            kn0 = kn1 = kn2 = 0.0
            qn0, qn1, qn2 = 1.0, 0.0, 0.0
        v0, v1, v2 = y[o + A_V], y[o + A_V + 1], y[o + A_V + 2]
        w0, w1, w2 = y[o + A_W], y[o + A_W + 1], y[o + A_W + 2]
        qa, qb, qc, qd = y[op + P_QUAT], y[op + P_QUAT + 1], y[op + P_QUAT + 2], y[op + P_QUAT + 3]
        pr = params[i]
        ma0, ma1, ma2 = pr[P_MASS], pr[P_MASS + 1], pr[P_MASS + 2]
        ji0, ji1, ji2 = pr[P_INERTIA], pr[P_INERTIA + 1], pr[P_INERTIA + 2]

        f0 = (nn0 - n0) / ds + (kn1 * nn2 - kn2 * nn1)
        f1 = (nn1 - n1) / ds + (kn2 * nn0 - kn0 * nn2)
        f2 = (nn2 - n2) / ds + (kn0 * nn1 - kn1 * nn0)
        # gyroscopic force -w x (M v), M with the added mass
        p0, p1, p2 = ma0 * v0, ma1 * v1, ma2 * v2
        f0 += -(w1 * p2 - w2 * p1)
        f1 += -(w2 * p0 - w0 * p2)
        f2 += -(w0 * p1 - w1 * p0)
        # rotation matrix of the (not exactly unit) quaternion, as in rotations.matrices
        fq = 2.0 / (qa * qa + qb * qb + qc * qc + qd * qd)
        r00 = 1.0 - fq * (qc * qc + qd * qd)
        r01 = fq * (qb * qc - qa * qd)
        r02 = fq * (qb * qd + qa * qc)
        r10 = fq * (qb * qc + qa * qd)
        r11 = 1.0 - fq * (qb * qb + qd * qd)
        r12 = fq * (qc * qd - qa * qb)
        r20 = fq * (qb * qd - qa * qc)
        r21 = fq * (qc * qd + qa * qb)
        r22 = 1.0 - fq * (qb * qb + qc * qc)
        # weight minus buoyancy, R^T G in the local frame
        nm = pr[P_NET_MASS]
        f0 += nm * (r00 * g0 + r10 * g1 + r20 * g2)
        f1 += nm * (r01 * g0 + r11 * g1 + r21 * g2)
        f2 += nm * (r02 * g0 + r12 * g1 + r22 * g2)
        # Morison drag with a smoothed |v|
        speed = np.sqrt(v0 * v0 + v1 * v1 + v2 * v2 + eps2)
        f0 += -pr[P_DRAG] * speed * v0
        f1 += -pr[P_DRAG + 1] * speed * v1
        f2 += -pr[P_DRAG + 2] * speed * v2

        t0 = (mn0 - m0) / ds + (kn1 * mn2 - kn2 * mn1) + (qn1 * nn2 - qn2 * nn1)
        t1 = (mn1 - m1) / ds + (kn2 * mn0 - kn0 * mn2) + (qn2 * nn0 - qn0 * nn2)
        t2 = (mn2 - m2) / ds + (kn0 * mn1 - kn1 * mn0) + (qn0 * nn1 - qn1 * nn0)
        h0, h1, h2 = ji0 * w0, ji1 * w1, ji2 * w2
        t0 += -(w1 * h2 - w2 * h1)
        t1 += -(w2 * h0 - w0 * h2)
        t2 += -(w0 * h1 - w1 * h0)
        if munk:  # -v x (rho_w F v)
            a0, a1, a2 = pr[P_ADDED] * v0, pr[P_ADDED + 1] * v1, pr[P_ADDED + 2] * v2
            t0 += -(v1 * a2 - v2 * a1)
            t1 += -(v2 * a0 - v0 * a2)
            t2 += -(v0 * a1 - v1 * a0)

        out[o + A_V], out[o + A_V + 1], out[o + A_V + 2] = f0 / ma0, f1 / ma1, f2 / ma2
        out[o + A_W], out[o + A_W + 1], out[o + A_W + 2] = t0 / ji0, t1 / ji1, t2 / ji2
        out[op + P_U] = r00 * v0 + r01 * v1 + r02 * v2
        out[op + P_U + 1] = r10 * v0 + r11 * v1 + r12 * v2
        out[op + P_U + 2] = r20 * v0 + r21 * v1 + r22 * v2
        _quaternion_rate(y, op + P_QUAT, w0, w1, w2, restoring, out)

    # Base pose (always y[0:7]), integrating the prescribed base velocities.
    qa, qb, qc, qd = y[3], y[4], y[5], y[6]
    fq = 2.0 / (qa * qa + qb * qb + qc * qc + qd * qd)
    v0, v1, v2 = base[0], base[1], base[2]
    out[0] = (1.0 - fq * (qc * qc + qd * qd)) * v0 + fq * (qb * qc - qa * qd) * v1 \
        + fq * (qb * qd + qa * qc) * v2
    out[1] = fq * (qb * qc + qa * qd) * v0 + (1.0 - fq * (qb * qb + qd * qd)) * v1 \
        + fq * (qc * qd - qa * qb) * v2
    out[2] = fq * (qb * qd - qa * qc) * v0 + fq * (qc * qd + qa * qb) * v1 \
        + (1.0 - fq * (qb * qb + qc * qc)) * v2
    _quaternion_rate(y, 3, base[3], base[4], base[5], restoring, out)
