"""External loads you apply to the rod: point and distributed wrenches, contact.

Every load acts in the dynamics and in the static equilibrium, and its force
and moment densities are recorded in the result (``Result.external_force``,
``Result.external_moment``) and written to the ParaView series.

Frames: ``frame="global"`` gives a dead load, fixed in the lab frame;
``frame="local"`` gives a follower load, fixed in the section's material frame
(it turns with the section). Contact forces act on the tube's surface (the
section radius is taken into account) along the obstacle's normal, with
regularised Coulomb friction.

Point loads take the same time inputs as cable tensions (a constant vector,
knots ``[(t, x, y, z), ...]``, a CSV table with columns t, x, y, z, or a
callable ``f(t)``); distributed loads take a constant vector or a callable
``f(s, t)`` called with the arc lengths of the nodes as an array.

On the grid, a point load at arc length s is shared between the two nodes
around s, linearly (a share that falls on the clamped base goes into the
clamp); distributed and contact loads act at every node but the base.
"""

import dataclasses
import typing
from dataclasses import dataclass
from typing import Any

import numpy as np

from . import _checks
from .errors import ParameterError, RodmolError
from .holds import Hold
from .inputs import as_time_input
from .load_kinds import KERNELS, Kernel  # noqa: F401 (the records, read through rodmol.loads too)

FRAMES = ("global", "local")
#: Default contact smoothing depth, as a fraction of the section radius.
SMOOTHING_FRACTION = 0.01


# The parameter row a load hands its kernel at each node (``params``): the
# contact kinds' geometry (plane: point, normal; capsule: start, end,
# radius), then the law, the section radius at the node and the depth over
# which the penalty is smoothed. Vector loads have none. A hold's row: the
# node's rest position (3), the held orientation's quaternion (4), then its
# stiffness, damping, turning stiffness and turning damping, and the held
# point's velocity and angular velocity (3 + 3, global: zero for the world,
# a body's for a joint of rodmol.System, written at each call by the assembly).
# A contact row ends with its obstacle's motion (3 + 3, global: the velocity
# of the obstacle's point at the row's first point and its angular
# velocity), zero for a fixed obstacle, a body's for a rodmol.Contact.
N_PARAMS = 19
P_STIFFNESS, P_DAMPING, P_FRICTION, P_SLIP, P_RADIUS, P_SMOOTHING = 7, 8, 9, 10, 11, 12
P_TURN_STIFFNESS, P_TURN_DAMPING, P_HELD_VELOCITY, P_HELD_SPIN = 9, 10, 11, 14
P_OBSTACLE_VELOCITY, P_OBSTACLE_SPIN = 13, 16


def _frame(frame, name):
    if not (isinstance(frame, str) and frame in FRAMES):
        raise ParameterError(f"{name}: `frame` must be 'global' (dead load) or 'local' "
                             f"(follower load), got {_checks.short(frame)}{_checks.did_you_mean(frame, FRAMES)}")
    return frame


class _Load:
    """What every load tells the grid (:mod:`rodmol.discretise.load_entries`):
    ``kernel``, the name of its branch in :data:`KERNELS`; ``spread``,
    ``"point"`` (shared between the two nodes around ``s``) or ``"nodes"``
    (a density at every node but the base); ``values(s, t)``, its (len(s), 3)
    vectors at arc lengths s [m] and time t, in the frame its kernel reads;
    ``constant``, True if they do not change with time; ``params(radius)``,
    the kernel's parameter rows at nodes of section radius ``radius`` [m]."""

    spread = "nodes"
    constant = True

    def check_within(self, length):
        """Refuse a load that does not fit a rod of ``length`` [m]."""

    def check_grid(self, s_nodes):
        """Refuse a load that does not fit the grid of nodes ``s_nodes`` [m]."""

    def values(self, s, t):
        return np.zeros((len(s), 3))

    def params(self, radius):
        return np.zeros((len(radius), 0))


