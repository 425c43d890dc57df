"""Inverse statics of a :class:`rodmol.System`: the inputs (the rods' cable
tensions, the insertions of rods' bases, the poses of driven bodies) whose
static equilibrium puts rods' tips, tangents and markers and bodies' poses at
their targets.

The loop is the rod's (:func:`rodmol.control._fitting.levenberg_marquardt`);
each iterate is the system's static equilibrium
(:class:`~rodmol.solve.system_equilibrium.FreeRestEquations`: the rods and the
free bodies' poses together), warm-started from the last one. The
sensitivities of the equilibrium to the inputs come from its own sparse
Jacobian by the implicit-function theorem, dR/dz dz/dp = -dR/dp (one sparse LU
for all the inputs; dR/dp exact for the tensions, the residual being affine in
them, central differences for the poses), and the outputs' derivatives are
central differences of the cheap map from the unknowns to the state, along
each input's tangent (dz/dp_j, e_j).
"""

from dataclasses import dataclass

import numpy as np
from scipy.sparse.linalg import splu

from .. import _checks
from ..discretise import rotations
from ..discretise.assembly import Assembly
from ..discretise.hand_tensions import tensions_by_hand
from ..discretise.schemes import DEFAULT_SCHEME
from ..errors import ParameterError
from ..solve.rest_equations import continuation, damped_newton
from ..solve.system_equilibrium import CoupledDifferences, FreeRestEquations, floating
from ..systems import System
from ._fitting import (
    REACH_TOLERANCE,
    actuated,
    at_bounds,
    cable_displacements,
    check_bounds,
    levenberg_marquardt,
    out_of_reach,
    verdict,
)
from .system_fit import SystemFit
from .system_targets import SystemTargets, distinct

#: The equilibria's tolerance and Newton iterations (as ``rodmol.equilibrium``'s defaults).
_TOL, _MAX_ITER = 1e-10, 40
#: Largest change [-] of a static unknown along an input's tangent in the outputs' differences.
_TANGENT_STEP = 1e-6
#: The pose inputs of a driven body: its origin's offset [m] and a rotation vector [rad], global.
POSE_AXES = ("x [m]", "y [m]", "z [m]", "rx [rad]", "ry [rad]", "rz [rad]")
POSE_UNITS = ("m",) * 3 + ("rad",) * 3


def fit_system(system, tip=None, *, direction=None, markers=None, pose=None, bounds=(0.0, np.inf), cables=None,
               insertions=None, driven=None, travel=None, t=0.0, tol=REACH_TOLERANCE, direction_weight=None,
               marker_weight=1.0, start=None, scheme=DEFAULT_SCHEME, max_iter=50):
    """The inputs, within bounds, whose static equilibrium puts the rods' tips (their
    tangents, markers) and the bodies' poses at their targets.

    Parameters
    ----------
    system : System
        Its loads act at ``t``; the inputs not solved for keep their values.
        Every free body must be held (by rods and joints) to the world.
    tip, direction : dict, optional
        Rod name -> its tip's target position [m] / its tip tangent's target
        direction, global.
    markers : dict, optional
        Rod name -> {marker name -> target position [m]}, global.
    pose : dict, optional
        Body name -> its origin's target position [m], or (position,
        rotation (3, 3) body to global), global. At least one target of any kind.
    bounds : (low, high)
        Tension bounds [N], each a number or one per actuated cable (in the
        order of the inputs); 0 <= low < high.
    cables : dict, optional
        Rod name -> the names of its actuated cables (a name or names); the
        rods left out hold theirs. Default: every cable of every rod.
    insertions : sequence of str, optional
        Rods whose base, clamped to the world (by its Model's fixed ``base``
        or a joint), slides along its own x axis (the rod's tangent there): one
        input each, the distance [m] (a prismatic actuator pushing the rod's
        base, the rod's length unchanged; Till's parallel robot inserts its
        legs through the base plate).
    driven : sequence of str, optional
        Driven bodies (a BaseMotion) whose pose is an input: six each, the
        origin's offset [m] and a rotation vector [rad] (R = exp(theta) R0),
        global, from the initial pose; unbounded.
    travel : (low, high), optional
        Insertion bounds [m], a number or one per rod in ``insertions``
        (default unbounded).
    t, tol, direction_weight, marker_weight, scheme, max_iter
        As for a rod (:func:`rodmol.inverse_statics`); ``direction_weight``
        (default each rod's length) weights the bodies' rotation errors too
        (default the longest rod).
    start : (n_inputs,) array, optional
        Initial values in the order of ``SystemFit.inputs`` (cables rod by rod,
        insertions, driven bodies' poses); default the system's own (clipped).

    Returns
    -------
    SystemFit
    """
    tol = _checks.positive("tol", tol, " m")
    max_iter = _checks.integer_at_least("max_iter", max_iter, 0)
    problem = SystemProblem(system, cables, insertions, driven, bounds, travel, t, scheme)
    targets = SystemTargets(system, problem.assembly, tip, direction, markers, pose, direction_weight, marker_weight)
    inputs = problem.start(start)
    problem.check_held()
    return problem.fit(targets, inputs, tol, max_iter)


