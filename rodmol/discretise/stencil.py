"""The compiled right-hand side loop of the staggered grid, for both schemes.

Strains and stresses live on the cells (strain node i is cell [s_i, s_i+1]),
velocities and poses on the nodes 1..N. The differences are the same in both
schemes: v' and w' across a cell in the compatibility laws, N' and M' between
neighbouring cells in the balance laws. The schemes differ in where the
non-derivative terms are evaluated (:mod:`rodmol.discretise.schemes` holds
the definitions, their dependency tables and sampling):

* ``upwind`` (the paper's, section IV-C, ``consts[SCHEME] = Kernel.UPWIND``): the strain
  rates use the velocities of the cell's base-side node, a node's balance uses
  the products k x N, k x M, q x N of the cell on its tip side (zero beyond
  the tip); first order in ds.
* ``centred`` (``consts[SCHEME] = Kernel.CENTRED``): the strain rates use the average of
  the cell's two node velocities, a node's balance the average of its two
  cells' products, and the tip node carries half a cell; second order in ds,
  and the discrete energy is conserved exactly without dissipation.

The per-node physics comes from :mod:`rodmol.discretise.physics` and
:mod:`rodmol.discretise.external`.

Packing of the sampled model (built once by ``SemiDiscrete``):

* ``params`` (N, 31): per element, the constant sectional data, one row per
  element (columns ``P_*``), the cell's rest strains q*, k* among them;
* ``consts`` (9,): ds, quaternion restoring rate, drag smoothing speed^2,
  Munk switch (0/1), gravity (3, global), the scheme's kernel code, drag law
  (0 Morison, 1 componentwise C v|v|: then ``P_DRAG`` holds C);
* ``offsets`` (n_c, N, 6), ``weights`` (n_c, N): per cable and cell the
  offset p and its slope p' (local, :mod:`rodmol.discretise.routing`), and
  the cell's share of the path times the tension's factor there (friction);
* external-load entries: ``kinds``, ``nodes`` (element block of the entry),
  ``entry_weights``, ``entry_params`` (E, 12) and ``entry_values`` (E, 3);
* ``tensions`` (n_c,), ``base`` (6,) = (v0, w0) and ``entry_values``: the
  time-dependent inputs, filled in place by the caller before each call;
* ``work`` (N, 18) scratch that the loop leaves holding, per element, the
  Kelvin-Voigt stress (0:6), the total stress with the cables (6:12) and the
  external load densities at its velocity node (12:18), local frame.
"""

import numba
import numpy as np

from .external import load
from .layout import BLOCK, HEADER, QUAT, K, U, V, W
from .layout import Q as QS
from .physics import (
    add,
    body_force,
    body_torque,
    cable_stress,
    componentwise_drag,
    cross,
    jit,
    kelvin_voigt,
    quaternion_rate,
    rotation,
    scale,
    strain_rate_terms,
    sub,
    to_global,
)
from .schemes import Kernel

#: Index of the scheme's :class:`~rodmol.discretise.schemes.Kernel` code in ``consts``.
SCHEME = 7
#: The kernel codes as plain integers (numba compares them as constants).
UPWIND, CENTRED = int(Kernel.UPWIND), int(Kernel.CENTRED)
#: Index of the drag law switch in ``consts`` (0 Morison, 1 componentwise).
COMPONENTWISE_DRAG = 8
N_CONSTS = 9

P_KL, P_KTH, P_VL, P_VTH, P_MASS, P_INERTIA = 0, 3, 6, 9, 12, 15
P_NET_MASS, P_DRAG, P_ADDED, P_REST_Q, P_REST_K = 18, 19, 22, 25, 28
N_PARAMS = 31
#: Columns of a ``work`` row: the Kelvin-Voigt N, M (6), the total N, M with
#: the cables (6) and the external force and moment densities (6).
WORK_STRESS, WORK_TOTAL, WORK_LOADS = 0, 6, 12
WORK_COLUMNS = 18


def pack_params(kl, kth, vl, vth, mass, inertia, net_mass, drag, added, rest_q, rest_k):
    """The (N, 31) parameter rows of the sampled model."""
    params = np.empty((len(kl), N_PARAMS))
    for col, arr in ((P_KL, kl), (P_KTH, kth), (P_VL, vl), (P_VTH, vth), (P_MASS, mass),
                     (P_INERTIA, inertia), (P_DRAG, drag), (P_ADDED, added), (P_REST_Q, rest_q),
                     (P_REST_K, rest_k)):
        params[:, col:col + 3] = arr
    params[:, P_NET_MASS] = net_mass
    return params


