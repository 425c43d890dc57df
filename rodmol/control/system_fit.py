"""What inverse statics of a :class:`rodmol.System` finds (:class:`SystemFit`) and how its
inputs are put on the system (:meth:`SystemFit.apply`)."""

from dataclasses import dataclass, field, replace

import numpy as np

from .. import _checks
from ..errors import ParameterError
from ._fitting import with_cables


@dataclass(frozen=True)
class SystemFit:
    """What :func:`fit_system` found.

    Attributes
    ----------
    inputs : tuple of str
        The inputs solved for, in the order of ``values`` and of ``start``:
        ``"<rod>/<cable> tension [N]"``, ``"<rod> insertion [m]"``,
        ``"<body> x [m]"`` ... ``"<body> rz [rad]"``.
    values : (n_inputs,) array
        Their values.
    tensions : dict
        Rod name -> {cable name -> tension [N]}, every cable of every rod.
    displacements : dict
        Rod name -> {cable name -> actuator position z [m]} for the actuated
        displacement-controlled cables.
    insertions : dict
        Rod name -> how far [m] its base moved along its own x axis (the rod's
        tangent there), for the rods in ``insertions``.
    driven : dict
        Body name -> (position [m], rotation (3, 3)), global: the found initial
        pose of each body in ``driven``.
    state : (size,) array
        The system's static equilibrium (``Assembly.parts``).
    tips : dict
        Rod name -> its tip [m], global.
    poses : dict
        Body name -> (position [m], rotation (3, 3)), global, every body.
    residual : float
        The weighted residual [m] over every target (as a rod's, plus
        |x - x_target|^2 and (w_d theta)^2 of each body, theta the angle
        between its rotation and the target's).
    tip_errors, direction_errors : dict
        Rod name -> [m], [rad], for the rods aimed at.
    marker_errors : dict
        Rod name -> {marker -> [m]}.
    position_errors, rotation_errors : dict
        Body name -> [m], [rad] (the rotation's only where a rotation is aimed at).
    reachable : bool
        ``residual <= tol``.
    active : dict
        Input name -> ``"lower"`` or ``"upper"``, for the inputs at a bound.
    message : str
    iterations, equilibria : int
    """

    inputs: tuple
    values: np.ndarray = field(repr=False)
    tensions: dict
    displacements: dict
    insertions: dict
    driven: dict
    state: np.ndarray = field(repr=False)
    tips: dict = field(repr=False)
    poses: dict = field(repr=False)
    residual: float
    tip_errors: dict
    direction_errors: dict
    marker_errors: dict
    position_errors: dict
    rotation_errors: dict
    reachable: bool
    active: dict
    message: str
    iterations: int
    equilibria: int

    def apply(self, system, ramp=None):
        """``system`` with the found inputs: each rod's cables as a fit of the rod
        (:meth:`StaticFit.apply`), each driven body's initial pose the found one, and
        each inserted rod's base sliding along its axis by its insertion over the first
        ``ramp`` seconds (smoothly, from rest to rest; a System's rods start where its
        joints meet them at rest, so an inserted base cannot start inserted): for
        ``simulate`` to settle into the found equilibrium."""
        rods = {}
        for name, model in system.given_rods.items():
            rods[name] = with_cables(model, self.tensions.get(name, {}), self.displacements.get(name, {}))
        moved = {name: d for name, d in self.insertions.items() if d != 0.0}
        if moved:
            if ramp is None:
                raise ParameterError(f"the fit inserts {', '.join(map(repr, moved))}: give `ramp`, the time [s] "
                                     "over which the bases slide there (a System starts with its rods where its "
                                     "joints meet them at rest)")
            ramp = _checks.positive("ramp", ramp, " s")
            for name, d in moved.items():
                rods[name] = rods[name].replace(base=replace(rods[name].base, velocity=_Slide(d, ramp)))
        bodies = {}
        for name, (position, rotation) in self.driven.items():
            body = system.bodies[name]
            motion = replace(body.motion, position=tuple(position.tolist()), rotation=tuple(map(tuple, rotation)))
            bodies[name] = replace(body, motion=motion, position=None, rotation=None)
        return system.replace(rods=rods, bodies=bodies)


class _Slide:
    """A base's velocity [m/s], local frame, sliding it along its x axis by ``distance`` [m]
    over ``duration`` [s]: d (1 - cos(pi t / T)) / 2, from rest to rest."""

    def __init__(self, distance, duration):
        self.distance, self.duration = distance, duration

    def __call__(self, t):
        rate = 0.0
        if 0.0 <= t < self.duration:
            rate = 0.5 * np.pi * self.distance / self.duration * np.sin(np.pi * t / self.duration)
        return np.array([rate, 0.0, 0.0])
