"""A rod's base joined to another rod's node (a branch): the base's segment
body held to the node by a penalty joint. A short arm hangs from the middle
of a beam clamped at both ends, so that by symmetry it hangs straight down
and the beam carries its weight as a point load at midspan; the beam's
equilibrium is then the single rod's under that point force (no systems
code in the reference)."""

import numpy as np
import pytest

import rodmol
from rodmol.errors import ParameterError

LB, RB, LA, RA, E, RHO = 0.2, 0.005, 0.1, 0.003, 1e8, 1000.0
MATERIAL = rodmol.Material(E, 0.5, rho=RHO, mu=1e4)
DOWN = np.array([[0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [-1.0, 0.0, 0.0]])  # the arm's x axis along -z
GRAVITY = (0.0, 0.0, -9.81)
ARM_WEIGHT = RHO * np.pi * RA**2 * LA * 9.81


def beam(n, loads=()):
    return rodmol.Model(rodmol.Rod(LB, RB, MATERIAL), n, gravity=GRAVITY, loads=[rodmol.Hold(LB, "clamp"), *loads])


def branch(kind, n):
    arm = rodmol.Model(rodmol.Rod(LA, RA, MATERIAL), n // 2,
                       base=rodmol.BaseMotion(position=(LB / 2, 0.0, 0.0), rotation=DOWN))
    return rodmol.System({"beam": beam(n), "arm": arm}, gravity=GRAVITY,
                         joints=[rodmol.Joint(("arm", "base"), ("beam", LB / 2), kind=kind)])


@pytest.mark.parametrize("n", [8, 16])
def test_an_arm_clamped_under_a_beam_loads_it_as_its_weight_at_midspan(n):
    system = branch("clamp", n)
    assert system.base_bodies == {"arm": "arm.base"} and system.clamps["arm"][0] == "arm.base"
    rest = rodmol.equilibrium(system)
    run = rodmol.simulate(system, 0.05, initial=rest, output_dt=0.05)
    reference = rodmol.simulate(beam(n, [rodmol.PointForce(LB / 2, (0.0, 0.0, -ARM_WEIGHT))]), 1e-6,
                                initial="equilibrium", output_dt=1e-6)
    sag, expected = run["beam"].positions[0, n // 2, 2], reference.positions[0, n // 2, 2]
    # Measured 2.2e-9 (N = 8) and 5.0e-10 (N = 16) of the sag: the joint's compliance. Without the arm's
    # weight the sag is 4% smaller.
    assert sag == pytest.approx(expected, rel=1e-7)
    assert abs(run["arm"].tip[0, 0] - LB / 2) < 1e-3 * LA  # it hangs straight down (measured 4e-7 m off)
    assert run["arm"].tip[0, 2] == pytest.approx(sag - LA, abs=1e-3 * LA)
    # A rest of the dynamics: the state stays there within the run's tolerances (the joint's
    # compliance moves the base body's angular velocity by about one atol, 1.1e-5 rad/s at N = 16).
    atol = rodmol.default_atol(system, rodmol.SCHEMES["centred"].default_rtol)
    assert run.success and np.max(np.abs(run.states[-1] - run.states[0]) / atol) < 2


def test_a_pinned_branch_rests_where_the_clamped_one_does():
    """By symmetry the clamp holds no moment: a pin there leaves the same rest (the same state layout)."""
    rest = rodmol.equilibrium(branch("clamp", 8))
    run = rodmol.simulate(branch("pin", 8), 0.05, initial=rest, output_dt=0.05)
    assert run.success
    for part in ("beam", "arm"):
        assert np.abs(run[part].positions[-1] - run[part].positions[0]).max() < 1e-6


def test_a_base_joined_to_its_own_rod_or_twice_is_refused():
    arm = rodmol.Model(rodmol.Rod(LA, RA, MATERIAL), 4)
    with pytest.raises(ParameterError, match="its own node"):
        rodmol.System({"a": arm}, joints=[rodmol.Joint(("a", "base"), ("a", "tip"))])
    with pytest.raises(ParameterError, match="already jointed"):
        rodmol.System({"a": arm, "b": arm}, joints=[rodmol.Joint(("a", "base"), ("b", "tip")),
                                                      rodmol.Joint(("a", "base"), "world")])


def _joined_bases_error(n, stiffness=None):
    """Rod a leaves x = 0 along +x, rod b along -x, their bases clamped to each other (two base
    bodies and a body joint) and b's tip clamped by a Hold at x = -L: one cantilever of 2L under
    its weight. The relative error of its free tip's sag against the single rod of both."""
    length, gravity = 0.1, (0.0, 0.0, -9.81)
    a = rodmol.Model(rodmol.Rod(length, RB, MATERIAL), n)
    b = rodmol.Model(rodmol.Rod(length, RB, MATERIAL), n, base=rodmol.BaseMotion(rotation=np.diag([-1.0, -1.0, 1.0])),
                     loads=[rodmol.Hold(length, "clamp", stiffness=stiffness)])
    system = rodmol.System({"a": a, "b": b}, joints=[rodmol.Joint(("a", "base"), ("b", "base"), stiffness=stiffness)],
                           gravity=gravity)
    assert system.base_bodies == {"a": "a.base", "b": "b.base"} and len(system.body_joints) == 1
    run = rodmol.simulate(system, 0.02, initial=rodmol.equilibrium(system), output_dt=0.02)
    single = rodmol.Model(rodmol.Rod(2 * length, RB, MATERIAL), 2 * n,
                          base=rodmol.BaseMotion(position=(-length, 0.0, 0.0)), gravity=gravity)
    reference = rodmol.simulate(single, 1e-6, initial="equilibrium", output_dt=1e-6).tip[0, 2]
    assert run.success and np.abs(run["a"].tip[-1] - run["a"].tip[0]).max() < 1e-6  # at rest
    return abs(run["a"].tip[0, 2] / reference - 1.0)


def test_two_bases_joined_are_the_single_rod_of_both_up_to_the_joints_compliance():
    """With the default penalties (stiffness 100 E A L / ds^2, turning 100 E I L / ds^2: their
    compliance is ds / (100 L) of an element's, O(ds^2) against the rod's) the tip converges to
    the single rod's at second order (measured 1.9e-3, 4.7e-4, 1.2e-4 of the sag at N = 4, 8, 16
    per rod; at 100 E A / ds, first order: 7.5e-3, 3.7e-3, 1.9e-3); with stiff joints the
    difference is 1.8e-6 at every N: the discretisation across the joints is the single rod's."""
    errors = [_joined_bases_error(n) for n in (4, 8, 16)]
    assert errors[1] < 1e-3 and np.log2(errors[0] / errors[1]) > 1.8 and np.log2(errors[1] / errors[2]) > 1.8
    assert _joined_bases_error(8, stiffness=1e11) < 1e-5
