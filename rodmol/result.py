"""The result of a simulation: time series on the nodes, and its .npz file format."""

import json
import os

import numpy as np

from .discretise import centreline, rotations

from . import markers
from .discretise.layout import FIELDS, HEADER
from .model import Q_STAR

#: Arrays of a Result, with their units (also the keys of the .npz file).
ARRAYS = {
    "t": "s",
    "s": "m",
    "radius": "m",
    "positions": "m, global",
    "integrated_positions": "m, global",
    "rotations": "local to global",
    "linear_strain": "-, local",
    "curvature": "1/m, local",
    "velocity": "m/s, local",
    "angular_velocity": "rad/s, local",
    "internal_force": "N, local",
    "internal_moment": "N m, local",
    "tensions": "N",
    "quaternion_norm_error": "-",
    "markers": "m, global",
}


class Result:
    """Time series of a run; arrays are time-first, components last.

    Attributes
    ----------
    t : (n_t,) output times [s].
    s : (N+1,) arc length of the nodes [m]; node 0 is the base.
    radius : (N+1,) section radius at the nodes [m].
    positions : (n_t, N+1, 3) centreline positions [m], global frame,
        rebuilt from the strains and orientations (see ``rodmol.centreline``).
    integrated_positions : (n_t, N+1, 3) positions integrated in time
        (``u_t = R v``); they drift from the shape by O(ds) per unit time but
        are the exact conjugate of the gravity work (used by ``rodmol.energy``).
    rotations : (n_t, N+1, 3, 3) local-to-global rotation matrices.
    linear_strain, curvature : (n_t, N+1, 3) strains q [-] and k [1/m], local.
    velocity, angular_velocity : (n_t, N+1, 3) v [m/s] and w [rad/s], local.
    internal_force, internal_moment : (n_t, N+1, 3) Kelvin-Voigt stress N [N]
        and M [N m] in the body, local (without the cables' own tension).
    tensions : (n_t, n_cables) cable tensions [N].
    quaternion_norm_error : (n_t,) max over nodes of ||Q| - 1|.
    markers : (n_t, n_markers, 3) marker positions [m], global; their names
        are ``meta["markers"]``.
    success, message : whether the solver reached ``t_end``, and why not.
    stats : dict with ``steps``, ``rhs_evals``, ``jac_evals``, ``wall_time_s``,
        ``backend``.
    """

    def __init__(self, arrays, success=True, message="", stats=None, meta=None, deferred=None):
        for name, value in arrays.items():
            setattr(self, name, np.asarray(value))
        # Arrays derived from the states are computed on first access:
        # name -> function returning a dict of arrays (a group computed together).
        self._deferred = dict(deferred or {})
        missing = set(ARRAYS) - set(arrays) - set(self._deferred)
        if missing:
            raise ValueError(f"Result lacks the arrays {sorted(missing)}")
        self.success, self.message = bool(success), str(message)
        self.stats = dict(stats or {})
        self.meta = dict(meta or {})

    def __getattr__(self, name):
        deferred = self.__dict__.get("_deferred", {})
        if name not in deferred:
            raise AttributeError(f"'Result' object has no attribute {name!r}")
        for key, value in deferred[name]().items():
            setattr(self, key, value)
            deferred.pop(key, None)
        return self.__dict__[name]

    def __repr__(self):
        return (f"Result(n_t={len(self.t)}, t_end={self.t[-1] if len(self.t) else None} s, "
                f"nodes={len(self.s)}, success={self.success}, message={self.message!r})")

    @property
    def tip(self):
        """(n_t, 3) tip position [m], global."""
        return self.positions[:, -1]

    def save(self, path):
        """Write the result to ``path`` (.npz); read it back with :func:`load_result`."""
        info = dict(success=self.success, message=self.message, stats=self.stats, meta=self.meta,
                    units=ARRAYS)
        tmp = f"{os.fspath(path)}.part.npz"
        np.savez_compressed(tmp, info=json.dumps(info), **{k: getattr(self, k) for k in ARRAYS})
        os.replace(tmp, path)  # never leave a half-written file under the real name


