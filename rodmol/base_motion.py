"""Motion of the clamped base (kinematic boundary condition at s = 0)."""

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from . import _checks
from .errors import ParameterError, RodmolError

_ZERO = np.zeros(3)


@dataclass(frozen=True)
class BaseMotion:
    """Prescribed base velocities, in the base's local frame.

    Parameters
    ----------
    velocity : callable, optional
        ``v0(t)`` -> (3,) linear velocity [m/s] of the base, local frame.
    angular_velocity : callable, optional
        ``w0(t)`` -> (3,) angular velocity [rad/s] of the base, local frame.
    position, rotation : array_like, optional
        Initial base pose: position [m] (global) and rotation matrix
        (local to global). Default: the origin and the identity.

    The base pose is integrated with the rest of the state. The default,
    ``BaseMotion()``, is a fixed clamp at the origin.
    """

    velocity: Callable | None = None
    angular_velocity: Callable | None = None
    position: tuple = (0.0, 0.0, 0.0)
    rotation: tuple = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))

    def __post_init__(self):
        for name in ("velocity", "angular_velocity"):
            f = getattr(self, name)
            if f is not None and not callable(f):
                raise ParameterError(f"base `{name}` must be a callable of t, got {f!r}")
        u, r = _checks.floats(self.position), _checks.floats(self.rotation)
        if u is None or u.shape != (3,) or not np.all(np.isfinite(u)):
            raise ParameterError(f"base `position` must be three finite numbers, got {self.position!r}")
        if r is None or r.shape != (3, 3) or not np.all(np.isfinite(r)) or not np.allclose(r.T @ r, np.eye(3), atol=1e-9) or np.linalg.det(r) < 0:
            raise ParameterError(f"base `rotation` must be a 3x3 rotation matrix, got {self.rotation!r}")

    @property
    def fixed(self):
        return self.velocity is None and self.angular_velocity is None

    def velocities(self, t):
        """(v0, w0) at time t [m/s, rad/s], local frame."""
        return self._velocity("velocity", t), self._velocity("angular_velocity", t)

    def _velocity(self, name, t):
        """The base's ``name`` function at t, checked: three finite numbers."""
        function = getattr(self, name)
        if function is None:
            return _ZERO
        try:
            value = function(t)
        except RodmolError:
            raise
        except Exception as exc:  # noqa: BLE001 (the user's function: chained, never lost)
            raise _checks.user_error(f"the base motion's `{name}` function", exc, t) from exc
        arr = _checks.floats(value)
        if arr is None or arr.shape != (3,) or not np.all(np.isfinite(arr)):
            raise _checks.bad_return(f"the base motion's `{name}` function", value, t,
                                     "it must return three finite numbers")
        return arr

    @classmethod
    def from_pose(cls, position, rotation=None, dt=1e-6):
        """A base following a pose trajectory ``position(t)`` [m], ``rotation(t)`` (3x3).

        Velocities are found by central differences with step ``dt`` [s].
        """
        def velocity(t):
            r = np.eye(3) if rotation is None else np.asarray(rotation(t))
            du = (np.asarray(position(t + dt)) - np.asarray(position(t - dt))) / (2 * dt)
            return r.T @ du

        angular = None
        if rotation is not None:
            def angular(t):
                r = np.asarray(rotation(t))
                dr = (np.asarray(rotation(t + dt)) - np.asarray(rotation(t - dt))) / (2 * dt)
                s = r.T @ dr
                return 0.5 * np.array([s[2, 1] - s[1, 2], s[0, 2] - s[2, 0], s[1, 0] - s[0, 1]])

        r0 = np.eye(3) if rotation is None else np.asarray(rotation(0.0), dtype=float)
        return cls(velocity, angular, tuple(np.asarray(position(0.0), dtype=float)),
                   tuple(map(tuple, r0)))


#: Former name of :class:`BaseMotion`, kept so existing scripts still run.
Base = BaseMotion
