"""Read-only views of a System's state, one per part: what the stepping
simulator hands a controller of a :class:`rodmol.System` (:class:`SystemStateView`)."""

import numpy as np

from .rotations import matrices


class BodyStateView:
    """A rigid body's pose and velocities in one state: ``t`` [s], ``position`` (3,) [m] of
    its origin and ``quaternion`` (4,) (body to global), ``rotation`` (3, 3), ``velocity``
    [m/s] and ``angular_velocity`` [rad/s] (3,), body frame, as :class:`rodmol.BodyResult`'s."""

    def __init__(self, t, position, quaternion, velocity, angular_velocity):
        self.t, self.position = t, np.array(position)
        self.quaternion = np.array(quaternion) / np.linalg.norm(quaternion)
        self.velocity, self.angular_velocity = np.array(velocity), np.array(angular_velocity)

    @property
    def rotation(self):
        return matrices(self.quaternion)


class SystemStateView:
    """A System's state at time ``t`` [s] by part: ``view[rod]`` is the rod's
    :class:`rodmol.StateView` (tip, positions, markers, cable lengths, strains,
    velocities), ``view[body]`` a :class:`BodyStateView`; ``names`` lists the rods
    then the bodies, as :class:`rodmol.SystemResult` does."""

    def __init__(self, assembly, t, y):
        self.t, self._assembly, self._y, self._parts = t, assembly, y, {}

    @property
    def rods(self):
        return list(self._assembly.rods)

    @property
    def bodies(self):
        return list(self._assembly.bodies)

    @property
    def names(self):
        return self.rods + self.bodies

    def __getitem__(self, name):
        if name not in self._parts:
            self._parts[name] = self._view(name)
        return self._parts[name]

    def _view(self, name):
        assembly, t, y = self._assembly, self.t, self._y
        if name in assembly.rods:
            return assembly.rods[name].state_view(t, y[assembly.parts[name]])
        if name in assembly.bodies:
            part = assembly.bodies[name]
            v, w = assembly.body_velocities(part, t, y)
            return BodyStateView(t, y[part.fields["x"]], y[part.fields["Q"]], v, w)
        raise KeyError(f"{name!r} is neither a rod nor a body of the system (names: {self.names})")