def load_result(path):
    """Read a :class:`Result` written by :meth:`Result.save`."""
    with np.load(path, allow_pickle=False) as data:
        info = json.loads(str(data["info"]))
        arrays = {k: data[k] for k in ARRAYS}
    return Result(arrays, info["success"], info["message"], info["stats"], info.get("meta"))


#: The arrays each deferred group of :func:`from_states` computes.
_GROUPS = {
    "mechanics": ("linear_strain", "curvature", "velocity", "angular_velocity", "internal_force",
                  "internal_moment"),
    "pose": ("positions", "rotations", "integrated_positions", "markers"),
}


def from_states(system, t, y, success, message, stats):
    """Build a :class:`Result` from raw states ``y`` (n_t, size) of ``system``.

    Times, tensions and the quaternion drift are filled at once; the strains,
    stresses and poses of every frame are computed on first access (most runs
    need only a few of them, and they cost about half the integration).
    """
    model = system.model
    n_t, n = len(t), model.n_elements
    blocks = y[:, HEADER:].reshape(n_t, n, -1)
    quat, q, k, v, w = (blocks[..., FIELDS[f]] for f in ("Q", "q", "k", "v", "w"))
    base = [model.base.velocities(ti) for ti in t]
    v0 = np.array([b[0] for b in base]).reshape(n_t, 3)
    w0 = np.array([b[1] for b in base]).reshape(n_t, 3)
    tensions = np.array([system.tensions(ti, yi) for ti, yi in zip(t, y)]).reshape(n_t, -1)


    def mechanics():
        """Strains, velocities and stresses at all nodes (node N: the tip)."""
        q_t, k_t = system.strain_rates(q, k, v, w, v0, w0)
        n_el, m_el, _, _ = system.stresses(q, k, q_t, k_t, tensions)
        # Tip node: the body carries minus the stress of the cables anchored at the tip.
        tip_cables = model.cable_weights[:, -1] == 1.0 if model.cables else np.zeros(0, bool)
        n_tip, m_tip = np.zeros((n_t, 3)), np.zeros((n_t, 3))
        if np.any(tip_cables):
            _, _, n_tot, m_tot = system.stresses(q[:, -1:], k[:, -1:], 0 * q[:, -1:], 0 * k[:, -1:],
                                                 tensions * tip_cables)
            n_tip, m_tip = -n_tot[:, 0], -m_tot[:, 0]
        kl_tip, kth_tip = model.rod.stiffness(model.rod.length)
        return dict(
            linear_strain=np.concatenate([q, (Q_STAR + n_tip / kl_tip)[:, None]], axis=1),
            curvature=np.concatenate([k, (m_tip / kth_tip)[:, None]], axis=1),
            velocity=np.concatenate([v0[:, None], v], axis=1),
            angular_velocity=np.concatenate([w0[:, None], w], axis=1),
            internal_force=np.concatenate([n_el, n_tip[:, None]], axis=1),
            internal_moment=np.concatenate([m_el, m_tip[:, None]], axis=1),
        )

    def pose():
        """Positions rebuilt from the strains, rotations, markers, integrated positions."""
        positions = centreline.positions(y[:, :3], quat_all, q, k, model.ds)
        rots = rotations.matrices(quat_all)
        return dict(
            positions=positions, rotations=rots,
            integrated_positions=np.concatenate([y[:, None, :3], blocks[..., FIELDS["u"]]], axis=1),
            markers=markers.track(model.markers, model.marker_offsets, model.s_nodes, positions, rots),
        )

    quat_all = np.concatenate([y[:, None, 3:7], quat], axis=1)
    arrays = dict(
        t=t, s=model.s_nodes, radius=model.rod.radius_at(model.s_nodes), tensions=tensions,
        quaternion_norm_error=np.max(np.abs(np.linalg.norm(quat_all, axis=-1) - 1.0), axis=-1),
    )
    deferred = {name: group for group in (mechanics, pose) for name in _GROUPS[group.__name__]}
    meta = dict(n_elements=n, length=model.rod.length,
                cables=[dict(name=c.name, offset=list(c.offset), anchor=c.anchor)
                        for c in model.cables],
                markers=[dict(name=mk.name, s=mk.s, offset=list(model.marker_offsets[i, 1:]))
                         for i, mk in enumerate(model.markers)])
    return Result(arrays, success, message, stats, meta, deferred)
