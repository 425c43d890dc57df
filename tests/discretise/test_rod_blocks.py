"""A system's rods' block preconditioners solved together (rodmol.discretise.rod_blocks)."""

import numpy as np

import rodmol
from rodmol.discretise.assembly import Assembly
from rodmol.discretise.system_preconditioner import SystemPreconditioner


def _system():
    """Three arms of two sizes (N = 4, 4, 6) on a free head."""
    mat = rodmol.Material(E=1e5, nu=0.5, mu=300.0, rho=1080.0)
    rod = rodmol.Rod(0.2, radius=0.01, material=mat)
    arm = rodmol.Model(rod, 4, cables=[rodmol.Cable((0.005, 0.0), 0.2, tension=0.1)])
    head = rodmol.RigidBody(0.05, (2e-5, 3e-5, 4e-5), volume=2e-5, drag=(1, 2, 3, 0.1, 0.2, 0.3))
    joints = [rodmol.Joint(("head", (0.02 * np.cos(a), 0.02 * np.sin(a), 0.0),
                            [[np.cos(a), -np.sin(a), 0.0], [np.sin(a), np.cos(a), 0.0], [0.0, 0.0, 1.0]]),
                           (name, "base")) for a, name in zip((0.0, 2.0, 4.0), "abc")]
    rods = {"a": arm, "b": arm, "c": arm.replace(n_elements=6)}
    return rodmol.System(rods, {"head": head}, joints, medium="water", gravity=(0.0, 0.0, -9.81))


def test_stacked_solves_equal_each_rods_own():
    assembly = Assembly(_system())
    scale = assembly.atol_scale()
    pre = SystemPreconditioner(assembly, scale)
    rng = np.random.default_rng(4)
    y = assembly.undeformed_state() + 1e-2 * rng.standard_normal(assembly.size) * scale
    fy = assembly(0.0, y)
    pre.setup(0.0, y, fy, False, [0], 3e-4)
    r = rng.standard_normal(assembly.size)
    together = np.full(assembly.size, np.nan)
    pre.rod_blocks.solve(r, together)
    for name, prec in pre.rods.items():
        sl = assembly.parts[name]
        alone = np.empty(sl.stop - sl.start)
        prec.solve(0.0, y[sl], fy[sl], r[sl].copy(), alone, 3e-4, 0.0, 1)
        assert np.array_equal(together[sl], alone), name
