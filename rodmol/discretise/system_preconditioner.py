"""A block-diagonal preconditioner of CVODE's Newton matrix for a system of
rods and rigid bodies (:class:`rodmol.discretise.assembly.Assembly`).

Each rod gets its own exact block preconditioner
(:class:`rodmol.discretise.preconditioner.BlockPreconditioner`), its base
velocities held at the state's; each body its block (I - gamma J_bb),
inverted directly, J_bb by differences in the body's own entries: of the
full right-hand side in its velocities (they move the rods' bases), of its
own rates in its rotation and, if it has penalty joints (whose held points
it moves), its position; no rate of a body without them reads its
position.

A free body is coupled to its rods both ways, and the coupling blocks are
kept: the free bodies that carry rods, have penalty joints or are joined to
other free bodies are eliminated by their Schur complement. Each coupling is a link between a body and a
rod: a rod clamped to the body (a tree joint) links the rod's header and
first element (their rows read the body's velocities: :meth:`Assembly.pattern`)
and that element's strains and velocities (the body's rows read cell 0's
stress from them: :data:`CLAMP_COLUMNS`), a penalty joint links its node's
velocity rows (they read the body's pose and velocities) and its u, Q, v, w
(the body's rows read the joint's reaction). A penalty joint couples as
stiffly as it holds: left out, GMRES needed hundreds of times the
right-hand sides or failed. A clamp's coupling left out (as it was until
the octopus was measured) cost GMRES a second iteration per Newton
iteration (solvers/octopus_stats.py). A joint between two free bodies
couples their blocks as stiffly as it holds them: both are in the Schur
complement, with the coupling blocks N_b1b2 (by differences of the full
right-hand side in one body's entries, the other's rows); a body's joints
to the world or to fixed or driven bodies are in its own block (left out,
two clamped bodies took 19 times the right-hand sides, a pinned base's
segment 240 times: solvers/body_joints.py).
With N = I - gamma J split into the rods (r) and
those bodies (b), N_rb holding the links' rod rows against the body's
entries and N_br the body's rows against the links' rod entries (both by
differences), S = N_bb - N_br N_rr^-1 N_rb (dense, one block of
``rigid.FREE_BODY.size`` rows per body) is formed at each setup from one
rod solve per body column that moves the rod and joined rod; a solve is
z_r' = N_rr^-1 r_r, z_b = S^-1 (r_b - N_br z_r'), z_r = z_r' - N_rr^-1
N_rb z_b. A penalty joint between two rods' nodes couples them as
stiffly: its blocks are kept on top of all this, by their own Schur
complement (:mod:`rodmol.discretise.rod_joint_coupling`).
"""

import numpy as np

from .body_part import first_element
from .joints import JOINT_COLUMNS, JOINT_ROWS, block_entries
from .rigid import FREE_BODY
from .rod_blocks import RodBlocks
from .rod_joint_coupling import RodJointCoupling

#: What a body reads of a rod clamped to it, within the rod's first element block: the stress of
#: cell 0, from its strains and (the viscous law) their rates.
CLAMP_COLUMNS = block_entries("q", "k", "v", "w")

#: Relative step of the body blocks' differences, times each entry's scale.
BODY_STEP = 1e-7


class Link:
    """One coupling of a free body with a rod in the Schur complement: the
    rod's ``rows`` that read the body and its entries (``columns``) that
    the body's rows read, state indices; ``to_body`` (rows x body entries)
    and ``from_rod`` (body entries x columns) are their Jacobian blocks,
    J_rb and J_br (N = -gamma J off the diagonal). ``clamp``: the rod's base
    is clamped to the body (the body's rows read the columns through the
    rod's stress, so a column's difference re-evaluates the rod), else a
    penalty joint (through the joint's reaction)."""

    def __init__(self, rod, rows, columns, clamp):
        self.rod, self.rows, self.columns, self.clamp = rod, rows, columns, clamp
        self.to_body = np.zeros((len(rows), FREE_BODY.size))
        self.from_rod = np.zeros((FREE_BODY.size, len(columns)))


def links(assembly, part):
    """The :class:`Link` s of free body ``part``: its clamped rods' header and
    first element, its penalty joints' nodes."""
    out = []
    for name, sd in zip(part.rods, part.systems):
        start = assembly.parts[name].start
        out.append(Link(name, first_element(start, sd), start + sd.layout.header + CLAMP_COLUMNS, True))
    for joint in part.joints:
        out.append(Link(joint.joint.rod, joint.node + JOINT_ROWS, joint.node + JOINT_COLUMNS, False))
    return out


