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

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from . import _checks
from .discretise import external
from .errors import ParameterError, RodmolError
from .inputs import TimeInput, as_time_input

FRAMES = ("global", "local")
#: Default contact smoothing depth, as a fraction of the section radius.
SMOOTHING_FRACTION = 0.01


@dataclass(frozen=True)
class GridLoad:
    """A load mapped onto the velocity nodes 1..N of a grid (see
    :mod:`rodmol.discretise.external` for the kinds and parameter rows).

    ``weight`` is the entry's share of the node's load density [1/m for a
    point load, 1 for densities], taking every node as standing for a length
    ds; ``concentrated`` marks point loads, whose density a scheme scales to
    its own node lengths. ``values(t)`` returns the (n_entries, 3) vectors at
    time t, or is None when they are constant (``initial`` is then used
    throughout).
    """

    kind: np.ndarray
    node: np.ndarray
    weight: np.ndarray
    params: np.ndarray
    initial: np.ndarray
    concentrated: np.ndarray
    values: Callable | None = None

    def fill(self, t, out):
        """Write the entries' values at time t into ``out`` (n_entries, 3),
        for a combined load whose ``values`` lists (entry slice, values(t))."""
        for rows, at in self.values:
            out[rows] = at(t)
        return out


def _frame(frame, name):
    if not (isinstance(frame, str) and frame in FRAMES):
        raise ParameterError(f"{name}: `frame` must be 'global' (dead load) or 'local' "
                             f"(follower load), got {_checks.short(frame)}")
    return frame


def _node_shares(s, s_nodes):
    """Velocity nodes (1..N) and weights [1/m] sharing a point load at s."""
    n = len(s_nodes) - 1
    ds = s_nodes[1] - s_nodes[0]
    x = min(s / ds, float(n))
    j = min(int(np.floor(x)), n - 1)
    f = x - j
    nodes, weights = [], []
    for node, share in ((j, 1.0 - f), (j + 1, f)):
        if node >= 1 and share > 0.0:  # node 0 is the clamped base
            nodes.append(node)
            weights.append(share / ds)
    return np.array(nodes, dtype=int), np.array(weights)


class _PointLoad:
    _what, _unit, _kinds = "", "", {}

    def _setup(self, name, value):
        object.__setattr__(self, "s", _checks.non_negative(f"{name} `s`", self.s, " m"))
        object.__setattr__(self, "frame", _frame(self.frame, name))
        object.__setattr__(self, self._what, as_time_input(f"{self._what}` of `{name}", value, 3,
                                                           self._unit))

    def on_grid(self, s_nodes, radius):
        length = float(s_nodes[-1])
        if self.s > length * (1 + 1e-12):
            raise ParameterError(f"{self.name}: `s` must lie in [0, L = {length!r} m], got {self.s!r}")
        nodes, weights = _node_shares(self.s, s_nodes)
        signal: TimeInput = getattr(self, self._what)
        count = len(nodes)
        kind = np.full(count, self._kinds[self.frame])
        initial = np.tile(signal.value(0.0), (count, 1))
        values = None if signal.constant else (lambda t: np.tile(signal.value(t), (count, 1)))
        return GridLoad(kind, nodes, weights, np.zeros((count, external.N_PARAMS)), initial,
                        np.ones(count, dtype=bool), values)


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
    _kinds = {"local": external.FOLLOWER_FORCE, "global": external.DEAD_FORCE}

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
    _kinds = {"local": external.FOLLOWER_MOMENT, "global": external.DEAD_MOMENT}

    def __post_init__(self):
        self._setup(self.name, self.moment)


class _DistributedLoad:
    _what, _kinds = "", {}

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
            raise _checks.user_error(f"{self.name}: the {self._what}(s, t) function", exc, t) from exc
        what = f"{self.name}: the {self._what}(s, t) function"
        try:
            arr = np.broadcast_to(np.asarray(raw, dtype=float), (len(s), 3))
        except (TypeError, ValueError, OverflowError):
            raise _checks.bad_return(what, raw, t, "it must return (len(s), 3) values for an array s") from None
        if not np.all(np.isfinite(arr)):
            raise _checks.bad_return(what, raw, t, "its values must be finite")
        return arr

    def on_grid(self, s_nodes, radius):
        s = s_nodes[1:]
        count = len(s)
        kind = np.full(count, self._kinds[self.frame])
        values = (lambda t: self._sample(s, t)) if callable(getattr(self, self._what)) else None
        return GridLoad(kind, np.arange(1, count + 1), np.ones(count),
                        np.zeros((count, external.N_PARAMS)), self._sample(s, 0.0),
                        np.zeros(count, dtype=bool), values)


