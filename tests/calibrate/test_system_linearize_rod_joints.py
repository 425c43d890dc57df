"""Linearisation of Systems whose rods are joined to each other (rodmol/system_joints.py):
two tips joined (clamped or pinned), a tip on another rod's node, two bases joined and
a base on another rod's tip (a branch). A, B and the drift against central differences of the Assembly's
rates and against Systems whose inputs are moved."""

import numpy as np
import pytest

import rodmol
from rodmol.discretise.assembly import Assembly

MATERIAL = rodmol.Material(E=1e5, nu=0.5, mu=300.0, rho=1080.0)
L = 0.2
N = 6
BACK = np.diag([-1.0, -1.0, 1.0])  # a rod leaving its base along -x
UP = np.array([[0.0, 0.0, -1.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]])  # along +z
PLACES = {  # rod b's base (position, rotation) and the joint of each case
    "tips": ((2 * L, 0.0, 0.0), BACK, (("a", "tip"), ("b", "tip"))),
    "tip on a node": ((L, 0.0, -2 * L / 3), UP, (("a", "tip"), ("b", 2 * L / 3))),
    "bases": ((0.0, 0.0, 0.0), BACK, (("a", "base"), ("b", "base"))),
    "branch": ((L, 0.0, 0.0), np.eye(3), (("b", "base"), ("a", "tip"))),
    "tips pinned": ((2 * L, 0.0, 0.0), BACK, (("a", "tip"), ("b", "tip"), "pin")),
}


def joined(case, pull=(0.05, 0.03), z=-0.002, force=(0.0, 0.002, 0.0)):
    """Rods a and b (6 elements each) joined as ``case`` says under gravity: a pulled by
    a cable (``pull[0]`` [N]) and pushed at its middle (``force`` [N], global), b pulled
    by a cable (``pull[1]``) and by an actuator at ``z`` [m]; the bases not joined are
    clamped to the world."""
    position, rotation, (end_a, end_b, *kind) = PLACES[case]
    rod = rodmol.Rod(L, radius=(0.012, 0.008), material=MATERIAL)
    a = rodmol.Model(rod, N, cables=[rodmol.Cable((0.005, 0.0), L, tension=pull[0], name="pull")],
                     loads=[rodmol.PointForce(L / 2, force, name="push")])
    b = rodmol.Model(rod, N, base=rodmol.BaseMotion(position=position, rotation=rotation),
                     cables=[rodmol.Cable((0.005, 0.0), L, tension=pull[1], name="pull"),
                             rodmol.Cable((0.0, 0.005), L, name="motor", displacement=z, compliance=5e-2)])
    return rodmol.System({"a": a, "b": b}, joints=[rodmol.Joint(end_a, end_b, *kind)], gravity=(0.0, 0.0, -9.81))


def moving(system):
    """The Assembly of ``system`` and a state of it away from rest and equilibrium: the
    undeformed state, every entry moved by 1% of its scale (the joints stretched, the rods
    bent and moving: every coupling of the joints is live)."""
    assembly = Assembly(system)
    rng = np.random.default_rng(3)
    y = assembly.undeformed_state() + 1e-2 * rng.standard_normal(assembly.size) * assembly.atol_scale()
    assembly.project_quaternions(y)
    return assembly, y


def central(rates, y, h):
    return np.column_stack([(rates(y + e) - rates(y - e)) / (2 * e[j]) for j, e in enumerate(np.diag(h))])


def assert_close(found, reference, tol):
    """``found`` within ``tol`` of ``reference``, entry by entry relative, on the entries
    above 1e-6 of the largest; the others within tol of the largest."""
    size = np.abs(reference).max()
    big = np.abs(reference) > 1e-6 * size
    assert np.max(np.abs(found - reference)[big] / np.abs(reference[big])) < tol
    assert np.max(np.abs(found - reference)[~big], initial=0.0) < tol * size


CASES = list(PLACES)
T = 0.1


@pytest.fixture(scope="module", params=CASES)
def linearised(request):
    system = joined(request.param)
    assembly, y = moving(system)
    return request.param, system, assembly, y, rodmol.linearize(system, y, t=T)


