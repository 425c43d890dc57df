"""Static equilibrium of a system with free bodies: the rods' rest equations and
the free bodies' wrench balances, solved together.

Unknowns: each rod's static unknowns (:class:`RestEquations`, in ``rods``
order), then each free body's pose as 6 numbers: its origin's position x [m]
(global) and a rotation increment theta [rad] (body frame) from its initial
orientation, Q = Q_init exp(theta). Equations: each rod's rest equations with
its base clamped where the body's pose puts the clamp and its penalty joints'
held points where the bodies (or partner rods) put them, then each free body's
balance of forces and moments about its origin (body frame): the rods' clamp
wrenches (:meth:`Assembly.body_wrench`), the penalty joints' and body joints'
reactions, its contacts (:mod:`rodmol.discretise.body_contact`) and its weight
less buoyancy with the base segments it carries, read from the same
Newton-Euler rates the dynamics integrate (at v = w = 0 they are M^-1 times
the wrench, so M times them is the wrench). The loads (gravity, tensions, load
values) are ramped by the continuation of :func:`continuation`; the joints'
held points follow the bodies at every step.

The coupled Jacobian is not banded (a body's rows read its rods' first cells
and joint nodes) but sparse: each rod's band, and the rows and columns of the
couplings. :class:`CoupledDifferences` takes it in few evaluations as a
sparse matrix, factorised by a sparse LU (SuperLU through scipy), so the cost
grows about as the number of unknowns rather than its cube: on eight arms at
N = 30 on a free head (3126 unknowns) 7 MB and 0.8 s CPU against the dense
LU's 239 MB and 3.9 s (``solvers/system_equilibrium_speed.py``).
"""

import numpy as np
from scipy import sparse

from ..discretise import rotations
from ..discretise.joints import RodJointPart
from ..discretise.rigid import NET_MASS, free_body_rates
from ..discretise.system import DRAG_SMOOTHING_SPEED, QUATERNION_RESTORING_RATE
from ..errors import EquilibriumError
from ..holds import Hold
from ..loads import P_STIFFNESS
from .rest_equations import STATIC_FIELDS, RestEquations, continuation

#: A free body's pose unknowns: position (3) and rotation increment (3).
POSE_UNKNOWNS = 6