@dataclass(frozen=True)
class DistributedForce(_DistributedLoad):
    """A force per unit length [N/m]: a constant vector or ``f(s, t)`` (s an array [m]).

    ``frame="global"``: lab-frame components (dead); ``"local"``: section frame (follower).
    """

    force: Any
    frame: str = "global"
    name: str = "distributed force"
    _what = "force"
    _kinds = {"local": external.FOLLOWER_FORCE, "global": external.DEAD_FORCE}

    def __post_init__(self):
        self._setup()


@dataclass(frozen=True)
class DistributedMoment(_DistributedLoad):
    """A moment per unit length [N m/m]: a constant vector or ``f(s, t)``."""

    moment: Any
    frame: str = "global"
    name: str = "distributed moment"
    _what = "moment"
    _kinds = {"local": external.FOLLOWER_MOMENT, "global": external.DEAD_MOMENT}

    def __post_init__(self):
        self._setup()


class _Contact:
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

    def _law(self):
        return [self.stiffness, self.damping, self.friction, self.slip_speed]

    def on_grid(self, s_nodes, radius):
        count = len(s_nodes) - 1
        params = np.zeros((count, external.N_PARAMS))
        row = np.array(self._geometry() + self._law())
        params[:, :len(row)] = row
        params[:, external.P_RADIUS] = radius[1:]
        params[:, external.P_SMOOTHING] = (SMOOTHING_FRACTION * radius[1:] if self.smoothing_depth is None
                                           else self.smoothing_depth)
        return GridLoad(np.full(count, self._kind), np.arange(1, count + 1), np.ones(count), params,
                        np.zeros((count, 3)), np.zeros(count, dtype=bool))


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
    _kind = external.PLANE

    def __post_init__(self):
        object.__setattr__(self, "point", _checks.vector3(f"{self.name} point", self.point))
        n = _checks.vector3(f"{self.name} normal", self.normal)
        if not np.linalg.norm(n) > 0.0:
            raise ParameterError(f"{self.name}: `normal` must not be zero, got {self.normal!r}")
        object.__setattr__(self, "normal", n / np.linalg.norm(n))
        self._check_common()

    def _geometry(self):
        return [*self.point, *self.normal, 0.0]


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
    _kind = external.CAPSULE

    def __post_init__(self):
        object.__setattr__(self, "start", _checks.vector3(f"{self.name} start", self.start))
        object.__setattr__(self, "end", _checks.vector3(f"{self.name} end", self.end))
        object.__setattr__(self, "radius", _checks.positive(f"{self.name} radius", self.radius, " m"))
        self._check_common()

    def _geometry(self):
        return [*self.start, *self.end, self.radius]


def SphereContact(centre, radius, stiffness, damping=0.0, friction=0.0, slip_speed=1e-4,  # noqa: N802
                  smoothing_depth=None, name="sphere contact"):
    """Contact with a sphere of ``radius`` [m] around ``centre`` [m] (global):
    a :class:`CapsuleContact` whose segment is a point."""
    return CapsuleContact(centre, centre, radius, stiffness, damping, friction, slip_speed,
                          smoothing_depth, name)


#: The load types a Model accepts.
LOAD_TYPES = (PointForce, PointMoment, DistributedForce, DistributedMoment, PlaneContact,
              CapsuleContact)


def on_grid(loads, s_nodes, radius):
    """All ``loads`` as one :class:`GridLoad` whose ``values`` is a list of
    (entry slice, values(t)) for the time-dependent ones."""
    parts = [load.on_grid(s_nodes, radius) for load in loads]
    timed, start = [], 0
    for part in parts:
        if part.values is not None:
            timed.append((slice(start, start + len(part.kind)), part.values))
        start += len(part.kind)

    def cat(name, shape):
        arrays = [getattr(p, name) for p in parts]
        return np.concatenate(arrays) if arrays else np.zeros(shape)

    return GridLoad(cat("kind", 0).astype(np.int64), cat("node", 0).astype(np.int64),
                    cat("weight", 0), cat("params", (0, external.N_PARAMS)), cat("initial", (0, 3)),
                    cat("concentrated", 0).astype(bool), timed)