class _PointLoad(_Load):
    _what, _unit, _kernels = "", "", {}

    def _setup(self, name, value):
        object.__setattr__(self, "s", _checks.non_negative(f"{name} `s`", self.s, " m"))
        object.__setattr__(self, "frame", _frame(self.frame, name))
        object.__setattr__(self, self._what, as_time_input(f"{self._what}` of `{name}", value, 3,
                                                           self._unit))

    spread = "point"

    @property
    def kernel(self):
        return self._kernels[self.frame]

    @property
    def constant(self):
        return getattr(self, self._what).constant

    def check_within(self, length):
        """Refuse an arc length beyond the rod's ``length`` [m]."""
        if self.s > length * (1 + 1e-12):
            raise ParameterError(f"{self.name}: `s` must lie in [0, L = {length!r} m], got {self.s!r}")

    def values(self, s, t):
        """The load's vector at time t, repeated for each arc length of ``s``."""
        return np.tile(getattr(self, self._what).value(t), (len(s), 1))


@dataclass(frozen=True)
class PointForce(_PointLoad):
    """A force [N] at arc length ``s`` [m] (the tip is ``s = L``).

    ``frame="global"``: the force is fixed in the lab frame (dead load);
    ``"local"``: its components are in the section's frame (follower load).
    """

    s: float
    force: Any
    frame: str = "global"
    name: str = "point force"
    _what, _unit = "force", "N"
    _kernels = {"local": "follower_force", "global": "dead_force"}

    def __post_init__(self):
        self._setup(self.name, self.force)


@dataclass(frozen=True)
class PointMoment(_PointLoad):
    """A moment [N m] at arc length ``s`` [m], in the global or the local frame."""

    s: float
    moment: Any
    frame: str = "global"
    name: str = "point moment"
    _what, _unit = "moment", "N m"
    _kernels = {"local": "follower_moment", "global": "dead_moment"}

    def __post_init__(self):
        self._setup(self.name, self.moment)


class _DistributedLoad(_Load):
    _what, _kernels = "", {}

    def _setup(self):
        object.__setattr__(self, "frame", _frame(self.frame, self.name))
        value = getattr(self, self._what)
        if not callable(value):
            object.__setattr__(self, self._what, _checks.vector3(f"{self.name} {self._what}", value))

    def _sample(self, s, t):
        value = getattr(self, self._what)
        if not callable(value):
            return np.tile(value, (len(s), 1))
        try:
            raw = value(s, t)
        except RodmolError:
            raise
        except Exception as exc:  # noqa: BLE001 (the user's function: chained, never lost)
            raise _checks.user_error(self._function_name(), exc, t) from exc
        try:
            arr = np.broadcast_to(np.asarray(raw, dtype=float), (len(s), 3))
        except (TypeError, ValueError, OverflowError):
            raise _checks.bad_return(self._function_name(), raw, t,
                                     "it must return (len(s), 3) values for an array s") from None
        if not np.all(np.isfinite(arr)):
            raise _checks.bad_return(self._function_name(), raw, t, "its values must be finite")
        return arr

    def _function_name(self):
        """The load's function, as failure messages name it (built only then: sampled per evaluation)."""
        return f"{self.name}: the {self._what}(s, t) function"

    @property
    def kernel(self):
        return self._kernels[self.frame]

    @property
    def constant(self):
        return not callable(getattr(self, self._what))

    def values(self, s, t):
        """The load's density at arc lengths ``s`` [m] and time t, (len(s), 3)."""
        return self._sample(s, t)


@dataclass(frozen=True)
class DistributedForce(_DistributedLoad):
    """A force per unit length [N/m]: a constant vector or ``f(s, t)`` (s an array [m]).

    ``frame="global"``: lab-frame components (dead); ``"local"``: section frame (follower).
    """

    force: Any
    frame: str = "global"
    name: str = "distributed force"
    _what = "force"
    _kernels = {"local": "follower_force", "global": "dead_force"}

    def __post_init__(self):
        self._setup()


@dataclass(frozen=True)
class DistributedMoment(_DistributedLoad):
    """A moment per unit length [N m/m]: a constant vector or ``f(s, t)``."""

    moment: Any
    frame: str = "global"
    name: str = "distributed moment"
    _what = "moment"
    _kernels = {"local": "follower_moment", "global": "dead_moment"}

    def __post_init__(self):
        self._setup()


