"""The preconditioner's blocks of penalty joints between two rods
(rodmol.discretise.rod_joint_coupling) on top of the rods', the bodies' and
their Schur complement (rodmol.discretise.system_preconditioner)."""

import numpy as np
from newton_check import NewtonCheck

import rodmol
from rodmol.discretise.assembly import Assembly


def _loop():
    # Two rods clamped to a free bar at their bases and to each other at their tips (a loop with no
    # world in it, the bar in the Schur complement), and a third from the world pinned to a's middle:
    # four sides of rod-rod joints, one rod (a) in two of them.
    mat = rodmol.Material(E=1e5, nu=0.5, mu=300.0, rho=1080.0)
    rod = rodmol.Rod(0.2, radius=0.01, material=mat)
    up = np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])
    post = rodmol.Model(rodmol.Rod(0.1, radius=0.01, material=mat), 2,
                        base=rodmol.BaseMotion(position=(0.1, -0.1, 0.0), rotation=up))
    bar = rodmol.RigidBody(0.02, (1e-5, 1e-5, 1e-5), centre_of_mass=(0.2, 0.01, 0.0))
    joints = [rodmol.Joint(("bar", (0.0, 0.0, 0.0)), ("a", "base")),
              rodmol.Joint(("bar", (0.4, 0.0, 0.0), np.diag([-1.0, -1.0, 1.0])), ("b", "base")),
              rodmol.Joint(("a", "tip"), ("b", "tip")),
              rodmol.Joint(("a", 0.1), ("c", "tip"), kind="pin")]
    rods = {"a": rodmol.Model(rod, 4), "b": rodmol.Model(rod, 4), "c": post}
    return Assembly(rodmol.System(rods, {"bar": bar}, joints, gravity=(0.0, -9.81, 0.0)))


def test_preconditioner_inverts_the_newton_matrix_of_rods_joined_to_each_other():
    # With the rod-rod joints' blocks kept (their Schur complement over the joints' rows) every
    # coupling is in the preconditioner: it is I - gamma J itself, to the error of its forward
    # differences (measured 8e-7 and 6e-6 of each entry's scale); without those blocks, as GMRES had it
    # before, it is off by more than 1000 times the entries' scale.
    check = NewtonCheck(_loop())
    assembly = check.assembly
    for gamma, bound in ((1e-4, 1e-5), (1e-3, 1e-4)):
        precond = check.preconditioner(gamma)
        assert len(precond.rod_joints.sides) == 4 and precond.coupled == [assembly.bodies["bar"]]
        np.testing.assert_array_equal(assembly(0.0, check.y), check.fy)  # the differences left every rod as at y
        v = np.random.default_rng(6).standard_normal(assembly.size) * check.scale
        r = check.newton(gamma) @ v
        assert check.error(check.solve(precond, r, gamma), v) < bound
        apart = np.empty_like(v)
        precond._solve_blocks(r, apart)
        assert check.error(apart, v) > 1e3