def test_state_jacobian_matches_central_differences_of_the_rates(linearised):
    """A against every column of the Assembly's rates by central differences at a step
    10 times the linearisation's: the coloured columns miss none of the joint's couplings
    (a rod's node held by the other rod's node, a base body between them)."""
    case, system, assembly, y, lin = linearised
    reference = central(lambda x: assembly(T, x).copy(), y, 1e-5 * np.maximum(np.abs(y), assembly.atol_scale()))
    assert_close(lin.A, reference, 1e-5)
    a, b = assembly.parts["a"], assembly.parts["b"]
    if case in ("tips", "tip on a node", "tips pinned"):  # the two rods read each other's nodes
        assert np.abs(lin.A[a, b]).max() > 1e-3 * np.abs(lin.A).max()


def test_drift_is_the_rates_at_the_operating_point(linearised):
    case, system, assembly, y, lin = linearised
    assert np.array_equal(lin.f0, assembly(T, y))


def test_input_columns_match_systems_with_other_inputs(linearised):
    """Each B column against Systems whose input is moved: each rod's cable tensions, b's
    motor position, a's push's components."""
    case, system, assembly, y, lin = linearised
    assert lin.inputs == ("a/pull tension [N]", "a/push x [N]", "a/push y [N]", "a/push z [N]",
                          "b/pull tension [N]", "b/motor tension [N]", "b/motor displacement [m]")

    def column(**changes):
        up, down = (Assembly(joined(case, **{k: v[i] for k, v in changes.items()}))(T, y) for i in (0, 1))
        return up - down

    checks = {0: column(pull=((0.06, 0.03), (0.04, 0.03))) / 0.02,
              4: column(pull=((0.05, 0.04), (0.05, 0.02))) / 0.02,
              6: column(z=(-0.00199, -0.00201)) / 2e-5}
    for k, e in enumerate(np.eye(3)):
        push = np.array([0.0, 0.002, 0.0])
        checks[1 + k] = column(force=(push + 0.01 * e, push - 0.01 * e)) / 0.02
    for j, reference in checks.items():
        assert_close(lin.B[:, j], reference, 1e-6)
    assert lin.B[assembly.parts["a"], 0].any() and not lin.B[assembly.parts["b"], 0].any()


def test_tip_outputs_follow_the_tips(linearised):
    """Each rod's tip row against the tip of a slightly moved state."""
    case, system, assembly, y, lin = linearised
    rng = np.random.default_rng(4)
    dy = 1e-7 * rng.standard_normal(y.size) * assembly.atol_scale()
    for rod in ("a", "b"):
        sd, part = assembly.rods[rod], assembly.parts[rod]
        moved = sd.state_view(T, (y + dy)[part]).tip - sd.state_view(T, y[part]).tip
        assert np.allclose(lin.output(f"{rod}/tip").C @ dy, moved, rtol=1e-4, atol=1e-14)


@pytest.mark.parametrize("case", ["tips", "branch"])
def test_static_gain_is_the_equilibria_s(case):
    """About the joined rods' equilibrium, the gain of a's tip to b's cable is the
    equilibria's (the load crosses the joint). The two differ by the discretisation
    (the dynamic rates' zero against the static rest equations): measured 0.3% (tips)
    and 0.8% (branch; 0.5% and 0.2% at N = 12 and 24)."""
    system = joined(case)
    y = rodmol.equilibrium(system)
    gain = rodmol.linearize(system, y).reduced(output="a/tip", order=12).static_gain()[:, 4]
    tips = []
    for pull in ((0.05, 0.035), (0.05, 0.025)):
        moved = joined(case, pull=pull)
        assembly = Assembly(moved)
        tips.append(assembly.rods["a"].state_view(0.0, rodmol.equilibrium(moved)[assembly.parts["a"]]).tip)
    reference = (tips[0] - tips[1]) / 0.01
    assert np.linalg.norm(reference) > 1e-3
    assert np.linalg.norm(gain - reference) < 0.015 * np.linalg.norm(reference)