@jit
def _vec(a, i):
    return (a[i], a[i + 1], a[i + 2])


@jit
def _put(out, i, x):
    out[i], out[i + 1], out[i + 2] = x[0], x[1], x[2]


@jit
def compatibility(q, k, v, w, v_prev, w_prev, ds, kernel):
    """The strain rates (q_t, k_t) of a cell, local frame, from the compatibility
    laws (eq. 2) with the difference of the velocities (v, w) of its tip-side
    node and (v_prev, w_prev) of its base-side node across the cell; the
    non-derivative terms read the base-side node (``UPWIND``) or the average
    of both (``CENTRED``), as the scheme's ``kernel`` code says."""
    if kernel == CENTRED:
        terms_q, terms_k = strain_rate_terms(q, k, scale(0.5, add(v, v_prev)), scale(0.5, add(w, w_prev)))
    else:
        terms_q, terms_k = strain_rate_terms(q, k, v_prev, w_prev)
    return add(scale(1.0 / ds, sub(v, v_prev)), terms_q), add(scale(1.0 / ds, sub(w, w_prev)), terms_k)


def _signature():
    # The state comes read-only from CVODE and writable from everywhere else;
    # typing it read-only accepts both with a single compilation.
    f1, f2, i1 = numba.types.float64[::1], numba.types.float64[:, ::1], numba.types.int64[::1]
    f3 = numba.types.float64[:, :, ::1]
    return numba.types.void(f1.copy(readonly=True), f1, f2, f1, f3, f2, f1, f1,
                            i1, i1, f1, f2, f2, f2)


