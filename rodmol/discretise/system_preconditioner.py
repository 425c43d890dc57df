"""A block-diagonal preconditioner of CVODE's Newton matrix for a system of
rods and rigid bodies (:class:`rodmol.discretise.assembly.Assembly`).

Each rod gets its own exact block preconditioner
(:class:`rodmol.discretise.preconditioner.BlockPreconditioner`), its base
velocities held at the state's; each body its block (I - gamma J_bb),
inverted directly, J_bb by differences in the body's own entries: of the
full right-hand side in its velocities (they move the rods' bases), of its
own rates in its rotation and, if it has penalty joints (whose held points
it moves), its position; no rate of a body without them reads its
position. The joints' coupling blocks are left out: GMRES's products J v
are differences of the full right-hand side, so it sees them, only
converging in more iterations (many more for penalty joints: see
:mod:`rodmol.solve.system_cvode`).
"""

import numpy as np

#: Relative step of the body blocks' differences, times each entry's scale.
BODY_STEP = 1e-7


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
                jac, steps = self._jac[part.name], self._steps[part.name]
                for j, index in enumerate(range(part.slice.start, part.slice.stop)):
                    field = self._field_of[part.name][j]
                    if field == "x" and not part.joints:  # no rate reads its position
                        continue
                    z[index] = y[index] + steps[j]
                    if field in ("x", "Q"):  # only the body's own rates (of the rods': off the block) read its pose
                        assembly.body_rates(part, t, z, self._out)
                    else:  # its velocities move the rods' bases
                        assembly(t, z, self._out)
                    jac[:, j] = (self._out[part.slice] - fy[part.slice]) / steps[j]
                    z[index] = y[index]
            assembly(t, y, self._out)  # leave the rods as at y
            self.jac_evals += 1
            jnew[0] = 1
        for prec in self.rods.values():
            prec.factor(gamma)
        for part in self.bodies:
            self._inverse[part.name] = np.linalg.inv(np.eye(part.layout.size) - gamma * self._jac[part.name])
        self.setups += 1

    def solve(self, t, y, fy, r, z, gamma, delta, lr):
        """z = P^-1 r with the last factors."""
        parts = self.assembly.parts
        for name, prec in self.rods.items():
            sl = parts[name]
            prec.solve(t, y[sl], fy[sl], r[sl], z[sl], gamma, delta, lr)
        for part in self.bodies:
            z[part.slice] = self._inverse[part.name] @ r[part.slice]
        self.solves += 1
