"""One rod's system (SemiDiscrete) and a system of rods and bodies (Assembly) both satisfy the
written protocol of a discretised system (rodmol.discretise.protocol.Discretised), member by
member, each called on a small model and checked for what it promises."""

import numpy as np
import pytest

import rodmol
from rodmol.discretise.assembly import Assembly
from rodmol.discretise.protocol import JACOBIANS, LINEAR_SOLVERS, Discretised
from rodmol.discretise.system import SemiDiscrete

MATERIAL = rodmol.Material(E=1e5, nu=0.5, mu=300.0, rho=1080.0)
RAMP = [(0.0, 0.0), (0.1, 0.2)]  # N: a tension with a knot at 0.1 s


def _arm(tension=RAMP, length=0.2, **options):
    """A rod of ``length`` [m], N = 4, one cable anchored at the tip."""
    return rodmol.Model(rodmol.Rod(length, radius=0.01, material=MATERIAL), 4,
                        cables=[rodmol.Cable((0.005, 0.0), length, tension=tension)], **options)


def _rod():
    return SemiDiscrete(_arm())


def _system():
    """The arm on a free head, a shorter arm clamped to the world beside it."""
    head = rodmol.RigidBody(0.05, (2e-5, 3e-5, 4e-5), volume=2e-5, drag=(1, 2, 3, 0.1, 0.2, 0.3))
    short = _arm(0.1, 0.1, base=rodmol.BaseMotion(position=(0.0, 0.3, 0.0)))
    return Assembly(rodmol.System({"arm": _arm(), "short": short}, {"head": head},
                                  [rodmol.Joint(("head", (0.0, 0.0, 0.0)), ("arm", "base"))],
                                  medium="water", gravity=(0.0, 0.0, -9.81)))


BOTH = pytest.mark.parametrize("make", [_rod, _system], ids=["rod", "system"])


def _moved(system):
    """A state near rest, every entry moved by a hundredth of its scale (quaternions kept unit)."""
    noise = np.random.default_rng(5).standard_normal(system.size)
    y = system.undeformed_state() + 1e-2 * noise * system.atol_scale()
    system.project_quaternions(y)
    return y


def _differences(system, t, y):
    """df/dy by forward differences of the rates, column by column."""
    f0 = system(t, y).copy()
    out = np.empty((system.size, system.size))
    for j in range(system.size):
        z = y.copy()
        h = 1e-7 * system.atol_scale()[j]
        z[j] += h
        out[:, j] = (system(t, z) - f0) / h
    return out


@BOTH
def test_both_kinds_are_discretised_systems(make):
    system = make()
    assert isinstance(system, Discretised)
    assert system.scheme.name == "centred" and isinstance(system.inputs_vary, bool)
    assert isinstance(system.lightly_damped, bool)


@BOTH
def test_rates_in_place_and_returned_agree_and_vanish_at_rest_without_loads(make):
    system = make()
    y = _moved(system)
    out = np.full(system.size, np.nan)
    assert system(0.05, y, out) is out
    np.testing.assert_array_equal(out, system(0.05, y))
    # Nothing but the moved state drives it: at rest, unloaded, in no medium, nothing moves.
    free = SemiDiscrete(_arm(0.0).replace(medium="air", gravity=(0.0, 0.0, 0.0)))
    assert np.abs(free(0.0, free.undeformed_state())).max() < 1e-12


@BOTH
def test_scales_names_and_quaternion_projection(make):
    system = make()
    assert system.atol_scale().shape == (system.size,) and np.all(system.atol_scale() > 0)
    y = _moved(system)
    names = [system.entry_name(i) for i in range(system.size)]
    quaternions = [i for i, name in enumerate(names) if "Q[" in name or "(Q)" in name]
    assert len(quaternions) == 4 * (5 if isinstance(system, SemiDiscrete) else 11)  # nodes 0-4, a body
    grown = y.copy()
    grown[quaternions] *= 2.0
    system.project_quaternions(grown)
    np.testing.assert_allclose(grown, y, rtol=1e-14, atol=1e-15)
    last = system.entry_name(system.size - 1)
    assert ("body 'head'" in last) if isinstance(system, Assembly) else ("element 3" in last)
    with pytest.raises(IndexError):
        system.entry_name(system.size)


@BOTH
def test_knots_and_the_bending_period(make):
    system = make()
    np.testing.assert_array_equal(system.knot_times(), [0.0, 0.1])
    rod_period = SemiDiscrete(_arm()).bending_period()
    if isinstance(system, Assembly):  # the shorter rod's, a quarter of the arm's (L^2)
        assert system.bending_period() == pytest.approx(rod_period / 4)
    else:
        assert system.bending_period() == rod_period


