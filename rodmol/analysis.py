"""Post-processing: discrete energies, oscillation periods and the paper's marker errors (eq. 15)."""

import os
from dataclasses import dataclass

import numpy as np

from .discretise import external
from .discretise.system import SemiDiscrete
from .errors import ParameterError
from .linking import link, result_link, twist, writhe  # noqa: F401 (rodmol.analysis's)


def energy(model, result):
    """Discrete energies [J] of every frame, consistent with the run's scheme.

    Returns a dict of (n_t,) arrays: ``kinetic`` (velocity nodes 1..N, each
    over the length of rod it stands for, with added mass), ``strain`` (the
    cells, with the scheme's cell stiffness), ``gravity`` (potential of
    weight minus buoyancy), ``contact`` (elastic energy of the contact
    penalties), ``hold`` (elastic energy of the held points' penalties,
    rodmol.Hold) and ``total``. With mu = 0, no gravity, no fluid, no cables and
    no external loads, ``kinetic + strain`` is conserved by the semi-discrete
    system of either scheme; contact damping and friction only remove energy.
    """
    system = SemiDiscrete(model, result.meta.get("scheme", "upwind"))
    lengths, (kl, kth) = system.node_lengths, system.cells[:2]
    v, w = result.velocity[:, 1:], result.angular_velocity[:, 1:]
    kinetic = 0.5 * (np.einsum("tni,n,ni,tni->t", v, lengths, system.sampled.mass, v)
                     + np.einsum("tni,n,ni,tni->t", w, lengths, system.sampled.inertia, w))
    rest_q, rest_k = system.rest  # the energy of the strains from the rest strains of each cell
    dq = result.linear_strain[:, :-1] - rest_q
    k = result.curvature[:, :-1] - rest_k
    strain = 0.5 * model.ds * (np.einsum("tni,ni,tni->t", dq, kl, dq)
                               + np.einsum("tni,ni,tni->t", k, kth, k))
    # The time-integrated positions, not the rebuilt ones: their rate is exactly R v,
    # so this potential balances the gravity work of the semi-discrete system.
    u = result.integrated_positions[:, 1:]
    gravity = -np.einsum("n,n,tni,i->t", lengths, system.sampled.net_mass, u, model.gravity)
    contact = _contact_energy(system.grid_loads, u, lengths)
    hold = _hold_energy(system.grid_loads, u, result.states, system.layout)
    return dict(kinetic=kinetic, strain=strain, gravity=gravity, contact=contact, hold=hold,
                total=kinetic + strain + gravity + contact + hold)


def _hold_energy(g, u, states, layout):
    """Penalty energy [J] of the held points (rodmol.Hold) in every frame, at the
    integrated positions ``u`` (n_t, N, 3) and the states' quaternions."""
    out = np.zeros(len(u))
    held = np.flatnonzero(np.isin(g.kind, external.HOLDS))
    if held.size:
        quat = layout.field(np.asarray(states), "Q")
    for e in held:
        node, kind, params, value = int(g.node[e]) - 1, int(g.kind[e]), g.params[e], tuple(g.initial[e])
        for i in range(len(u)):
            out[i] += external.hold_energy(kind, params, value, tuple(u[i, node]), tuple(quat[i, node]))
    return out


def _contact_energy(g, u, lengths):
    """Penalty energy [J] of every frame, at the integrated positions ``u``
    (n_t, N, 3) of the velocity nodes (those the contact law sees); ``g``
    the system's loads on the grid."""
    out = np.zeros(len(u))
    for e in np.flatnonzero(np.isin(g.kind, external.CONTACTS)):
        node, params = int(g.node[e]) - 1, g.params[e]
        weight = g.weight[e] * lengths[node]
        for i in range(len(u)):
            out[i] += weight * external.contact_energy(int(g.kind[e]), params, tuple(u[i, node]))
    return out


