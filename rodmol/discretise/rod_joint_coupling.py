"""The coupling of two rods by a penalty joint between their nodes
(:class:`rodmol.discretise.joints.RodJointPart`) in the system's block
preconditioner (:class:`rodmol.discretise.system_preconditioner.SystemPreconditioner`).

Each side of such a joint is rod a's hold held by rod b's node: the velocity
rows of a's node read b's node's u, Q, v, w. The joint couples the two
rods as stiffly as it holds them (its hold's own stiffness is in each rod's
exact block); left out, GMRES's runs drifted off the trajectory. The
coupling is a few small blocks: with D the preconditioner without them (the
rods' exact blocks, the bodies' and their Schur complement) and, per side
s, M_s = -gamma J_s (6 x 13, by differences of rod a's rates in b's node's
entries), the Newton matrix is N = D + U V^T, U the unit columns of the
sides' rows, V^T's rows M_s over the partners' columns. It is inverted
exactly by its Schur complement over the sides' rows (the Woodbury
identity):

    N^-1 = D^-1 - Z K^-1 V^T D^-1,  Z = D^-1 U,  K = I + V^T Z,

K of 6 rows per side, dense; Z is formed at each factorisation from one
solve of D per side's row, so a preconditioner solve costs one solve of D
and two small products.
"""

import numpy as np


class RodJointCoupling:
    """The rod-rod joints' blocks of ``assembly``'s Newton matrix and their
    Schur complement. ``steps`` (size,) are the differences' steps of each
    state entry; ``rows`` the velocity entries of a joint's node within its
    element block (what the joint's force moves)."""

    def __init__(self, assembly, steps, rows):
        self.assembly, self._steps = assembly, steps
        self.sides = list(assembly.rod_joints)
        self._rows = [side.node + rows for side in self.sides]
        self._jac = [np.zeros((len(rows), len(side.partner_fields))) for side in self.sides]
        self._blocks = [np.zeros_like(jac) for jac in self._jac]
        self.rows = np.concatenate(self._rows) if self.sides else np.zeros(0, dtype=int)
        self._solved = np.zeros((len(self.rows), assembly.size))  # Z^T: a row per solve, contiguous
        self._inverse = np.eye(len(self.rows))
        self._out = np.empty(assembly.size)

    def evaluate(self, t, y, fy):
        """J_s of each side: rod a's node rows against b's node entries, by forward differences of
        rod a's rates alone (only its hold reads b's node); its hold and rates left as at y."""
        assembly, out = self.assembly, self._out
        z = np.array(y)
        for side, rows, jac in zip(self.sides, self._rows, self._jac):
            name = side.joint.rod
            rod, sl = assembly.rods[name], assembly.parts[name]
            for c, index in enumerate(side.partner_fields):
                step = self._steps[index]
                z[index] = y[index] + step
                side.wrench(z, side.row, side.value)
                rod(t, z[sl], out[sl])
                jac[:, c] = (out[rows] - fy[rows]) / step
                z[index] = y[index]
            side.wrench(y, side.row, side.value)
            rod(t, y[sl], out[sl])

    def factor(self, gamma, solve):
        """Z = D^-1 U by ``solve(r, z)`` (z = D^-1 r with D's last factors), and K^-1."""
        unit = np.zeros(self.assembly.size)
        for i, row in enumerate(self.rows):
            unit[row] = 1.0
            solve(unit, self._solved[i])
            unit[row] = 0.0
        k = np.eye(len(self.rows))
        for s, (side, jac) in enumerate(zip(self.sides, self._jac)):
            self._blocks[s][:] = -gamma * jac
            sl = self._side(s)
            k[sl] += self._blocks[s] @ self._solved[:, side.partner_fields].T
        self._inverse = np.linalg.inv(k)

    def correct(self, z):
        """z = D^-1 r (in place) becomes N^-1 r."""
        product = np.empty(len(self.rows))
        for s, (side, block) in enumerate(zip(self.sides, self._blocks)):
            product[self._side(s)] = block @ z[side.partner_fields]
        z -= (self._inverse @ product) @ self._solved

    def _side(self, s):
        """Side s's rows within U's columns (and K's rows)."""
        n = len(self._rows[s])
        return slice(n * s, n * (s + 1))