@jit(signature=_signature())
def rhs(y, out, params, consts, offsets, weights, tensions, base,
        kinds, nodes, entry_weights, entry_params, entry_values, work):
    """dy/dt of the semi-discrete system into ``out`` (see the module docstring)."""
    n = params.shape[0]
    ds, restoring, smoothing2, munk = consts[0], consts[1], consts[2], consts[3] != 0.0
    gravity = (consts[4], consts[5], consts[6])
    kernel = int(consts[SCHEME])
    centred = kernel == CENTRED
    componentwise = consts[COMPONENTWISE_DRAG] != 0.0

    # Pass 1, cells i = 0..N-1: compatibility with the differences of v, w
    # across the cell (cell 0 starts at the base), and the sectional stress.
    for i in range(n):
        o = HEADER + BLOCK * i
        q, k, v, w = _vec(y, o + QS), _vec(y, o + K), _vec(y, o + V), _vec(y, o + W)
        if i == 0:
            v_prev, w_prev = _vec(base, 0), _vec(base, 3)
        else:
            v_prev, w_prev = _vec(y, o - BLOCK + V), _vec(y, o - BLOCK + W)
        q_t, k_t = compatibility(q, k, v, w, v_prev, w_prev, ds, kernel)
        _put(out, o + QS, q_t)
        _put(out, o + K, k_t)
        pr = params[i]
        n_el, m_el = kelvin_voigt(_vec(pr, P_KL), _vec(pr, P_KTH), _vec(pr, P_VL), _vec(pr, P_VTH),
                                  q, k, q_t, k_t, _vec(pr, P_REST_Q), _vec(pr, P_REST_K))
        row = work[i]
        _put(row, WORK_STRESS, n_el)
        _put(row, WORK_STRESS + 3, m_el)
        _put(row, WORK_TOTAL, n_el)
        _put(row, WORK_TOTAL + 3, m_el)
        for j in range(WORK_LOADS, WORK_LOADS + 6):
            row[j] = 0.0

    # Cables as actuation stress on their path (weights: share of each cell).
    for c in range(offsets.shape[0]):
        if tensions[c] == 0.0:
            continue
        for i in range(n):
            if weights[c, i] == 0.0:  # beyond the anchor
                continue
            o = HEADER + BLOCK * i
            route = offsets[c, i]
            n_a, m_a = cable_stress(_vec(y, o + QS), _vec(y, o + K), _vec(route, 0), _vec(route, 3),
                                    tensions[c] * weights[c, i])
            row = work[i]
            _put(row, WORK_TOTAL, add(_vec(row, WORK_TOTAL), n_a))
            _put(row, WORK_TOTAL + 3, add(_vec(row, WORK_TOTAL + 3), m_a))

    # External loads at their velocity nodes.
    for e in range(kinds.shape[0]):
        o = HEADER + BLOCK * nodes[e]
        f, m = load(kinds[e], entry_params[e], _vec(entry_values[e], 0), _vec(y, o + U),
                    (y[o + QUAT], y[o + QUAT + 1], y[o + QUAT + 2], y[o + QUAT + 3]),
                    _vec(y, o + V), _vec(y, o + W))
        row = work[nodes[e]]
        _put(row, WORK_LOADS, add(_vec(row, WORK_LOADS), scale(entry_weights[e], f)))
        _put(row, WORK_LOADS + 3, add(_vec(row, WORK_LOADS + 3), scale(entry_weights[e], m)))

    # Pass 2, velocity nodes 1..N (element i): balance laws with the
    # difference of the total stress of the cells around the node; beyond the
    # tip the stress vanishes. Upwind: the products k x N, k x M, q x N of the
    # tip-side cell. Centred: their average over both cells, and the tip node
    # balances half a cell (the cell's full product over half its length).
    zero = (0.0, 0.0, 0.0)
    for i in range(n):
        o = HEADER + BLOCK * i
        row = work[i]
        n_here, m_here = _vec(row, WORK_TOTAL), _vec(row, WORK_TOTAL + 3)
        q_here, k_here = _vec(y, o + QS), _vec(y, o + K)
        if i + 1 < n:
            n_next, m_next = _vec(work[i + 1], WORK_TOTAL), _vec(work[i + 1], WORK_TOTAL + 3)
            k_next, q_next = _vec(y, o + BLOCK + K), _vec(y, o + BLOCK + QS)
        else:
            n_next, m_next, k_next, q_next = zero, zero, zero, zero  # no stress, no products
        f_next, t_next = cross(k_next, n_next), add(cross(k_next, m_next), cross(q_next, n_next))
        if not centred:
            length, f_cells, t_cells = ds, f_next, t_next
        else:
            f_here = cross(k_here, n_here)
            t_here = add(cross(k_here, m_here), cross(q_here, n_here))
            if i + 1 < n:
                length, f_cells, t_cells = ds, scale(0.5, add(f_here, f_next)), scale(0.5, add(t_here, t_next))
            else:
                length, f_cells, t_cells = 0.5 * ds, f_here, t_here
        v, w = _vec(y, o + V), _vec(y, o + W)
        quat = (y[o + QUAT], y[o + QUAT + 1], y[o + QUAT + 2], y[o + QUAT + 3])
        r = rotation(quat)
        pr = params[i]
        mass, inertia = _vec(pr, P_MASS), _vec(pr, P_INERTIA)

        f = add(scale(1.0 / length, sub(n_next, n_here)), f_cells)
        if componentwise:
            f = add(f, body_force(mass, pr[P_NET_MASS], zero, r, gravity, v, w, smoothing2))
            f = sub(f, componentwise_drag(_vec(pr, P_DRAG), v, smoothing2))
        else:
            f = add(f, body_force(mass, pr[P_NET_MASS], _vec(pr, P_DRAG), r, gravity, v, w, smoothing2))
        f = add(f, _vec(row, WORK_LOADS))
        t = add(scale(1.0 / length, sub(m_next, m_here)), t_cells)
        t = add(t, body_torque(inertia, _vec(pr, P_ADDED), munk, v, w))
        t = add(t, _vec(row, WORK_LOADS + 3))

        _put(out, o + V, (f[0] / mass[0], f[1] / mass[1], f[2] / mass[2]))
        _put(out, o + W, (t[0] / inertia[0], t[1] / inertia[1], t[2] / inertia[2]))
        _put(out, o + U, to_global(r, v))
        qr = quaternion_rate(quat, w, restoring)
        for j in range(4):
            out[o + QUAT + j] = qr[j]

    # Base pose, integrating the prescribed base velocities.
    quat0 = (y[3], y[4], y[5], y[6])
    _put(out, 0, to_global(rotation(quat0), _vec(base, 0)))
    qr = quaternion_rate(quat0, _vec(base, 3), restoring)
    for j in range(4):
        out[3 + j] = qr[j]
