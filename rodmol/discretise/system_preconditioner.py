"""A block-diagonal preconditioner of CVODE's Newton matrix for a system of
rods and rigid bodies (:class:`rodmol.discretise.assembly.Assembly`).

Each rod gets its own exact block preconditioner
(:class:`rodmol.discretise.preconditioner.BlockPreconditioner`), its base
velocities held at the state's; each body its block (I - gamma J_bb),
inverted directly, J_bb by differences in the body's own entries: of the
full right-hand side in its velocities (they move the rods' bases), of its
own rates in its rotation and, if it has penalty joints (whose held points
it moves), its position; no rate of a body without them reads its
position. The tree joints' coupling blocks are left out: GMRES's products
J v are differences of the full right-hand side, so it sees them, only
converging in more iterations.

A body's joints to the world or to fixed or driven bodies are in its own
block; a joint between two free bodies couples their blocks as stiffly as
it holds them: both bodies join the Schur complement below, with the
coupling blocks N_b1b2 (by differences of the full right-hand side in one
body's entries, the other's rows).

A penalty joint between a rod node and a free body couples them as stiffly
as it holds them: left out, GMRES needs hundreds of times the right-hand
sides or fails. Its blocks are kept, and the free bodies with penalty
joints are eliminated by their Schur complement: with N = I - gamma J split
into the rods (r) and those bodies (b), N_rb holding each joint node's
velocity rows against its body's entries and N_br the body's rows against
the node's u, Q, v, w (both by differences), S = N_bb - N_br N_rr^-1 N_rb
(dense, one block of ``rigid.FREE_BODY.size`` rows per body) is formed at each setup from one rod solve per
body column and joined rod; a solve is z_r' = N_rr^-1 r_r, z_b = S^-1
(r_b - N_br z_r'), z_r = z_r' - N_rr^-1 N_rb z_b.
"""

from dataclasses import dataclass

import numpy as np

from .joints import block_entries
from .rigid import FREE_BODY

#: A joint node's rows (its velocities) and columns (what the joint reads), within its element block.
JOINT_ROWS, JOINT_COLUMNS = block_entries("v", "w"), block_entries("u", "Q", "v", "w")

#: Relative step of the body blocks' differences, times each entry's scale.
BODY_STEP = 1e-7


@dataclass(eq=False)
class Coupling:
    """A coupling of a Schur body with rod ``rod``: the rod's ``rows`` its
    entries move and the ``columns`` its rates read (state indices), and
    the blocks by differences, ``rod_to_body`` (N_rb / -gamma, rows x body)
    and ``body_to_rod`` (N_br / -gamma, body x columns). ``full``: the
    body's rates read the columns through the rod's rates (a clamp: cell
    0's stress), so their differences take the rod's rates first."""

    rod: str
    rows: np.ndarray
    columns: np.ndarray
    full: bool

    def __post_init__(self):
        self.rod_to_body = np.zeros((len(self.rows), FREE_BODY.size))
        self.body_to_rod = np.zeros((FREE_BODY.size, len(self.columns)))


def couplings(assembly, part):
    """The :class:`Coupling` of a Schur body ``part``: its penalty joints'
    nodes and, for a pinned base (``segment_only``), its rods' clamps (the
    header and first element: they outweigh the segment's own mass)."""
    found = [Coupling(j.joint.rod, j.node + JOINT_ROWS, j.node + JOINT_COLUMNS, False) for j in part.joints]
    for name, sd in zip(part.rods, part.systems) if part.segment_only else ():
        start = assembly.parts[name].start
        first = np.arange(start, start + sd.layout.header + sd.layout.block)
        found.append(Coupling(name, first, first, True))
    return found