class CoupledDifferences:
    """Forward-difference Jacobian (``bands`` None: scipy CSC, or a dense array if
    ``dense``, for cross-checks) of
    :class:`FreeRestEquations`, in few evaluations: within a rod the column
    groups of its :class:`BandedDifferences`, all rods' g-th groups perturbed
    together (a rod's rows read no other rod's unknowns but through the
    joints); the columns that reach other rows (each rod's first block, whose
    strains make the clamp's wrench, the blocks of its joint nodes, and the
    bodies' poses) one at a time. Increments as the banded ones',
    1.5e-8 max(|z_j|, 1)."""

    bands = None

    def __init__(self, equations, dense=False):
        assembly, self.size, self.dense = equations.assembly, equations.size, dense
        coupled = [np.arange(equations.slices[p.name].start, equations.slices[p.name].stop) for p in assembly.free]
        nodes = {}  # rod -> the element blocks its joints read or write
        for joint in assembly.joints + assembly.rod_joints:
            for rod, node in [(joint.joint.rod, joint.node)] + (
                    [(joint.joint.partner, joint.partner_node)] if isinstance(joint, RodJointPart) else []):
                nodes.setdefault(rod, set()).add((node - assembly.parts[rod].start - equations.rods[rod].system.
                                                  layout.header) // equations.rods[rod].system.layout.block)
        grouped = []  # per rod: (columns, rows, cols) of each group, columns shifted to the unknowns
        touching = set() if assembly.rod_pairs is None else set(assembly.rod_pairs.rods)
        for name, eq in equations.rods.items():
            start, block = equations.slices[name].start, eq.static.block
            blocks = {0} | nodes.get(name, set())
            if name in touching:  # any block may touch any other: every column alone
                blocks = set(range(eq.static.n_blocks))
            alone = np.concatenate([start + b * block + np.arange(block) for b in sorted(blocks)])
            coupled.append(alone)
            groups = []
            for members, rows, cols, _ in eq.differences.groups:
                keep = ~np.isin(start + cols, alone)
                groups.append((start + members[~np.isin(start + members, alone)], start + rows[keep],
                               start + cols[keep]))
            grouped.append(groups)
        self._alone = np.concatenate(coupled)
        self._groups = [sum((g[i] for g in grouped if i < len(g)), ()) for i in range(max(map(len, grouped)))]

    def __call__(self, fun, z, f0):
        """dfun/dz at ``z`` (``f0`` = fun(z))."""
        h = 1.5e-8 * np.maximum(np.abs(z), 1.0)
        entries = []  # (rows, cols, values)
        for parts in self._groups:
            members = np.concatenate(parts[0::3])
            zp = z.copy()
            zp[members] += h[members]
            df = fun(zp) - f0
            rows, cols = np.concatenate(parts[1::3]), np.concatenate(parts[2::3])
            entries.append((rows, cols, df[rows] / h[cols]))
        for j in self._alone:
            zp = z.copy()
            zp[j] += h[j]
            column = (fun(zp) - f0) / h[j]
            rows = np.flatnonzero(column)
            entries.append((rows, np.full(len(rows), j), column[rows]))
        rows, cols, values = (np.concatenate(e) for e in zip(*entries))
        if self.dense:
            jac = np.zeros((self.size, self.size))
            jac[rows, cols] = values
            return jac
        return sparse.csc_matrix((values, (rows, cols)), shape=(self.size, self.size))


class FreeRestEquations:
    """The rest equations of an :class:`Assembly` with free bodies, at time t
    (see the module's docstring). ``residual(w, lam)`` is dimensionless: the
    rods' rows as :class:`RestEquations`', a body's force rows over the
    system's load scale S [N] (the rods' load scales and the bodies' net
    weights summed), its moment rows over S times the longest rod. ``tensions``
    ({rod: (n_cables,) [N]}) replace those rods' cable inputs (see :class:`RestEquations`)."""

    def __init__(self, assembly, t, tensions=None):
        self.assembly, self.t = assembly, t
        tensions = {} if tensions is None else tensions
        self.rods = {name: RestEquations(sd, t, tensions.get(name)) for name, sd in assembly.rods.items()}
        self.y = assembly.undeformed_state()  # fixed and driven bodies keep their initial poses
        self._gravity = np.asarray(assembly.system.gravity, dtype=float)
        gravity = np.linalg.norm(self._gravity)
        self.scale = (sum(eq.scale for eq in self.rods.values())
                      + sum(abs(p.params[NET_MASS]) * gravity for p in assembly.free)) or 1.0
        self.length = max(sd.model.rod.length for sd in assembly.rods.values())
        self._initial = {p.name: self.y[p.fields["Q"]].copy() for p in assembly.free}
        sizes = [eq.static.size for eq in self.rods.values()] + [POSE_UNKNOWNS] * len(assembly.free)
        bounds = np.cumsum([0, *sizes])
        names = list(self.rods) + [p.name for p in assembly.free]
        self.slices = {name: slice(a, b) for name, a, b in zip(names, bounds[:-1], bounds[1:])}
        self.size = int(bounds[-1])
        self._rates = np.zeros(13)
        self._clamped = {}  # rod -> (body part, its clamp's index on the body)
        for part in assembly.free:
            for i, rod in enumerate(part.rods):
                self._clamped[rod] = (part, i)

    def unknowns(self):
        """The unknowns at the initial state: rods undeformed, bodies at their poses."""
        z = np.zeros(self.size)
        for name, eq in self.rods.items():
            z[self.slices[name]] = eq.unknowns(eq.system.undeformed_state())
        for part in self.assembly.free:
            z[self.slices[part.name]][:3] = self.y[part.fields["x"]]
        return z

    def tolerance(self, tol):
        """Per-row tolerances: the rods' own (:meth:`RestEquations.tolerance`); for a
        body, ``tol`` raised to the round-off floor of the forces its balance sums,
        as a rod's rows are: its rods' cell 0 stresses (of size E A) and its joints'
        penalties on positions of size L (k L)."""
        out = np.full(self.size, float(tol))
        for name, eq in self.rods.items():
            out[self.slices[name]] = eq.tolerance(tol)
        for part in self.assembly.free:
            forces = [np.max(sd.sampled.kl[0]) for sd in part.systems]
            forces += [joint.row[P_STIFFNESS] * self.length for joint in part.joints + part.body_joints]
            floor = 10 * np.finfo(float).eps * max(forces, default=0.0) / self.scale
            out[self.slices[part.name]] = max(float(tol), floor)
        return out

    def move(self, body, position, quaternion):
        """Put the fixed or driven body ``body`` at ``position`` [m] with ``quaternion`` (body
        to global), both global, instead of its initial pose: the rods clamped to it and its
        joints follow (an input of the inverse statics)."""
        part = self.assembly.bodies[body]
        self.y[part.fields["x"]], self.y[part.fields["Q"]] = position, quaternion
        for i, rod in enumerate(part.rods):
            self._clamped[rod] = (part, i)

    def _place(self, z):
        """Write the bodies' poses and the rods' bases and static unknowns into ``self.y``."""
        y, assembly = self.y, self.assembly
        for part in assembly.free:
            pose = z[self.slices[part.name]]
            y[part.fields["x"]] = pose[:3]
            y[part.fields["Q"]] = rotations.multiply(self._initial[part.name],
                                                     rotations.from_rotation_vector(pose[3:]))
        for name, eq in self.rods.items():
            if name in self._clamped:
                part, i = self._clamped[name]
                quat = y[part.fields["Q"]]
                eq.place(y[part.fields["x"]] + rotations.matrices(quat) @ part.points[i],
                         rotations.multiply(quat, rotations.from_matrix(part.turns[i])))
            sd, rod = eq.system, y[assembly.parts[name]]
            rod[:sd.layout.header] = np.concatenate(eq.base)
            blocks, zb = sd.layout.blocks(rod), eq.static.blocks(z[self.slices[name]])
            state, static = sd.layout.slices(), eq.static.slices()
            for f in STATIC_FIELDS:
                blocks[:, state[f]] = zb[:, static[f]]
            sd.base_velocities[:] = 0.0

    def _body(self, part):
        """A body's state (x, Q, v = 0, w = 0)."""
        return np.concatenate([self.y[part.fields["x"]], self.y[part.fields["Q"]], np.zeros(6)])

    def residual(self, z, lam=1.0):
        """R(z) with the loads scaled by ``lam``; the joints' held points follow the bodies."""
        assembly, y = self.assembly, self.y
        self._place(z)
        reactions = {p.name: np.zeros(6) for p in assembly.free}
        for joint in assembly.joints + assembly.rod_joints:
            if isinstance(joint, RodJointPart):
                joint.wrench(y, joint.row, joint.value)
                continue
            force, moment = joint.wrench(y, self._body(joint.part), joint.row, joint.value)
            if joint.part.name in reactions:
                reactions[joint.part.name] += np.concatenate([force, moment])
        assembly.add_body_joints(self.t, y, reactions)  # the free bodies' velocities in y are zero
        if assembly.rod_pairs is not None:  # at rest: the penalties alone (velocities zero)
            assembly.rod_pairs.apply(y)
        out = np.empty(self.size)
        for name, eq in self.rods.items():  # held=1: a joint's gap is where the bodies are, not a load
            out[self.slices[name]] = eq.residual(z[self.slices[name]], lam, held=1.0)
        gravity = lam * self._gravity
        for part in assembly.free:
            wrench = reactions[part.name]
            if part.rods:
                wrench = wrench + np.concatenate(assembly.body_wrench(part, y))
            if part.contacts is not None:
                wrench = wrench + part.contacts.wrench(self._body(part))
            free_body_rates(self._body(part), part.params, part.rigid_mass, part.inverse_mass, gravity,
                            tuple(wrench[:3]), tuple(wrench[3:]), DRAG_SMOOTHING_SPEED**2,
                            QUATERNION_RESTORING_RATE, self._rates)
            balance = part.mass_matrix @ self._rates[7:]
            out[self.slices[part.name]] = np.concatenate([balance[:3], balance[3:] / self.length]) / self.scale
        return out

    def state(self, z):
        """The assembled state at rest of the unknowns ``z``."""
        self._place(z)
        y = self.y.copy()
        for name, eq in self.rods.items():
            y[self.assembly.parts[name]] = eq.state(z[self.slices[name]])
        return y


def floating(system):
    """The names of the free bodies of a :class:`rodmol.System` that no chain of
    rods and joints holds to the world (a fixed or driven body, a rod's base
    clamped to the world, a penalty joint or a rod's own Hold to the world): contacts do not hold a
    body at rest (friction acts on sliding only, so on a floor alone every
    horizontal position is a rest)."""
    edges = [(rod, "world" if clamp[0] is None else clamp[0]) for rod, clamp in system.clamps.items()]
    edges += [(rod, "world") for rod in system.rods if rod not in system.clamps]
    for joint in system.penalty_joints:
        edges.append((joint.rod, joint.partner if joint.partner is not None else joint.body or "world"))
    edges += [(joint.a, joint.b or "world") for joint in system.body_joints]
    of_joints = {(joint.rod, joint.load) for joint in system.penalty_joints}
    edges += [(rod, "world") for rod, model in system.rods.items()  # a rod's own holds (rodmol.Hold)
              if any(isinstance(load, Hold) and (rod, k) not in of_joints for k, load in enumerate(model.loads))]
    held = {"world"} | {name for name, body in system.bodies.items() if not body.free}
    grown = True
    while grown:
        grown = False
        for a, b in edges:
            if (a in held) != (b in held):
                held |= {a, b}
                grown = True
    return [name for name, body in system.bodies.items() if body.free and name not in held]


def free_rest_state(assembly, t, tol, max_iter):
    """The rest state of ``assembly`` (an :class:`Assembly` with free bodies) at t:
    :class:`FreeRestEquations` by load continuation from the undeformed rods at
    the bodies' initial poses. A free body that nothing holds to the world
    (:func:`floating`) has no rest, or no single one: refused."""
    loose = floating(assembly.system)
    if loose:
        names = ", ".join(map(repr, loose))
        raise EquilibriumError(f"free body {names} is held by nothing: no chain of rods and joints holds it to "
                               "the world, so its weight less buoyancy has no rest, or every pose is one "
                               "(fix it, drive it, or join it to the world or a rod held there; its contacts "
                               "do not hold it at rest: their friction acts on sliding only)")
    equations = FreeRestEquations(assembly, t)
    try:
        z = continuation(equations.residual, equations.unknowns(), equations.tolerance(tol), max_iter,
                         CoupledDifferences(equations), t)
    except EquilibriumError as exc:
        names = ", ".join(repr(part.name) for part in assembly.free)
        raise EquilibriumError(f"system with free bodies ({names}): {exc}; or a free body is not held "
                               "in every direction (a single pin leaves it free to turn)") from exc
    y = equations.state(z)
    for name, sd in assembly.rods.items():
        problem = sd.state_problem(t, y[assembly.parts[name]])
        if problem:
            raise EquilibriumError(f"rod {name!r}: the static equilibrium is not a valid state: {problem}")
    return y