class _Contact(_Load):
    """Penalty contact of the tube's surface with a fixed obstacle.

    Where the surface penetrates the obstacle by a depth d > 0, the rod gets a
    force per unit length ``f_n = max(0, stiffness d - damping d_t)`` along the
    obstacle's outward normal (below ``smoothing_depth`` h the penalty is
    ``stiffness d^2 / (2 h)`` and the damping ramps up as d / h, so the
    force is continuously differentiable at first touch; beyond it the
    penalty is ``stiffness (d - h / 2)``), and a friction force opposing the sliding
    velocity ``v_t`` of the surface point, ``friction f_n v_t / sqrt(|v_t|^2 +
    slip_speed^2)`` (Coulomb's law, smoothed below ``slip_speed`` so that
    the implicit solver sees a differentiable law); both act at the surface
    point, so they also exert a moment about the centreline.
    """

    def _check_common(self):
        name = self.name
        object.__setattr__(self, "stiffness", _checks.positive(f"{name} stiffness", self.stiffness,
                                                                " N/m^2"))
        object.__setattr__(self, "damping", _checks.non_negative(f"{name} damping", self.damping,
                                                                  " N s/m^2"))
        object.__setattr__(self, "friction", _checks.non_negative(f"{name} friction", self.friction))
        object.__setattr__(self, "slip_speed", _checks.positive(f"{name} slip_speed",
                                                                 self.slip_speed, " m/s"))
        if self.smoothing_depth is not None:
            object.__setattr__(self, "smoothing_depth", _checks.positive(
                f"{name} smoothing_depth", self.smoothing_depth, " m"))

    #: The fields holding the shape's 3-vectors, in the order of its record's
    #: ``geometry`` roles (:data:`rodmol.load_kinds.KERNELS`), then those of its
    #: scalars: together they open its parameter row.
    vectors, scalars = (), ()

    def _law(self):
        return [self.stiffness, self.damping, self.friction, self.slip_speed]

    def _geometry(self):
        row = [float(x) for f in self.vectors for x in getattr(self, f)] + [float(getattr(self, f))
                                                                          for f in self.scalars]
        return row + [0.0] * (P_STIFFNESS - len(row))

    def shape_vectors(self):
        """(n, 3) the shape's 3-vectors [m or -], in its own frame (a body's, for a rodmol.Contact)."""
        return np.array([getattr(self, f) for f in self.vectors], dtype=float)

    def placed(self, position, rotation, name):
        """This shape, given in a body's frame, where the body's pose (``position``
        [m], ``rotation``, global) puts it, named ``name``: its points moved and
        turned with the body, its directions turned (the roles of its record's ``geometry``)."""
        roles = KERNELS[self.kernel].geometry
        moved = {f: rotation @ getattr(self, f) + (position if role == "point" else 0.0)
                 for f, role in zip(self.vectors, roles)}
        return dataclasses.replace(self, name=name, **moved)

    def params(self, radius):
        """The kernel's parameter rows at nodes of section radius ``radius`` [m]."""
        rows = np.zeros((len(radius), N_PARAMS))
        row = np.array(self._geometry() + self._law())
        rows[:, :len(row)] = row
        rows[:, P_RADIUS] = radius
        rows[:, P_SMOOTHING] = (SMOOTHING_FRACTION * radius if self.smoothing_depth is None
                                else self.smoothing_depth)
        return rows


@dataclass(frozen=True)
class PlaneContact(_Contact):
    """Contact with the half-space behind a plane (a floor, a wall).

    Parameters
    ----------
    point : (3,) a point of the plane [m], global.
    normal : (3,) the plane's normal [-], global, pointing out of the obstacle
        (toward the side the rod lives on); normalised here.
    stiffness : penalty stiffness per unit length of rod [N/m^2].
    damping : normal damping per unit length [N s/m^2] (acts only in contact).
    friction : Coulomb coefficient [-].
    slip_speed : sliding speed [m/s] below which friction is smoothed.
    smoothing_depth : depth [m] over which the penalty is smoothed; default
        ``SMOOTHING_FRACTION`` (1%) of the section radius at each node.
    """

    point: Any
    normal: Any
    stiffness: float
    damping: float = 0.0
    friction: float = 0.0
    slip_speed: float = 1e-4
    smoothing_depth: float | None = None
    name: str = "plane contact"
    kernel, vectors = "plane", ("point", "normal")

    def __post_init__(self):
        object.__setattr__(self, "point", _checks.vector3(f"{self.name} point", self.point))
        n = _checks.vector3(f"{self.name} normal", self.normal)
        if not np.linalg.norm(n) > 0.0:
            raise ParameterError(f"{self.name}: `normal` must not be zero, got {self.normal!r}")
        object.__setattr__(self, "normal", n / np.linalg.norm(n))
        self._check_common()