class SystemPreconditioner:
    """scikit-sundae ``precond`` callbacks (:meth:`setup`, :meth:`solve`) of ``assembly``;
    ``scale`` (size,) is each entry's typical magnitude (atol / rtol)."""

    def __init__(self, assembly, scale):
        self.assembly = assembly
        self.rods = {name: sd.preconditioner(scale[assembly.parts[name]]) for name, sd in assembly.rods.items()}
        self.bodies = list(assembly.bodies.values())
        self._steps = {p.name: BODY_STEP * np.maximum(scale[p.slice], 1e-300) for p in self.bodies}
        self._jac = {p.name: np.zeros((p.layout.size, p.layout.size)) for p in self.bodies}
        self._inverse = {p.name: np.eye(p.layout.size) for p in self.bodies}
        self._field_of = {p.name: [f for f, n in p.layout.fields.items() for _ in range(n)] for p in self.bodies}
        self._out = np.empty(assembly.size)
        self._scale, self.gamma = scale, np.nan
        # The Schur complement's bodies (free, with penalty joints, joints to other free bodies or a
        # pinned base's), their offsets in S, their couplings with rods and with their free partners.
        self._partners = {p.name: [o for j in p.body_joints for o in j.parts if o is not p and o.body.free]
                          for p in self.bodies}
        self.coupled = [p for p in self.bodies
                        if p.body.free and (p.joints or self._partners[p.name] or (p.segment_only and p.rods))]
        self._couplings = {p.name: couplings(assembly, p) for p in self.coupled}
        self._pairs = {(p.name, o.name): np.zeros((FREE_BODY.size, FREE_BODY.size))
                       for p in self.coupled for o in self._partners[p.name]}  # o's rows, p's columns
        self._offset = dict(zip((p.name for p in self.coupled), FREE_BODY.size * np.arange(len(self.coupled))))
        self._schur = np.eye(FREE_BODY.size * len(self.coupled))
        self.jac_evals = self.setups = self.solves = 0

    def setup(self, t, y, fy, jok, jnew, gamma):
        """Refresh the blocks if CVODE says they are stale (``jok`` false), then factor."""
        assembly, parts = self.assembly, self.assembly.parts
        if jok:
            jnew[0] = 0
        else:
            assembly(t, y, self._out)  # the rods' base velocities at y
            for name, prec in self.rods.items():
                prec.jacobian.evaluate(t, y[parts[name]], fy[parts[name]])
            z = np.array(y)
            for part in self.bodies:
                assembly(t, y, self._out)  # the rods' stress at y (their Jacobians and other bodies moved it)
                coupled = part in self.coupled
                if coupled:
                    self._coupling_columns(part, t, y, fy, z)
                jac, steps = self._jac[part.name], self._steps[part.name]
                for j, index in enumerate(range(part.slice.start, part.slice.stop)):
                    field = self._field_of[part.name][j]
                    if field == "x" and not (part.joints or part.body_joints) and part.contacts is None:
                        continue
                    z[index] = y[index] + steps[j]
                    if field in ("x", "Q") and not coupled:  # of the rates kept, only the body's read its pose
                        assembly.body_rates(part, t, z, self._out)
                    else:  # its velocities move the rods' bases, its pose the joints' held points
                        assembly(t, z, self._out)
                    jac[:, j] = (self._out[part.slice] - fy[part.slice]) / steps[j]
                    for c in self._couplings[part.name] if coupled else ():
                        c.rod_to_body[:, j] = (self._out[c.rows] - fy[c.rows]) / steps[j]
                    for other in self._partners[part.name] if coupled else ():
                        rows = other.slice
                        self._pairs[part.name, other.name][:, j] = (self._out[rows] - fy[rows]) / steps[j]
                    z[index] = y[index]
            assembly(t, y, self._out)  # leave the rods as at y
            self.jac_evals += 1
            jnew[0] = 1
        for prec in self.rods.values():
            prec.factor(gamma)
        for part in self.bodies:
            self._inverse[part.name] = np.linalg.inv(np.eye(part.layout.size) - gamma * self._jac[part.name])
        self.gamma = gamma
        if self.coupled:
            self._factor_schur(gamma)
        self.setups += 1

    def _coupling_columns(self, part, t, y, fy, z):
        """The body's rows against each coupling's columns (N_br / -gamma), by differences of its rates."""
        assembly = self.assembly
        for c in self._couplings[part.name]:
            rod = assembly.parts[c.rod]
            for k, index in enumerate(c.columns):
                step = BODY_STEP * max(self._scale[index], 1e-300)
                z[index] = y[index] + step
                if c.full:  # the rod's rates (its cell 0's stress), its base velocities as at y
                    assembly.rods[c.rod](t, z[rod], self._out[rod])
                assembly.body_rates(part, t, z, self._out)
                c.body_to_rod[:, k] = (self._out[part.slice] - fy[part.slice]) / step
                z[index] = y[index]
        assembly(t, y, self._out)

    def _rod_solve(self, name, rows_values):
        """N_rr^-1 of a right-hand side nonzero at coupling rows only: [(coupling, values)] of rod ``name``."""
        rhs = np.zeros(self.assembly.rods[name].size)
        start = self.assembly.parts[name].start
        for c, values in rows_values:
            rhs[c.rows - start] += values
        return self.rods[name].apply(rhs)

    def _by_rod(self, part):
        """``part``'s couplings grouped by rod."""
        by_rod = {}
        for c in self._couplings[part.name]:
            by_rod.setdefault(c.rod, []).append(c)
        return by_rod

    def _factor_schur(self, gamma):
        """S = N_bb - N_br N_rr^-1 N_rb over the coupled bodies, inverted."""
        schur, size = np.zeros_like(self._schur), FREE_BODY.size
        for part in self.coupled:
            o = self._offset[part.name]
            schur[o:o + size, o:o + size] = np.eye(size) - gamma * self._jac[part.name]
        for (name, other), block in self._pairs.items():  # the body joints' coupling of two free bodies
            o, oo = self._offset[name], self._offset[other]
            schur[oo:oo + size, o:o + size] -= gamma * block
        for part in self.coupled:
            o = self._offset[part.name]
            for rod, found in self._by_rod(part).items():
                start = self.assembly.parts[rod].start
                for k in range(size):
                    x = self._rod_solve(rod, [(c, -gamma * c.rod_to_body[:, k]) for c in found])
                    for other in self.coupled:  # every body coupled to this rod reads x at its columns
                        oo = self._offset[other.name]
                        for c in self._by_rod(other).get(rod, ()):
                            schur[oo:oo + size, o + k] -= -gamma * c.body_to_rod @ x[c.columns - start]
        self._schur = np.linalg.inv(schur)

    def solve(self, t, y, fy, r, z, gamma, delta, lr):
        """z = P^-1 r with the last factors."""
        parts = self.assembly.parts
        for name, prec in self.rods.items():
            sl = parts[name]
            prec.solve(t, y[sl], fy[sl], r[sl], z[sl], gamma, delta, lr)
        for part in self.bodies:
            if part not in self.coupled:
                z[part.slice] = self._inverse[part.name] @ r[part.slice]
        if not self.coupled:
            self.solves += 1
            return
        g = self.gamma
        rhs = np.concatenate([r[part.slice] for part in self.coupled])
        for part in self.coupled:
            o = self._offset[part.name]
            for c in self._couplings[part.name]:
                rhs[o:o + FREE_BODY.size] -= -g * c.body_to_rod @ z[c.columns]
        z_b = self._schur @ rhs
        by_rod = {}
        for part in self.coupled:
            o = self._offset[part.name]
            z[part.slice] = z_b[o:o + FREE_BODY.size]
            for c in self._couplings[part.name]:
                by_rod.setdefault(c.rod, []).append((c, -g * c.rod_to_body @ z_b[o:o + FREE_BODY.size]))
        for rod, rows_values in by_rod.items():
            z[parts[rod]] -= self._rod_solve(rod, rows_values)
        self.solves += 1