@dataclass(frozen=True)
class MarkerErrors:
    """Errors of eq. (15) between simulated and measured markers.

    ``t`` [s] are the measurement times; ``tip`` is e_t(t), ``mean`` is
    e_m(t) (both normalised by the arm length); ``tip_average`` and
    ``mean_average`` are their time averages.
    """

    t: np.ndarray
    tip: np.ndarray
    mean: np.ndarray

    @property
    def tip_average(self):
        return float(np.mean(self.tip))

    @property
    def mean_average(self):
        return float(np.mean(self.mean))


def oscillation_period(t, x):
    """Period [s] of an oscillation ``x`` sampled at times ``t`` [s].

    The mean spacing of the upward crossings of ``x`` through its mean, each
    placed by linear interpolation between samples (second-order accurate
    where a sine crosses, at its inflection). Needs two upward crossings.
    """
    t, x = np.asarray(t, dtype=float), np.asarray(x, dtype=float)
    x = x - x.mean()
    i = np.flatnonzero((x[:-1] < 0) & (x[1:] >= 0))
    if len(i) < 2:
        raise ParameterError(f"`x` crosses its mean upwards {len(i)} time(s); a period needs two")
    crossings = t[i] - x[i] * (t[i + 1] - t[i]) / (x[i + 1] - x[i])
    return (crossings[-1] - crossings[0]) / (len(crossings) - 1)


def read_markers_csv(path, n_markers=4):
    """Read measured markers: columns t, x1, y1, z1, ..., xM, yM, zM [s, m] (header optional)."""
    path = os.fspath(path)
    try:
        data = np.genfromtxt(path, delimiter=",", comments="#", skip_header=0)
    except OSError as exc:
        raise ParameterError(f"cannot read marker table {path!r}: {exc}") from None
    if data.ndim == 2 and np.all(np.isnan(data[0])):
        data = data[1:]
    data = np.atleast_2d(data)
    if data.shape[1] != 1 + 3 * n_markers or not np.all(np.isfinite(data)):
        raise ParameterError(f"{path}: expected {1 + 3 * n_markers} numeric columns "
                             f"(t and x, y, z of {n_markers} markers), got {data.shape[1]}")
    if np.any(np.diff(data[:, 0]) <= 0):
        line = int(np.flatnonzero(np.diff(data[:, 0]) <= 0)[0]) + 2
        raise ParameterError(f"{path}: times must increase (data row {line})")
    return data[:, 0], data[:, 1:].reshape(len(data), n_markers, 3)


def marker_errors(result, measured, times=None, length=None):
    """The paper's tip and mean errors (eq. 15) of ``result`` against measurements.

    Parameters
    ----------
    result : Result
        Its markers must be, in order, L1, L2, L3 and the tip (the
        default of :func:`rodmol.paper_arm`).
    measured : array (n, 4, 3) or path
        Measured marker positions [m], global frame, or a CSV file (see
        :func:`read_markers_csv`).
    times : array (n,), optional
        Measurement times [s]; default: the result's output times. The
        simulation is interpolated linearly to them.
    length : float, optional
        Normalising length [m]; default: the arm's rest length.
    """
    if isinstance(measured, (str, os.PathLike)):
        times, measured = read_markers_csv(measured, result.markers.shape[1])
    measured = np.asarray(measured, dtype=float)
    times = result.t if times is None else np.asarray(times, dtype=float)
    if measured.shape != (len(times),) + result.markers.shape[1:]:
        raise ParameterError(f"`measured` must have shape {(len(times),) + result.markers.shape[1:]}, "
                             f"got {measured.shape}")
    if times[0] < result.t[0] - 1e-12 or times[-1] > result.t[-1] + 1e-12:
        raise ParameterError(f"measurement times [{times[0]}, {times[-1]}] s fall outside the "
                             f"simulated interval [{result.t[0]}, {result.t[-1]}] s")
    flat = result.markers.reshape(len(result.t), -1)
    sim = np.stack([np.interp(times, result.t, col) for col in flat.T], axis=1).reshape(measured.shape)
    length = result.meta.get("length") if length is None else length
    dist = np.linalg.norm(sim - measured, axis=-1) / length
    return MarkerErrors(times, dist[:, -1], np.mean(dist, axis=1))
