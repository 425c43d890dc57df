"""Points of the rod held to the world: :class:`Hold`, a pin or a clamp.

A load kind of :mod:`rodmol.loads` (its kinds, ``"pin"`` and ``"clamp"``,
are the records of quantity ``"hold"`` in :data:`rodmol.load_kinds.KERNELS`;
its ``[[load]] type = "hold"`` in ``SCENARIO_TYPES``); the grid
places it on its node (:mod:`rodmol.discretise.load_entries`) and the
compiled law is :func:`rodmol.discretise.external.hold`. With the base clamp,
a hold at the tip gives a rod held at both ends (docs/model.md, "Held points").
"""

from dataclasses import dataclass
from typing import Any

from . import _checks
from .errors import ParameterError
from .load_kinds import HOLD_KINDS, KERNELS

#: Default hold stiffness, as a multiple of the held element's axial
#: stiffness E A / ds times the rod's length over ds (:func:`default_stiffness`;
#: docs/model.md: the measured drift and cost).
HOLD_STIFFNESS_FACTOR = 100.0


def default_stiffness(axial_stiffness, ds, length):
    """The default stiffness [N/m] of a hold at a node whose element has the
    axial stiffness E A / ds ``axial_stiffness`` [N/m], on a rod of ``length``
    [m] and elements ``ds`` [m]: HOLD_STIFFNESS_FACTOR E A L / ds^2.

    Its compliance is ds / (HOLD_STIFFNESS_FACTOR L) of an element's, O(ds^2)
    against the whole rod's, as the scheme's own error: joints at the rods'
    ends converge at second order (with E A / ds alone their compliance, ds /
    100 of an element's, was a first-order term; docs/systems.md, "Joints at
    rods' ends")."""
    return HOLD_STIFFNESS_FACTOR * axial_stiffness * length / ds


@dataclass(frozen=True)
class Hold:
    """A point of the rod held to the world by a stiff penalty joint.

    The velocity node at arc length ``s`` [m] is pulled to ``position`` by a
    concentrated force ``F = -stiffness (u - position) - damping u_t``
    (global, [N]); ``kind="clamp"`` also holds the section's orientation at
    ``rotation`` by a moment ``stiffness r^2/4 sin(theta) n - damping r^2/4 w``,
    theta n the rotation from the section to the held orientation (local),
    r the section radius (the section's ratio I/A: the clamp holds the
    rotation as stiffly, for the section, as the position).

    Parameters
    ----------
    s : arc length [m] of the held point: a velocity node (``i L / N``, i >= 1).
    kind : ``"pin"`` (a ball joint: position only) or ``"clamp"`` (position and orientation).
    position : (3,) [m], global; default: where the point is at rest.
    rotation : (3, 3) rotation matrix (its columns the section's axes, global)
        held by a clamp; default: the section's orientation at rest.
    stiffness : penalty stiffness [N/m]; default ``HOLD_STIFFNESS_FACTOR``
        times the held element's axial stiffness E A / ds times L / ds
        (:func:`default_stiffness`: its compliance O(ds^2) against the rod's).
    damping : penalty damping [N s/m]; default critical for the node's own
        mass, 2 sqrt(stiffness m) with m = rho A ds (added mass left out).
    name : used in messages and in the result's ``meta["loads"]``.
    """

    s: float
    kind: str = "pin"
    position: Any = None
    rotation: Any = None
    stiffness: float | None = None
    damping: float | None = None
    name: str = "hold"
    # What it tells the grid (as rodmol.loads' loads do): the whole entry at its own
    # node, built by rodmol.discretise.load_entries from the rod's rest state.
    spread = "node"
    constant = True

    def __post_init__(self):
        name = self.name
        object.__setattr__(self, "s", _checks.positive(f"{name} `s`", self.s, " m"))
        object.__setattr__(self, "kind", _checks.choice(f"{name} kind", self.kind, HOLD_KINDS))
        if self.position is not None:
            object.__setattr__(self, "position", _checks.vector3(f"{name} position", self.position))
        if self.rotation is not None:
            if not KERNELS[self.kind].holds_turning:
                turning = [kind for kind in HOLD_KINDS if KERNELS[kind].holds_turning]
                raise ParameterError(f"{name}: `rotation` is held by kind={' or '.join(map(repr, turning))} only "
                                     f"(a {self.kind} leaves the section free to turn), got kind={self.kind!r}")
            object.__setattr__(self, "rotation", _checks.rotation(f"{name} rotation", self.rotation))
        if self.stiffness is not None:
            object.__setattr__(self, "stiffness", _checks.positive(f"{name} stiffness", self.stiffness,
                                                                    " N/m"))
        if self.damping is not None:
            object.__setattr__(self, "damping", _checks.non_negative(f"{name} damping", self.damping,
                                                                      " N s/m"))

    @property
    def kernel(self):
        return self.kind

    def check_within(self, length):
        """Refuse an arc length beyond the rod's ``length`` [m]."""
        if self.s > length * (1 + 1e-12):
            raise ParameterError(f"{self.name}: `s` must lie in (0, L = {length!r} m], got {self.s!r}")

    def check_grid(self, s_nodes):
        """Refuse an arc length that is not a velocity node of ``s_nodes`` [m]."""
        ds = s_nodes[1] - s_nodes[0]
        i = int(round(self.s / ds))
        if i < 1 or abs(self.s - s_nodes[min(i, len(s_nodes) - 1)]) > 1e-9 * s_nodes[-1]:
            below = float(s_nodes[max(1, min(int(self.s // ds), len(s_nodes) - 2))])
            raise ParameterError(f"{self.name}: `s` must be a velocity node i L / N (i = 1..N) of the "
                                 f"grid, got {self.s!r} m (nearest nodes: {below:.6g}, "
                                 f"{below + ds:.6g} m)")