class SystemPreconditioner:
    """scikit-sundae ``precond`` callbacks (:meth:`setup`, :meth:`solve`) of ``assembly``;
    ``scale`` (size,) is each entry's typical magnitude (atol / rtol)."""

    def __init__(self, assembly, scale):
        self.assembly = assembly
        self.rods = {name: sd.preconditioner(scale[assembly.parts[name]]) for name, sd in assembly.rods.items()}
        self.bodies = list(assembly.bodies.values())
        self._steps = {p.name: BODY_STEP * np.maximum(scale[p.slice], 1e-300) for p in self.bodies}
        self._jac = {p.name: np.zeros((p.layout.size, p.layout.size)) for p in self.bodies}
        self._inverse = {}  # the bodies outside the Schur complement: their own blocks inverted
        self._field_of = {p.name: [f for f, n in p.layout.fields.items() for _ in range(n)] for p in self.bodies}
        self._out = np.empty(assembly.size)
        self._scale = scale
        # The Schur complement's bodies (free, with rods, penalty joints or free partners joined to them),
        # their links and offsets in S, and the blocks of their joints to their free partners.
        self._partners = {p.name: [o for j in p.body_joints for o in j.parts if o is not p and o.body.free]
                          for p in self.bodies}
        self.coupled = [p for p in self.bodies if p.body.free and (p.rods or p.joints or self._partners[p.name])]
        self._pairs = {(p.name, o.name): np.zeros((FREE_BODY.size, FREE_BODY.size))
                       for p in self.coupled for o in self._partners[p.name]}  # o's rows, p's columns
        self.links = {p.name: links(assembly, p) for p in self.coupled}
        self._offset = dict(zip((p.name for p in self.coupled), FREE_BODY.size * np.arange(len(self.coupled))))
        size = FREE_BODY.size * len(self.coupled)
        self._schur = np.eye(size)
        # Per linked rod, N_rr^-1 N_rb (its columns: S's); all links' rod entries and N_br over them.
        # All of them rows of one matrix (one product per solve, not one per rod).
        linked = list(dict.fromkeys(link.rod for p in self.coupled for link in self.links[p.name]))
        self._solved_rows = np.concatenate([np.arange(assembly.parts[rod].start, assembly.parts[rod].stop)
                                            for rod in linked] or [np.zeros(0, dtype=int)])
        self._all_solved = np.zeros((len(self._solved_rows), size))
        if len(self._solved_rows) and np.all(np.diff(self._solved_rows) == 1):  # a slice costs 3 us less
            self._solved_rows = slice(int(self._solved_rows[0]), int(self._solved_rows[-1]) + 1)
        self._where_solved, first = {}, 0  # each linked rod's first row of _all_solved
        for rod in linked:
            self._where_solved[rod] = first
            first += assembly.rods[rod].size
        self._reads = np.concatenate([link.columns for p in self.coupled for link in self.links[p.name]]
                                     or [np.zeros(0, dtype=int)])
        where = np.full(assembly.size, -1)
        where[self._solved_rows] = np.arange(len(self._all_solved))
        self._reads_solved = where[self._reads]  # each read entry's row of _all_solved
        self._n_br = np.zeros((size, len(self._reads)))
        self._body_rows = np.concatenate([np.arange(p.slice.start, p.slice.stop) for p in self.coupled]
                                         or [np.zeros(0, dtype=int)])  # S's rows, state indices
        self._n_br_jac = np.zeros_like(self._n_br)  # N_br / -gamma
        self._s_jac = np.zeros((size, size))  # (I - S) / gamma before the rods' part
        # Per rod size and count of body entries moving a rod: (the rods, their rows and columns
        # of _all_solved, N_rb / -gamma in those entries); after each Jacobian (_moved).
        self._couplings = []
        self.rod_blocks = RodBlocks(self.rods, assembly.parts)  # the rods' blocks, solved together
        self.rod_joints = RodJointCoupling(assembly, BODY_STEP * np.maximum(scale, 1e-300), JOINT_ROWS)
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
                part_links = self.links.get(part.name, ())
                for link in part_links:
                    self._rod_columns(part, link, t, y, fy, z)
                jac, steps = self._jac[part.name], self._steps[part.name]
                for j, index in enumerate(range(part.slice.start, part.slice.stop)):
                    field = self._field_of[part.name][j]
                    if field == "x" and not (part.joints or part.body_joints) and part.contacts is None:
                        continue  # no rate reads its position
                    z[index] = y[index] + steps[j]
                    # Its velocities move the rods' bases, its pose the joints' held points and its free
                    # partners' rates; of the rest only the body's own rates read its pose.
                    full = field in ("v", "w") or bool(part.joints) or bool(self._partners[part.name])
                    if full:
                        assembly(t, z, self._out)
                    else:
                        assembly.body_rates(part, t, z, self._out)
                    jac[:, j] = (self._out[part.slice] - fy[part.slice]) / steps[j]
                    for link in part_links:
                        link.to_body[:, j] = (self._out[link.rows] - fy[link.rows]) / steps[j] if full else 0.0
                    for other in self._partners[part.name] if part in self.coupled else ():
                        rows = other.slice
                        self._pairs[part.name, other.name][:, j] = (self._out[rows] - fy[rows]) / steps[j]
                    z[index] = y[index]
            assembly(t, y, self._out)  # leave the rods as at y
            if self.rod_joints.sides:
                self.rod_joints.evaluate(t, y, fy)
            self._moved()
            self.jac_evals += 1
            jnew[0] = 1
        self.rod_blocks.factor(gamma)
        for part in self.bodies:
            if part not in self.coupled:
                self._inverse[part.name] = np.linalg.inv(np.eye(part.layout.size) - gamma * self._jac[part.name])
        if self.coupled:
            self._factor_schur(gamma)
        if self.rod_joints.sides:
            self.rod_joints.factor(gamma, self._solve_blocks)
        self.setups += 1

    def _rod_columns(self, part, link, t, y, fy, z):
        """The body's rows against the link's rod entries (J_br), by differences of its rates; a
        clamp's through its rod's rates (its stress), left as at y."""
        assembly = self.assembly
        rod, sl = assembly.rods[link.rod], assembly.parts[link.rod]
        for c, index in enumerate(link.columns):
            step = BODY_STEP * max(self._scale[index], 1e-300)
            z[index] = y[index] + step
            if link.clamp:
                rod(t, z[sl], self._out[sl])
            assembly.body_rates(part, t, z, self._out)
            link.from_rod[:, c] = (self._out[part.slice] - fy[part.slice]) / step
            z[index] = y[index]
        if link.clamp:
            rod(t, y[sl], self._out[sl])

    def _factor_schur(self, gamma):
        """S = N_bb - N_br N_rr^-1 N_rb over the coupled bodies, inverted; N_rr^-1 N_rb and N_br kept."""
        self._n_br = -gamma * self._n_br_jac
        for names, rows, columns, coupling in self._couplings:
            self._all_solved[rows, columns] = self.rod_blocks.solve_rows(names, gamma * coupling).transpose(0, 2, 1)
        # every body linked to a rod reads N_rr^-1 N_rb at its links' columns
        schur = np.eye(len(self._schur)) - gamma * self._s_jac - self._n_br @ self._all_solved[self._reads_solved]
        self._schur = np.linalg.inv(schur)

    def _moved(self):
        """After a Jacobian: its parts of S and N_br over -gamma, and per coupled body and rod the
        body entries that move the rod (a clamp's: its velocities) with N_rb / -gamma in them,
        stacked by rod size and count (one compiled call of rod solves each at a factorisation)."""
        size = FREE_BODY.size
        self._s_jac[:] = 0.0
        self._n_br_jac[:] = 0.0
        column = 0
        for part in self.coupled:
            o = self._offset[part.name]
            self._s_jac[o:o + size, o:o + size] = self._jac[part.name]
            for link in self.links[part.name]:
                self._n_br_jac[o:o + size, column:column + len(link.columns)] = link.from_rod
                column += len(link.columns)
        for (name, other), block in self._pairs.items():  # the body joints' coupling of two free bodies
            o, oo = self._offset[name], self._offset[other]
            self._s_jac[oo:oo + size, o:o + size] += block
        self._all_solved[:] = 0.0  # the columns no body entry moves stay zero
        stacks = {}
        for part in self.coupled:
            by_rod = {}
            for link in self.links[part.name]:
                by_rod.setdefault(link.rod, []).append(link)
            for rod, rod_links in by_rod.items():
                moving = np.flatnonzero(np.any([link.to_body.any(axis=0) for link in rod_links], axis=0))
                start, n = self.assembly.parts[rod].start, self.assembly.rods[rod].size
                coupling = np.zeros((len(moving), n))
                for link in rod_links:
                    coupling[:, link.rows - start] -= link.to_body[:, moving].T
                rows = self._where_solved[rod] + np.arange(n)
                stacks.setdefault((n, len(moving)), []).append((rod, rows, self._offset[part.name] + moving, coupling))
        self._couplings = [([s[0] for s in stack], np.array([s[1] for s in stack])[:, :, None],
                            np.array([s[2] for s in stack])[:, None, :], np.array([s[3] for s in stack]))
                           for stack in stacks.values()]

    def solve(self, t, y, fy, r, z, gamma, delta, lr):
        """z = P^-1 r with the last factors."""
        self._solve_blocks(r, z)
        if self.rod_joints.sides:
            self.rod_joints.correct(z)
        self.solves += 1

    def _solve_blocks(self, r, z):
        """z = P^-1 r without the rod-rod joints' coupling: the rods', the bodies' blocks and S."""
        self.rod_blocks.solve(r, z)
        for part in self.bodies:
            if part not in self.coupled:
                z[part.slice] = self._inverse[part.name] @ r[part.slice]
        if self.coupled:
            z_b = self._schur @ (r[self._body_rows] - self._n_br @ z[self._reads])
            z[self._body_rows] = z_b
            z[self._solved_rows] -= self._all_solved @ z_b