@BOTH
def test_linear_solvers_offered_with_their_jacobians(make):
    system = make()
    offered = system.linear_solvers()
    assert set(offered) <= set(LINEAR_SOLVERS) and set(offered.values()) <= set(JACOBIANS)
    assert "gmres" in offered and "sparse" in offered
    assert ("band" in offered) != isinstance(system, Assembly)  # a body's rows are no band


@BOTH
def test_pattern_bands_and_compiled_jacobian_hold_the_differences(make):
    system = make()
    y = _moved(system)
    jac = _differences(system, 0.05, y)
    pattern = system.pattern()
    pattern = np.asarray(pattern.toarray() if hasattr(pattern, "toarray") else pattern)
    assert not np.any((np.abs(jac) > 0) & ~pattern)
    lower, upper = system.bandwidths()
    rows, cols = np.nonzero(pattern)
    assert np.all(rows - cols <= lower) and np.all(cols - rows <= upper)
    compiled = system.jacobian(system.atol_scale(), "sparse").dense(0.05, y)
    np.testing.assert_allclose(compiled, jac, atol=1e-4 * np.abs(jac).max())


@BOTH
def test_preconditioner_inverts_the_newton_matrix(make):
    system = make()
    y, gamma = _moved(system), 1e-3
    fy = system(0.05, y).copy()
    newton = np.eye(system.size) - gamma * _differences(system, 0.05, y)
    x = np.random.default_rng(7).standard_normal(system.size) * system.atol_scale()
    precond = system.preconditioner(system.atol_scale())
    precond.setup(0.05, y, fy, False, np.zeros(1, dtype=int), gamma)
    z = np.zeros(system.size)
    precond.solve(0.05, y, fy, newton @ x, z, gamma, 0.0, 1)
    assert precond.setups == 1 and precond.solves == 1
    assert np.max(np.abs(z - x) / system.atol_scale()) < 1e-3 * np.max(np.abs(x) / system.atol_scale())


@BOTH
def test_state_and_step_problems_name_where(make):
    system = make()
    y = system.undeformed_state()
    assert system.state_problem(0.0, y) is None and system.step_problem(0.0, y) is None
    y[2] = np.nan
    problem = system.state_problem(0.5, y)
    assert "non-finite at t = 0.5 s" in problem and "u[2]" in problem
    assert system.step_problem(0.5, y) == problem
    if isinstance(system, Assembly):
        assert problem.startswith("rod 'arm': ")
        y = system.undeformed_state()
        y[system.parts["head"].stop - 1] = np.inf
        assert "body 'head' became non-finite" in system.state_problem(0.5, y)


def test_the_tip_crushed_is_a_step_problem_only():
    """The cables anchored at the tip pull through a section no state entry shows: a run stops
    there, a user's state is not refused for it."""
    rod = SemiDiscrete(_arm(1e4))  # 10 kN on the 1 cm tip: EA = 31 N
    y = rod.undeformed_state()
    assert rod.state_problem(0.0, y) is None
    assert "the tip section is crushed at t = 0 s" in rod.step_problem(0.0, y)
    system = _system()
    system.rods["arm"] = rod
    crushed = system.step_problem(0.0, system.undeformed_state())
    assert crushed.startswith("rod 'arm': the tip section is crushed")


@BOTH
def test_a_stall_is_described_by_the_most_compressed_rod(make):
    system = make()
    y = system.undeformed_state()
    rod = system if isinstance(system, SemiDiscrete) else system.rods["short"]
    part = y if rod is system else y[system.parts["short"]]
    rod.layout.field(part, "q")[2, 0] = 0.5
    rod.layout.field(part, "k")[1, 1] = 3.0
    described = system.describe_stall(y)
    assert f"element 2 (q1 = 0.5), largest turn {3.0 * rod.model.ds:.3g} rad over element 1" in described
    assert described.startswith("In rod 'short': ") == (rod is not system)


def test_a_systems_step_check_finds_what_its_state_check_finds():
    """The per-step check scans every rod and the bodies in one compiled call: it names the
    same rod, element and body as the state check, rod by rod."""
    system = _system()
    for part, entry in (("arm", 3), ("short", 30), ("head", 5)):
        y = system.undeformed_state()
        y[system.parts[part].start + entry] = np.nan
        assert system.step_problem(0.2, y) == system.state_problem(0.2, y)
    y = system.undeformed_state()
    system.rods["short"].layout.field(y[system.parts["short"]], "q")[1, 0] = -0.5
    assert system.step_problem(0.2, y).startswith("rod 'short': element 1 inverted at t = 0.2 s")
