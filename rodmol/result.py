"""The result of a simulation: time series on the nodes, and its .npz file format."""

import json
from functools import partial

import numpy as np

from . import derivatives
from ._files import claim, refuse_directories, write_atomically
from .discretise import centreline, physics, rotations
from .discretise.layout import StateLayout

#: Arrays of a Result, with their units (also the keys of the .npz file).
ARRAYS = {
    "t": "s",
    "s": "m",
    "radius": "m",
    "node_length": "m",
    "states": "state vectors (rodmol.StateLayout), for restarts",
    "positions": "m, global",
    "integrated_positions": "m, global",
    "rotations": "local to global",
    "linear_strain": "-, local",
    "curvature": "1/m, local",
    "velocity": "m/s, local",
    "angular_velocity": "rad/s, local",
    "internal_force": "N, local",
    "internal_moment": "N m, local",
    "external_force": "N/m, global",
    "external_moment": "N m/m, global",
    "tensions": "N",
    "cable_lengths": "m",
    "actuator_positions": "m",
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
    node_length : (N+1,) length of rod [m] each node stands for in the
        scheme (0 at the clamp; ds, and ds/2 at the tip in the centred
        scheme): ``sum(external_force[k, :, i] * node_length)`` is the total
        external force at frame k.
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
    external_force, external_moment : (n_t, N+1, 3) external load densities
        [N/m, N m/m] at the nodes, global frame (point loads appear as their
        share over the node's ``node_length``; node 0, the clamp, carries none).
    tensions : (n_t, n_cables) cable tensions [N] (where the cable leaves the base).
    cable_lengths : (n_t, n_cables) path length of each cable from the base to
        its anchor [m] (actuator space: add ``base_to_actuator`` for the
        tendon's length from its actuator).
    actuator_positions : (n_t, n_actuated) actuator position z(t) [m] of the
        displacement-controlled cables, in their order among the cables
        (named by ``meta["actuators"]``).
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
        # Arrays computed on first access: name -> function of the Result
        # returning a dict of arrays (a group computed together).
        self._deferred = dict(deferred or {})
        for needs, function, gives in DERIVED.values():
            if all(n in arrays or n in self._deferred for n in needs):
                self._deferred.update({n: function for n in gives if n not in arrays and n not in self._deferred})
        missing = set(ARRAYS) - set(arrays) - set(self._deferred)
        if missing:
            raise ValueError(f"Result lacks the arrays {sorted(missing)}")
        self.success, self.message = bool(success), str(message)
        self.stats = dict(stats or {})
        self.meta = dict(meta or {})
        self.error = None  # the exception that ended a failed run, if any (not saved)

    def __getattr__(self, name):
        deferred = self.__dict__.get("_deferred", {})
        if name not in deferred:
            raise AttributeError(f"'Result' object has no attribute {name!r}")
        for key, value in deferred[name](self).items():
            if key in deferred:
                setattr(self, key, value)
                deferred.pop(key)
        return self.__dict__[name]

    def select(self, frames):
        """The Result of the frames ``frames`` (indices or a slice) only."""
        arrays = {name: getattr(self, name) for name in STATIC}
        for name in (*STORED, *ARRAYS):
            if name not in arrays and (name in self.__dict__ or name in STORED and name in self._deferred):
                arrays[name] = getattr(self, name)[frames]
        return Result(arrays, self.success, self.message, self.stats, self.meta)

    def sensitivity(self, key):
        """The derivative of this run by the parameter ``key``, one of those asked of
        :func:`rodmol.simulate` with ``sensitivities=``: a result-shaped
        :class:`rodmol.derivatives.Derivative` whose fields are those of this result per
        unit of the parameter (a knot tension's: a leading axis over its knots)."""
        return derivatives.lookup(self, key)

    def __repr__(self):
        return (f"Result(n_t={len(self.t)}, t_end={self.t[-1] if len(self.t) else None} s, "
                f"nodes={len(self.s)}, success={self.success}, message={self.message!r})")

    @property
    def tip(self):
        """(n_t, 3) tip position [m], global."""
        return self.positions[:, -1]

    def save(self, path, overwrite=False):
        """Write the result to ``path`` (.npz); read it back with :func:`rodmol.load_result`.
        A file already there is kept unless ``overwrite`` (:func:`rodmol._files.claim`)."""
        refuse_directories([path], "path")  # before the arrays are compressed
        claim([path], overwrite, remove=False)  # replaced atomically below
        info = dict(success=self.success, message=self.message, stats=self.stats, meta=self.meta,
                    units=ARRAYS)
        arrays = {k: getattr(self, k) for k in ARRAYS}
        # Never a half-written file under the real name (see write_atomically).
        write_atomically(path, lambda handle: np.savez_compressed(handle, info=json.dumps(info), **arrays))


#: Arrays of a Result that do not change in time.
STATIC = ("s", "radius", "node_length")
#: (n_t, 12) the rows of the strains and velocities that are not state fields
#: (``StateLayout.boundary``, fields ``layout.BOUNDARY_FIELDS``):
#: the base's velocity v0 [m/s] and angular velocity w0 [rad/s] (prescribed) and
#: the tip's strains q [-] and k [1/m] (from the tip load), local frame.
BOUNDARY = "boundary_rows"
#: The stresses and loads (computed together with the ``BOUNDARY`` rows).
FORCES = ("internal_force", "internal_moment", "external_force", "external_moment")
#: What a Result holds besides its static arrays and ``meta``: the states, and
#: what follows from the model rather than from the states alone (tensions,
#: path lengths, actuator positions, stresses, loads, and the ``BOUNDARY`` rows
#: of the strains and velocities). Every other array is derived from these on
#: first access (``DERIVED``), the same way in memory and from a file: the
#: result file stores only these.
STORED = ("t", "states", "tensions", "cable_lengths", "actuator_positions", *FORCES, BOUNDARY)
#: The stored arrays one pass of the model over the frames computes (on first access).
LOADS = (*FORCES, BOUNDARY)


def from_states(system, t, y, success, message, stats):
    """Build a :class:`Result` from raw states ``y`` (n_t, size) of ``system``.

    Times and tensions are filled at once; the stresses and loads of every
    frame, by the same compiled kernel as the integration, and the arrays
    derived from the states are computed on first access (most runs need only
    a few of them, and they cost about half the integration). Until then the
    result holds the system and the states, and pickles as them.
    """
    model, layout = system.model, system.layout
    t, y = np.asarray(t, dtype=float), np.asarray(y)
    n_t = len(t)
    tensions = system.tension_history(t, y)
    lengths = system.routing.lengths(layout.field(y, "q"), layout.field(y, "k")).reshape(n_t, -1)
    actuated = [c for c in model.cables if c.actuated]
    times, at = np.unique(t, return_inverse=True)  # functions of time: once per distinct time
    actuators = np.array([[c.displacement.value(ti) for c in actuated] for ti in times]).reshape(len(times), -1)
    actuators = actuators[at.reshape(-1)].reshape(n_t, len(actuated))
    arrays = dict(t=t, tensions=tensions, **static_arrays(system), cable_lengths=lengths,
                  actuator_positions=actuators, states=y)
    loads = partial(_loads, system)
    deferred = {name: loads for name in LOADS}
    return Result(arrays, success, message, stats, run_meta(system), deferred)


def static_arrays(system):
    """The arrays of a Result that do not change in time."""
    model = system.model
    return dict(s=model.s_nodes, radius=model.rod.radius_at(model.s_nodes),
                node_length=np.concatenate([[0.0], system.node_lengths]))


def run_meta(system):
    """The ``meta`` of a Result of ``system``: sizes, scheme, cables, actuators, markers and loads."""
    model = system.model
    actuated = [c for c in model.cables if c.actuated]
    return dict(n_elements=model.n_elements, length=model.rod.length, scheme=system.scheme.name,
                cables=[dict(name=c.name, offset=c.offset_at(0.0)[0].tolist(), anchor=c.anchor,
                             node_offsets=c.offset_at(model.s_nodes).tolist())
                        for c in model.cables],
                actuators=[c.name for c in actuated],
                markers=[dict(name=mk.name, s=mk.s, offset=list(model.marker_offsets[i, 1:]))
                         for i, mk in enumerate(model.markers)],
                loads=[repr(load) for load in model.loads])


def _loads(system, result):
    """Stresses and external loads at all nodes, and the boundary rows of the strains and velocities."""
    model, layout = system.model, system.layout
    t, y, tensions = result.t, result.states, result.tensions
    n_t = len(t)
    q, k = layout.field(y, "q"), layout.field(y, "k")
    base = [model.base.velocities(ti) for ti in t]
    v0, w0 = (np.array([v[j] for v in base]).reshape(n_t, 3) for j in (0, 1))
    stress, loads = system.frames(t, y)
    # Tip node: the body carries the load concentrated on the tip node (a
    # point load at s = L; distributed loads give an O(ds) share) minus the
    # stress of the cables anchored at the tip.
    tip_length = system.node_lengths[-1]
    n_tip, m_tip = loads[:, -1, :3] * tip_length, loads[:, -1, 3:] * tip_length
    for c in range(len(model.cables)):
        if system.routing.weights[c, -1] != 1.0:
            continue
        p, dp = tuple(system.routing.geometry[c, -1, :3]), tuple(system.routing.geometry[c, -1, 3:])
        for i in range(n_t):
            tension = tensions[i, c]
            if model.friction:  # the tension that reaches the tip cell
                system.update_inputs(float(t[i]), y[i])
                tension = tension * system.friction_factors(y[i])[c, -1]
            n_a, m_a = physics.cable_stress(tuple(q[i, -1]), tuple(k[i, -1]), p, dp, tension)
            n_tip[i] -= n_a
            m_tip[i] -= m_a
    kl_tip, kth_tip = model.rod.stiffness(model.rod.length)
    rest_q, rest_k = model.rod.rest_strains_at(model.rod.length)
    boundary = np.empty((n_t, layout.boundary.size))
    for name, value in dict(v=v0, w=w0, q=rest_q + n_tip / kl_tip, k=rest_k + m_tip / kth_tip).items():
        layout.boundary.field(boundary, name)[:, 0] = value
    rots = result.rotations[:, 1:]  # the pose's (a writer needs both)
    external_force, external_moment = np.zeros((2, n_t, len(result.s), 3))  # none at the clamp, node 0
    rotations.rotate(rots, loads[..., :3], external_force[:, 1:])
    rotations.rotate(rots, loads[..., 3:], external_moment[:, 1:])
    return {
        "internal_force": np.concatenate([stress[..., :3], n_tip[:, None]], axis=1),
        "internal_moment": np.concatenate([stress[..., 3:], m_tip[:, None]], axis=1),
        "external_force": external_force, "external_moment": external_moment,
        BOUNDARY: boundary,
    }


def _layout(result):
    """The state layout of a Result's ``states``."""
    return StateLayout(result.meta["n_elements"])


def _kinematics(result):
    """Strains and velocities at all nodes: the state's fields and the boundary rows."""
    layout = _layout(result)
    field = partial(layout.field, result.states)
    row = partial(layout.boundary.field, getattr(result, BOUNDARY))  # (n_t, 1, 3) each
    return dict(linear_strain=np.concatenate([field("q"), row("q")], axis=1),
                curvature=np.concatenate([field("k"), row("k")], axis=1),
                velocity=np.concatenate([row("v"), field("v")], axis=1),
                angular_velocity=np.concatenate([row("w"), field("w")], axis=1))


def _pose(result):
    """Positions rebuilt from the strains, rotations, markers."""
    y, meta = result.states, result.meta
    layout = _layout(result)
    quat_all = layout.quaternions(y)
    positions = centreline.positions(layout.base_position(y), quat_all, layout.field(y, "q"),
                                     layout.field(y, "k"), meta["length"] / layout.n_elements)
    rots = rotations.matrices(quat_all)
    marks = meta.get("markers", [])
    offsets = np.array([m["offset"] for m in marks]).reshape(-1, 2)
    return dict(
        positions=positions, rotations=rots,
        markers=centreline.track([m["s"] for m in marks], offsets, result.s, positions, rots),
    )


def _drift(result):
    """The positions integrated in time, and the quaternions' drift off the unit sphere."""
    layout = _layout(result)
    quat_all = layout.quaternions(result.states)
    return dict(integrated_positions=layout.integrated_positions(result.states),
                quaternion_norm_error=np.max(np.abs(np.linalg.norm(quat_all, axis=-1) - 1.0), axis=-1))


#: The arrays derived from ``STORED`` ones: group -> (what it needs, its function, what it gives).
DERIVED = {
    "kinematics": ((BOUNDARY,), _kinematics, ("linear_strain", "curvature", "velocity", "angular_velocity")),
    "pose": (("states",), _pose, ("positions", "rotations", "markers")),
    "drift": (("states",), _drift, ("integrated_positions", "quaternion_norm_error")),
}