@dataclass
class _Rest:
    """An equilibrium: the state, its static unknowns and the equations it solves."""

    y: np.ndarray
    z: np.ndarray
    equations: FreeRestEquations


class SystemProblem:
    """The inputs of a system's statics and its equilibria under them."""

    def __init__(self, system, cables, insertions, driven, bounds, travel, t, scheme):
        if not isinstance(system, System):
            raise ParameterError(f"`system` must be a rodmol.System, got {_checks.short(system)}")
        self.system, self.t = system, _checks.finite("t", t)
        loose = floating(system)
        if loose:
            raise ParameterError(f"free body {', '.join(map(repr, loose))} is held by nothing (no chain of rods "
                                 "and joints to the world): it has no rest, so no inverse statics; fix it "
                                 "(motion='fixed') or drive it")
        self.cables = self._cables(cables)
        self.inserted = self._insertions(insertions)
        self.driven = self._driven(driven)
        n_cables = sum(len(index) for index in self.cables.values())
        low, high = check_bounds("bounds", bounds, n_cables, "actuated cable", "N", lowest=0.0)
        if travel is not None and not self.inserted:
            raise ParameterError(f"`travel` bounds the insertions, but none is asked for: give `insertions`, got "
                                 f"travel={_checks.short(travel)}")
        travel = (-np.inf, np.inf) if travel is None else travel
        t_low, t_high = check_bounds("travel", travel, len(self.inserted), "inserted rod", "m")
        free = np.full(6 * len(self.driven), np.inf)
        self.low, self.high = np.concatenate([low, t_low, -free]), np.concatenate([high, t_high, free])
        self.names = [f"{rod}/{system.rods[rod].cables[i].name} tension [N]"
                      for rod, index in self.cables.items() for i in index]
        self.names += [f"{rod} insertion [m]" for rod in self.inserted]
        self.names += [f"{body} {axis}" for body in self.driven for axis in POSE_AXES]
        self.units = ["N"] * n_cables + ["m"] * len(self.inserted) + list(POSE_UNITS) * len(self.driven)
        held = system.replace(rods={name: tensions_by_hand(model) for name, model in system.given_rods.items()})
        self.assembly = Assembly(held, scheme)
        self.tensions = {name: np.array([c.tension_at(self.t) if not c.tension.feedback else 0.0
                                         for c in model.cables]) for name, model in system.rods.items()}
        self.warm, self.equilibria, self.targets = None, 0, None

    def _cables(self, cables):
        """{rod: indices of its actuated cables}, rods in the system's order."""
        rods = self.system.rods
        if cables is None:
            return {name: np.arange(len(m.cables)) for name, m in rods.items() if m.cables}
        if not isinstance(cables, dict):
            raise ParameterError(f"`cables` must map rod names to cable names, got {_checks.short(cables)}")
        for name in cables:
            if name not in rods:
                raise ParameterError(f"`cables`: no rod named {name!r} in the system" + _checks.did_you_mean(name, rods))
        return {name: actuated([c.name for c in m.cables], cables[name], f"rod {name!r}")
                for name, m in rods.items() if name in cables}

    def _insertions(self, insertions):
        system = self.system
        names = distinct("insertions", insertions, system.rods, "rod")
        for name in names:
            body = system.clamps.get(name, (None,))[0]
            where = ("pinned or joined to another rod" if name in system.base_bodies else
                     f"on body {body!r}" if body is not None else
                     None if system.rods[name].base.fixed else "moving (its Model's base moves)")
            if where:
                raise ParameterError(f"`insertions`: rod {name!r}'s base is {where}; an insertion slides a base "
                                     "clamped to the world (move a body by `driven`)")
        return names

    def _driven(self, driven):
        bodies = self.system.bodies
        names = distinct("driven", driven, bodies, "body")
        for name in names:
            if not bodies[name].driven:
                raise ParameterError(f"`driven`: body {name!r} is {bodies[name].motion!r}, not driven (a "
                                     "BaseMotion): only a driven body's pose is an input")
        return names

    def check_held(self):
        """The cables not actuated must not read the state: their tensions are held."""
        for name, model in self.system.rods.items():
            chosen = self.cables.get(name, ())
            for i, cable in enumerate(model.cables):
                if i not in chosen and cable.tension.feedback:
                    raise ParameterError(f"cable {cable.name!r} of rod {name!r} reads the state (feedback or "
                                         "displacement control): list it in `cables` to solve for it")

    def start(self, start):
        n = len(self.names)
        if start is None:  # the tensions at t (a feedback law's: slack), no insertion, the initial poses
            values = np.zeros(n)
            tensions = [self.tensions[rod][index] for rod, index in self.cables.items()]
            if tensions:
                values[:sum(map(len, tensions))] = np.concatenate(tensions)
        else:
            values = _checks.floats(start)
            if values is None or values.shape != (n,) or not np.all(np.isfinite(values)):
                raise ParameterError(f"`start` must be {n} finite numbers (one per input: {', '.join(self.names)}), "
                                     f"got {_checks.short(start)}")
        return np.clip(values, self.low, self.high)

    # ------------------------------------------------------------------ the equilibria

    def _split(self, p):
        """(tensions {rod: (n_cables,)}, insertions (n,), poses (n_driven, 6)) of inputs ``p``."""
        tensions, k = {}, 0
        for rod, held in self.tensions.items():
            tensions[rod] = held.copy()
            index = self.cables.get(rod, np.zeros(0, dtype=int))
            tensions[rod][index] = p[k:k + len(index)]
            k += len(index)
        insertions = p[k:k + len(self.inserted)]
        return tensions, insertions, p[k + len(self.inserted):].reshape(-1, 6)

    def _place(self, equations, p):
        """Put the inserted bases and the driven bodies where the inputs ``p`` say."""
        _, insertions, poses = self._split(p)
        for rod, d in zip(self.inserted, insertions):
            base = self.assembly.rods[rod].model.base
            rotation = np.asarray(base.rotation, dtype=float)
            equations.rods[rod].place(np.asarray(base.position, dtype=float) + d * rotation[:, 0],
                                      rotations.from_matrix(rotation))
        for body, pose in zip(self.driven, poses):
            b = self.system.bodies[body]
            turned = rotations.multiply(rotations.from_rotation_vector(pose[3:]), rotations.from_matrix(b.rotation))
            equations.move(body, b.position + pose[:3], turned)

    def _equations(self, p):
        equations = FreeRestEquations(self.assembly, self.t, self._split(p)[0])
        self._place(equations, p)
        return equations

    def rest(self, p):
        """The equilibrium under inputs ``p``: Newton from the last one, else the loads'
        continuation from the undeformed rods."""
        self.equilibria += 1
        equations = self._equations(p)
        tol, jacobian = equations.tolerance(_TOL), CoupledDifferences(equations)
        z = None
        if self.warm is not None:
            z = damped_newton(equations.residual, self.warm.z, tol, _MAX_ITER, jacobian)
        if z is None:
            z = continuation(equations.residual, equations.unknowns(), tol, _MAX_ITER, jacobian, self.t)
        self.warm = _Rest(equations.state(z), z, equations)
        return self.warm

    def values(self, rest):
        return self.targets.values(rest.y)

    def jacobian(self, rest, p):
        """d outputs / d inputs: the unknowns' tangents dz/dp by the implicit-function
        theorem, then the outputs' central differences along (dz/dp_j, e_j)."""
        equations, z = rest.equations, rest.z
        r0 = equations.residual(z)
        solve = splu(CoupledDifferences(equations)(equations.residual, z, r0).tocsc()).solve
        d_r = np.empty((len(z), len(p)))
        k = 0
        for rod, index in self.cables.items():
            eq = equations.rods[rod]
            held = eq.tensions
            for i in index:
                eq.tensions = held.copy()
                eq.tensions[i] += 1.0  # the residual is affine in the tensions
                d_r[:, k] = equations.residual(z) - r0
                k += 1
            eq.tensions = held
        length = max(sd.model.rod.length for sd in self.assembly.rods.values())
        for j in range(k, len(p)):
            h = 1e-6 * (1.0 if self.units[j] == "rad" else length)
            d_r[:, j] = (self._residual_at(equations, z, p, j, h) - self._residual_at(equations, z, p, j, -h)) / (2 * h)
        self._place(equations, p)
        d_z = -solve(d_r)
        jac = np.empty((len(self.targets.aim), len(p)))
        for j in range(len(p)):
            size = np.max(np.abs(d_z[:, j]))
            h = min(1e-6 * (1.0 if self.units[j] in ("N", "rad") else length), _TANGENT_STEP / max(size, 1e-300))
            sides = []
            for sign in (1.0, -1.0):
                shifted = p.copy()
                shifted[j] += sign * h
                self._place(equations, shifted)
                sides.append(self.targets.values(equations.state(z + sign * h * d_z[:, j])))
            jac[:, j] = (sides[0] - sides[1]) / (2 * h)
        self._place(equations, p)
        return jac

    def _fixed_base(self, rod):
        """Rod ``rod``'s base position [m] if neither an input nor a free body moves it, else None."""
        system = self.system
        if rod in self.inserted or rod in system.base_bodies:
            return None
        body, point, _ = system.clamps.get(rod, (None, None, None))
        if body is None:
            base = system.rods[rod].base
            return np.asarray(base.position, dtype=float) if base.fixed else None
        b = system.bodies[body]
        return None if b.free or body in self.driven else b.position + b.rotation @ point

    def _residual_at(self, equations, z, p, j, h):
        shifted = p.copy()
        shifted[j] += h
        self._place(equations, shifted)
        return equations.residual(z)

    def fit(self, targets, inputs, tol, max_iter):
        """The bounded least squares on ``targets`` (a :class:`SystemTargets`) from ``inputs``,
        warm-started from the last equilibrium solved, reported."""
        self.targets = targets
        values, rest, r, accepted = levenberg_marquardt(self, targets.aim, inputs, tol, max_iter)
        return self.report(values, rest, r, tol, accepted)

    # ------------------------------------------------------------------ the report

    def report(self, p, rest, r, tol, iterations):
        residual = float(np.linalg.norm(r))
        tensions, insertions, _ = self._split(p)
        y, assembly = rest.y, self.assembly
        displacements = {}
        for rod, index in self.cables.items():
            sd, model = assembly.rods[rod], self.system.rods[rod]
            found = cable_displacements(model, sd.state_view(self.t, y[assembly.parts[rod]]), index,
                                        tensions[rod][index])
            if found:
                displacements[rod] = found
        tips = {name: sd.state_view(self.t, y[assembly.parts[name]]).tip for name, sd in assembly.rods.items()}
        poses = {name: (y[part.fields["x"]].copy(), rotations.matrices(y[part.fields["Q"]]))
                 for name, part in assembly.bodies.items()}
        errors = self.targets.errors(y)
        active = at_bounds(p, self.low, self.high, self.names)
        far = [out_of_reach(f"the tip of rod {rod!r}", self._fixed_base(rod), target, self.system.rods[rod].rod.length)
               for rod, target in self.targets.tips.items() if self._fixed_base(rod) is not None]
        message = verdict(residual, tol, iterations, self.equilibria, active,
                          {n: f"{h:.4g} {u}" for n, h, u in zip(self.names, self.high, self.units)},
                          [note for note in far if note])
        return SystemFit(tuple(self.names), p.copy(),
                         {rod: dict(zip([c.name for c in self.system.rods[rod].cables], values.tolist()))
                          for rod, values in tensions.items()},
                         displacements, dict(zip(self.inserted, insertions.tolist())),
                         {name: poses[name] for name in self.driven}, y, tips, poses, residual,
                         *errors, residual <= tol, active, message, iterations, self.equilibria)
