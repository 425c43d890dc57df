"""The static equilibrium of systems with free bodies
(rodmol.solve.system_equilibrium): a payload hanging on a rod from the world
against the extensible bar's stretch, a tilted one started at rest, and the
refusal of a body that nothing holds; the sparse Jacobian against the
dense one. The parallel robot's equilibrium is
tested against its shooting solution in tests/test_system_joints.py."""

import numpy as np
import pytest

import rodmol
from rodmol.discretise.assembly import Assembly
from rodmol.solve.rest_equations import continuation
from rodmol.solve.system_equilibrium import CoupledDifferences, FreeRestEquations

ROD_L, ROD_R, ROD_E, ROD_RHO, PAYLOAD_M, G = 0.5, 0.01, 1e6, 1000.0, 0.5, 9.81
UP = ((0.0, -1.0, 0.0), (1.0, 0.0, 0.0), (0.0, 0.0, 1.0))  # the rod's x axis along global y


def _hanging(n, offset=0.0):
    """A payload clamped at the base of a vertical rod whose tip is clamped to
    the world ``ROD_L`` above it; ``offset`` [m] moves its centre of mass sideways (x)."""
    material = rodmol.Material(E=ROD_E, nu=0.5, mu=0.0, rho=ROD_RHO)
    rod = rodmol.Model(rodmol.Rod(ROD_L, radius=ROD_R, material=material), n)
    payload = rodmol.RigidBody(PAYLOAD_M, (1e-4, 1e-4, 1e-4), centre_of_mass=(offset, 0.0, 0.0))
    joints = [rodmol.Joint(("payload", (0.0, 0.0, 0.0), UP), ("rod", "base")),
              rodmol.Joint("world", ("rod", "tip"), kind="clamp")]
    return rodmol.System({"rod": rod}, {"payload": payload}, joints, gravity=(0.0, -G, 0.0))


def _pose(system, y):
    part = Assembly(system).bodies["payload"]
    return y[part.fields["x"]], y[part.fields["Q"]]


def test_hanging_payload_sinks_by_the_stretch_of_the_bar():
    # The bar's axial force at s is the weight below s: N = M g + rho A g s, so the payload sinks
    # by (M g L + rho A g L^2 / 2) / EA, exactly linear in the strains, plus the gap the tip's penalty
    # joint opens (its compliance, O(ds): 1.1e-3 of the stretch at N = 10, halving with ds).
    system = _hanging(10)
    rest = rodmol.equilibrium(system)
    position, quat = _pose(system, rest)
    assembly = Assembly(system)
    gap = assembly.rods["rod"].layout.field(rest[assembly.parts["rod"]], "u")[-1] - (0.0, ROD_L, 0.0)
    assert 0.0 < -gap[1] < 2e-3 * ROD_L / 10
    ea, weight = ROD_E * np.pi * ROD_R**2, ROD_RHO * np.pi * ROD_R**2 * G
    stretch = (PAYLOAD_M * G * ROD_L + weight * ROD_L**2 / 2) / ea
    assert stretch > 0.01 * ROD_L
    np.testing.assert_allclose(position - gap, (0.0, -stretch, 0.0), atol=1e-6 * stretch)
    np.testing.assert_allclose(np.abs(quat), (1.0, 0.0, 0.0, 0.0), atol=1e-9)


def test_tilted_payload_started_at_its_equilibrium_stays_put():
    # A centre of mass off the axis bends the rod and turns the payload. Its sway is barely damped
    # (from the straight rod it swings by 2e-3 m for seconds), so an error e in the rest pose would
    # show as a swing of amplitude e: started at the equilibrium it moves by 1e-12 m (measured).
    system = _hanging(8, offset=0.002)
    rest = rodmol.equilibrium(system)
    position, quat = _pose(system, rest)
    assert abs(quat[3]) > 1e-2 and position[0] < -1e-3  # turned about z, moved sideways
    still = rodmol.simulate(system, 0.5, initial=rest, output_dt=0.1)
    assert still.success
    np.testing.assert_allclose(still["payload"].position, np.tile(position, (len(still.t), 1)), atol=1e-9)
    np.testing.assert_allclose(still["rod"].tip[-1], rodmol.simulate(system, 0.1, initial="equilibrium",
                                                                      output_dt=0.1)["rod"].tip[0], atol=1e-9)


def test_free_body_held_by_nothing_has_no_equilibrium():
    rod = rodmol.Model(rodmol.Rod(ROD_L, radius=ROD_R, material=rodmol.Material(E=ROD_E, nu=0.5, rho=ROD_RHO)), 4)
    loose = rodmol.System({"rod": rod}, {"payload": rodmol.RigidBody(PAYLOAD_M, (1e-4, 1e-4, 1e-4))},
                          gravity=(0.0, -G, 0.0))
    with pytest.raises(rodmol.EquilibriumError, match="free body 'payload' is held by nothing"):
        rodmol.equilibrium(loose)


def test_sparse_jacobian_equals_the_dense_one_and_finds_the_same_rest():
    # Two rods hang a tilted payload (their bases clamped to it, their tips to the world): the
    # sparse Jacobian holds every entry of the dense one, bitwise (the same differences, placed
    # apart), and the continuation through SuperLU ends where the dense LU's does.
    material = rodmol.Material(E=ROD_E, nu=0.5, mu=0.0, rho=ROD_RHO)
    rod = rodmol.Model(rodmol.Rod(ROD_L, radius=ROD_R, material=material), 6)
    payload = rodmol.RigidBody(PAYLOAD_M, (1e-4, 1e-4, 1e-4), centre_of_mass=(0.003, 0.0, 0.001))
    joints = [rodmol.Joint(("payload", (0.0, 0.0, z), UP), (name, "base")) for name, z in (("a", -0.02), ("b", 0.02))]
    joints += [rodmol.Joint("world", (name, "tip")) for name in ("a", "b")]
    system = rodmol.System({"a": rod, "b": rod}, {"payload": payload}, joints, gravity=(0.0, -G, 0.0))
    equations = FreeRestEquations(Assembly(system), 0.0)
    z = equations.unknowns() + 1e-3 * np.random.default_rng(4).standard_normal(equations.size)
    f = equations.residual(z)
    sparse, dense = CoupledDifferences(equations), CoupledDifferences(equations, dense=True)
    matrix = sparse(equations.residual, z, f)
    assert matrix.nnz < 0.2 * equations.size**2
    np.testing.assert_array_equal(matrix.toarray(), dense(equations.residual, z, f))
    rests = [continuation(equations.residual, equations.unknowns(), equations.tolerance(1e-10), 40, jacobian, 0.0)
             for jacobian in (sparse, dense)]
    assert np.abs(rests[0][equations.slices["payload"]][3:]).max() > 1e-3  # the payload turned
    np.testing.assert_allclose(rests[0], rests[1], rtol=0.0, atol=1e-10)
