"""The result of a system's run: each rod's :class:`Result` and each body's pose and velocities."""

import numpy as np

from . import derivatives
from .base_motion import BaseMotion
from .discretise.assembly_frames import momentum, recorded_rod
from .discretise.contact_parts import ContactPart
from .discretise.rotations import matrices
from .discretise.system import SemiDiscrete
from .errors import ParameterError
from .result import from_states


class BodyResult:
    """Time series of one rigid body.

    Attributes
    ----------
    t : (n_t,) output times [s].
    position : (n_t, 3) position of the body origin [m], global.
    rotation : (n_t, 3, 3) body-to-global rotation matrices.
    quaternion : (n_t, 4) the same rotations as unit quaternions (scalar first).
    velocity : (n_t, 3) velocity of the body origin [m/s], body frame.
    angular_velocity : (n_t, 3) angular velocity [rad/s], body frame.
    contact_force, contact_moment : (n_t, 3) force [N] and moment about the
        body origin [N m] of its contacts with fixed obstacles (its
        ``contacts``), on the body, body frame; zeros without any.
    rod_contact_force, rod_contact_moment : (n_t, 3) the same of the rods
        touching it (:class:`rodmol.Contact`): minus the sum of their
        contact forces, acting where each touches.
    surface : (points (n, 3) [m], body frame; triangles (m, 3)) or None
        How the body is drawn, for a result read from files (else from the RigidBody).

    The contact forces are those the run's right-hand side applied at the
    frames (:func:`contact_wrenches`); a file of an older rodmol has none
    (zeros).
    """

    def __init__(self, t, position, quaternion, velocity, angular_velocity, contact=None, rod_contact=None):
        self.t, self.position, self.quaternion = t, position, quaternion
        self.rotation = matrices(quaternion)
        self.velocity, self.angular_velocity = velocity, angular_velocity
        none = np.zeros((len(t), 6))
        contact, rod_contact = (none if w is None else np.asarray(w, dtype=float) for w in (contact, rod_contact))
        self.contact_force, self.contact_moment = contact[:, :3], contact[:, 3:]
        self.rod_contact_force, self.rod_contact_moment = rod_contact[:, :3], rod_contact[:, 3:]
        self.surface = None


def contact_wrenches(assembly, part, t, states):
    """Force and moment [N, N m] about the origin, body frame, on the body
    ``part`` (an assembly's BodyPart) at the frames ``states`` (n_t, size) at
    ``t``: of its contacts with fixed obstacles (a free body's, as its rates
    apply them) and of the rods' contacts (:class:`ContactPart`), each
    (n_t, 6), through the compiled functions of the right-hand side."""
    obstacles, rods = np.zeros((len(t), 6)), np.zeros((len(t), 6))
    touching = [joint for joint in part.joints if isinstance(joint, ContactPart)]
    if not touching and (part.contacts is None or not part.body.free):
        return obstacles, rods
    for k, (tk, y) in enumerate(zip(t, states)):
        y = np.ascontiguousarray(y)
        body = assembly.body_state(part, tk, y)
        if part.contacts is not None and part.body.free:
            obstacles[k] = part.contacts.wrench(body)
        for joint in touching:  # each node on its own row: the run's rows stay as they are
            force, moment = joint.wrench(y, body, joint.row.copy(), joint.value.copy())
            rods[k] += (*force, *moment)
    return obstacles, rods