@dataclass(frozen=True)
class CapsuleContact(_Contact):
    """Contact with a capsule: the points within ``radius`` [m] of the segment
    from ``start`` to ``end`` [m] (global). See :class:`PlaneContact` for the law."""

    start: Any
    end: Any
    radius: float
    stiffness: float
    damping: float = 0.0
    friction: float = 0.0
    slip_speed: float = 1e-4
    smoothing_depth: float | None = None
    name: str = "capsule contact"
    kernel, vectors, scalars = "capsule", ("start", "end"), ("radius",)

    def __post_init__(self):
        object.__setattr__(self, "start", _checks.vector3(f"{self.name} start", self.start))
        object.__setattr__(self, "end", _checks.vector3(f"{self.name} end", self.end))
        object.__setattr__(self, "radius", _checks.positive(f"{self.name} radius", self.radius, " m"))
        self._check_common()


def SphereContact(centre, radius, stiffness, damping=0.0, friction=0.0, slip_speed=1e-4,  # noqa: N802
                  smoothing_depth=None, name="sphere contact") -> CapsuleContact:
    """Contact with a sphere of ``radius`` [m] around ``centre`` [m] (global):
    a :class:`CapsuleContact` whose segment is a point."""
    return CapsuleContact(centre, centre, radius, stiffness, damping, friction, slip_speed,
                          smoothing_depth, name)


#: The load types a Model accepts.
LOAD_TYPES = (PointForce, PointMoment, DistributedForce, DistributedMoment, PlaneContact,
              CapsuleContact, Hold)


_CONTACT_UNITS = {"stiffness": "N/m^2", "damping": "N s/m^2", "friction": "-", "slip_speed": "m/s",
                  "smoothing_depth": "m"}

#: The ``[[load]]`` types of a scenario file: type -> (constructor, units of
#: its keys). The keys are the constructor's arguments, those without a
#: default required (:mod:`rodmol.scenario.tables` derives them from here).
SCENARIO_TYPES = {
    "point_force": (PointForce, {"s": "m", "force": "N"}),
    "point_moment": (PointMoment, {"s": "m", "moment": "N m"}),
    "distributed_force": (DistributedForce, {"force": "N/m"}),
    "distributed_moment": (DistributedMoment, {"moment": "N m/m"}),
    "plane_contact": (PlaneContact, {"point": "m", "normal": "-", **_CONTACT_UNITS}),
    "sphere_contact": (SphereContact, {"centre": "m", "radius": "m", **_CONTACT_UNITS}),
    "capsule_contact": (CapsuleContact, {"start": "m", "end": "m", "radius": "m", **_CONTACT_UNITS}),
    "hold": (Hold, {"s": "m", "position": "m", "rotation": "-", "stiffness": "N/m",
                    "damping": "N s/m", "kind": "-"}),
}


def _builds(build):
    """The class a scenario type's constructor makes (a function's: its return annotation)."""
    return build if isinstance(build, type) else typing.get_type_hints(build)["return"]


#: The contact shapes (a rodmol.Contact's and a rigid body's ``contacts`` take them).
CONTACT_SHAPES = tuple(kind for kind in LOAD_TYPES if issubclass(kind, _Contact))
#: The contact types of :data:`SCENARIO_TYPES` (a rigid body's ``[[body.contact]]`` takes them too).
CONTACT_TYPES = tuple(kind for kind, (build, _) in SCENARIO_TYPES.items() if issubclass(_builds(build), _Contact))
_constructors = [SCENARIO_TYPES[kind][0].__name__ for kind in CONTACT_TYPES]
#: How messages name the contact shapes: "rodmol.PlaneContact, SphereContact or CapsuleContact".
CONTACT_NAMES = f"rodmol.{', '.join(_constructors[:-1])} or {_constructors[-1]}"
