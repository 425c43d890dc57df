"""The block preconditioners of a system's rods
(:class:`rodmol.discretise.preconditioner.BlockPreconditioner`), solved together.

A system's GMRES applies every rod's exact block solve at each of its
preconditioner solves; called one by one from Python, the eight rods of the
octopus at N = 6 cost 20 us a solve, most of it the calls. Here the rods of
one size keep their factors stacked (each rod's preconditioner factors into
its views) and are solved in one compiled call per size.
"""

import numpy as np

from .jacobian import read_only
from .layout import HEADER
from .physics import jit
from .preconditioner import N_FACTORS, block_solve


@jit
def _solve_stacked(gamma, heads, facs, starts, size, r, z, y_x, y_p, h):
    """z = (I - gamma J)^-1 r on the rods whose entries start at ``starts`` (each ``size`` long)."""
    for i in range(starts.shape[0]):
        a = starts[i]
        block_solve(gamma, heads[i], facs[i], r[a:a + size], z[a:a + size], y_x, y_p, h)


@jit
def _solve_rows_stacked(gamma, heads, facs, which, rhs, out, y_x, y_p, h):
    """out[i, j] = (I - gamma J)^-1 rhs[i, j] with the stacked rod ``which[i]``'s factors."""
    for i in range(which.shape[0]):
        for j in range(rhs.shape[1]):
            block_solve(gamma, heads[which[i]], facs[which[i]], rhs[i, j], out[i, j], y_x, y_p, h)


class RodBlocks:
    """The rods' preconditioners ``rods`` ({name: BlockPreconditioner}) of a system whose
    rods' entries are at ``parts`` ({name: slice}), grouped by size."""

    def __init__(self, rods, parts):
        self.rods = rods
        groups = {}
        for name in rods:
            groups.setdefault(parts[name].stop - parts[name].start, []).append(name)
        self._groups, self._where = [], {}  # each rod's (group, place in it)
        for size, names in groups.items():
            self._where.update({name: (len(self._groups), i) for i, name in enumerate(names)})
            n = rods[names[0]].factors[2].shape[0]
            heads, facs = np.zeros((len(names), HEADER, HEADER)), np.zeros((len(names), n, N_FACTORS))
            for i, name in enumerate(names):
                rods[name].factor_into(heads[i], facs[i])
            starts = np.array([parts[name].start for name in names], dtype=np.int64)
            self._groups.append((names[0], heads, facs, starts, size))

    def factor(self, gamma):
        """Factor every rod's I - gamma J (its current Jacobian)."""
        for prec in self.rods.values():
            prec.factor(gamma)

    def solve(self, r, z):
        """z = (I - gamma J)^-1 r on every rod's entries, with the last factors."""
        r = read_only(r)
        for first, heads, facs, starts, size in self._groups:
            gamma, _, _, scratch = self.rods[first].factors
            _solve_stacked(gamma, heads, facs, starts, size, r, z, *scratch)

    def solve_rows(self, names, rhs):
        """(k, m, size) solutions of (I - gamma J) x = rhs[i, j] on rod ``names[i]`` (all of one
        size, ``rhs`` (k, m, size)), with the last factors."""
        group = {self._where[name][0] for name in names}
        if len(group) != 1:
            raise ValueError(f"rods {names} are not all of one size")
        first, heads, facs, _, _ = self._groups[group.pop()]
        which = np.array([self._where[name][1] for name in names], dtype=np.int64)
        gamma, _, _, scratch = self.rods[first].factors
        out = np.empty_like(rhs)
        _solve_rows_stacked(gamma, heads, facs, which, rhs, out, *scratch)
        return out