class SystemResult:
    """Time series of a system's run; ``result[name]`` is a rod's
    :class:`rodmol.Result` (built on first access, as a single rod's, its
    base velocities those its body had at the frames) or a body's
    :class:`BodyResult`.

    Attributes
    ----------
    t : (n_t,) output times [s].
    states : (n_t, size) the assembled states (``Assembly.parts`` says where each part sits).
    success, message, stats, error : as for :class:`rodmol.Result`.
    assembly : the run's :class:`rodmol.discretise.assembly.Assembly`; None for a
        result read from files (:func:`rodmol.load_result`), whose parts are read
        from them (``saved``: {rod name: reader}, {body name: reader}).
    """

    def __init__(self, assembly, t, states, success, message, stats, error=None, saved=None):
        self.assembly, self.t, self.states = assembly, np.asarray(t, dtype=float), np.asarray(states)
        self.success, self.message, self.stats, self.error = success, message, stats, error
        self._parts, self._saved = {}, saved
        self._touching = None
        if assembly is not None and assembly.rod_pairs is not None and len(self.t) and isinstance(stats, dict):
            _, gaps, active = self.rod_contacts()
            self.stats = {**stats, "rod_contact_least_gap": float(gaps.min()),
                          "rod_contact_pairs": int(active.max())}

    def rod_contacts(self):
        """The rods' contacts with each other (:class:`rodmol.RodContact`) at the frames:
        ({rod name: (n_t, N + 1, 3) contact force [N] on each node 0..N, global},
        least surface gap (n_t,) [m], negative where they overlap (inf where no two
        rods come within their radii of each other), number of touching segment
        pairs (n_t,)). The stats hold the run's least gap (``rod_contact_least_gap``)
        and most pairs (``rod_contact_pairs``). A rod's Result records the same
        forces (its nodes 1..N) in its ``external_force``, as densities."""
        assembly = self._system("rod_contacts")
        if assembly.rod_pairs is None:
            return {}, np.full(len(self.t), np.inf), np.zeros(len(self.t), dtype=int)
        if self._touching is None:
            self._touching = assembly.rod_pairs.history(self.states)
        return self._touching

    def __getstate__(self):
        # The parts built on access are left behind (a rod's replays its body's recorded
        # base motion, which does not pickle); the receiver builds them again.
        return {**self.__dict__, "_parts": {}}

    @property
    def rods(self):
        """Names of the rods."""
        return list(self.assembly.rods if self._saved is None else self._saved[0])

    @property
    def bodies(self):
        """Names of the bodies."""
        return list(self.assembly.bodies if self._saved is None else self._saved[1])

    @property
    def names(self):
        """Names of the rods, then of the bodies."""
        return self.rods + self.bodies

    def __getitem__(self, name):
        if name not in self.names:
            raise KeyError(f"{name!r} is neither a rod nor a body of the system (names: {self.names})")
        if name not in self._parts:
            if self._saved is not None:
                self._parts[name] = {**self._saved[0], **self._saved[1]}[name]()
            else:
                self._parts[name] = self._rod(name) if name in self.assembly.rods else self._body(name)
        return self._parts[name]

    def _system(self, what):
        if self.assembly is None:
            raise ParameterError(f"`{what}` needs the System: a result read from files has none "
                                 "(simulate the System again, or use its rods' and bodies' arrays)")
        return self.assembly

    def _body(self, name):
        part = self.assembly.bodies[name]
        y, n_t = self.states, len(self.t)
        if part.body.free:
            v, w = y[:, part.fields["v"]], y[:, part.fields["w"]]
        else:
            pairs = [self.assembly.body_velocities(part, ti, None) for ti in self.t]
            v, w = (np.array([p[j] for p in pairs]).reshape(n_t, 3) for j in (0, 1))
        return BodyResult(self.t, y[:, part.fields["x"]], y[:, part.fields["Q"]], v, w,
                          *contact_wrenches(self.assembly, part, self.t, y))

    def _rod(self, name):
        assembly = self.assembly
        sd, y_rod = assembly.rods[name], self.states[:, assembly.parts[name]]
        held = next((part for part in assembly.free if name in part.rods), None)
        if held is not None:  # the same rod, its base moving as its body did at the frames
            sd = SemiDiscrete(sd.model.replace(base=self._recorded_base(name, held, sd.model.base)), sd.scheme)
        sd = recorded_rod(assembly, name, self.t, self.states, sd)  # its penalty joints as at the frames
        return from_states(sd, self.t, y_rod, self.success, self.message, dict(self.stats))

    def _recorded_base(self, name, part, base):
        """A BaseMotion replaying the base velocities of rod ``name`` on the free body
        ``part`` (exact at the frames, linear between them), local frame of the base."""
        i = part.rods.index(name)
        v, w = self.states[:, part.fields["v"]], self.states[:, part.fields["w"]]
        moving = np.array([part.base_velocities(vk, wk)[i] for vk, wk in zip(v, w)]).reshape(-1, 6)
        v0, w0 = moving[:, :3], moving[:, 3:]
        t = self.t

        def replay(values):
            return lambda s: np.array([np.interp(s, t, values[:, j]) for j in range(3)])

        return BaseMotion(replay(v0), replay(w0), base.position, base.rotation)

    def momentum(self):
        """Total linear [kg m/s] and angular momentum about the origin [kg m^2/s]
        of the system at each frame, global: two (n_t, 3) arrays."""
        assembly = self._system("momentum")
        pairs = [momentum(assembly, y) for y in self.states]
        return np.array([p[0] for p in pairs]), np.array([p[1] for p in pairs])

    def pose_drift(self, name):
        """How far the base header of rod ``name`` (integrated with the rod) has
        drifted from its clamp on its body (integrated with the body): (distance
        [m], angle [rad]) at each frame, each (n_t,); zeros for a rod not on a body."""
        assembly, n_t = self._system("pose_drift"), len(self.t)
        body = assembly.system.clamps.get(name, (None,))[0]
        if body is None:
            return np.zeros(n_t), np.zeros(n_t)
        _, point, rj = assembly.system.clamps[name]
        b = self[body]
        lay, y_rod = assembly.rods[name].layout, self.states[:, assembly.parts[name]]
        expected_u = b.position + b.rotation @ point
        expected_r = b.rotation @ rj
        r0 = matrices(lay.base_quaternion(y_rod))
        relative = np.einsum("nji,njk->nik", expected_r, r0)
        cos = np.clip((np.trace(relative, axis1=1, axis2=2) - 1.0) / 2.0, -1.0, 1.0)
        return np.linalg.norm(lay.base_position(y_rod) - expected_u, axis=-1), np.arccos(cos)

    def sensitivity(self, key):
        """The derivative of this run by the parameter ``key``, one of those asked of
        :func:`rodmol.simulate` with ``sensitivities=``: a result-shaped
        :class:`rodmol.derivatives.Derivative` whose fields are those of this result per
        unit of the parameter (a knot tension's: a leading axis over its knots)."""
        return derivatives.lookup(self, key)

    def __repr__(self):
        state = "success" if self.success else f"failed: {self.message}"
        return f"SystemResult({self.names}, {len(self.t)} frames, {state})"
