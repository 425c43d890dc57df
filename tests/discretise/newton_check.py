"""A system's Newton matrix I - gamma J against its preconditioner, for the
preconditioner tests (test_assembly, test_body_joints, test_rod_joint_coupling):
J by central differences at the initial state perturbed by 1e-2 of each
entry's scale; errors in units of those scales."""

import numpy as np

from rodmol._differences import central_columns
from rodmol.discretise.system_preconditioner import SystemPreconditioner


class NewtonCheck:
    def __init__(self, assembly, seed=5):
        self.assembly, self.scale = assembly, assembly.atol_scale()
        perturbation = np.random.default_rng(seed).standard_normal(assembly.size)
        self.y = assembly.undeformed_state() + 1e-2 * perturbation * self.scale
        self.fy = assembly(0.0, self.y).copy()
        self.jac = central_columns(lambda z: assembly(0.0, z).copy(), self.y, range(assembly.size),
                                   1e-7 * self.scale)

    def preconditioner(self, gamma):
        """A SystemPreconditioner set up at the state for ``gamma``."""
        precond = SystemPreconditioner(self.assembly, self.scale)
        precond.setup(0.0, self.y, self.fy, False, [0], gamma)
        return precond

    def newton(self, gamma):
        return np.eye(self.assembly.size) - gamma * self.jac

    def solve(self, precond, r, gamma):
        """The preconditioner's solve of ``r``."""
        z = np.empty_like(r)
        precond.solve(0.0, self.y, self.fy, r, z, gamma, 0.0, 1)
        return z

    def apart(self, precond, r, gamma):
        """The solve of ``r`` with every part on its own: each rod's exact block, each body's own block."""
        z = np.empty_like(r)
        for name, rod in precond.rods.items():
            z[self.assembly.parts[name]] = rod.apply(r[self.assembly.parts[name]])
        for part in self.assembly.bodies.values():
            z[part.slice] = np.linalg.solve(np.eye(part.layout.size) - gamma * precond._jac[part.name], r[part.slice])
        return z

    def error(self, z, v):
        return float(np.abs((z - v) / self.scale).max())
