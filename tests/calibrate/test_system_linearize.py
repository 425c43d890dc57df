"""Linearisation of a System: A and B against differences of the Assembly's rates
(and of systems with other inputs), the named outputs, the step response against
simulate, and the refusals."""

from pathlib import Path

import numpy as np
import pytest
from example_modules import load_example

import rodmol
from rodmol.discretise.assembly import Assembly

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
parallel_robot = load_example("parallel_robot.py")

MATERIAL = rodmol.Material(E=1e5, nu=0.5, mu=300.0, rho=1080.0)
TURN = np.diag([-1.0, -1.0, 1.0])  # the left arm leaves the head along -x
HEAD = dict(mass=0.3, inertia=(2e-4, 2e-4, 2e-4), volume=2.5e-4, added_mass=(0.1, 0.1, 0.1, 0.0, 0.0, 0.0),
            drag=(0.5, 0.5, 0.5, 1e-3, 1e-3, 1e-3))


def arms(motion="free", pull=0.3, z=-0.004, force=(0.0, 0.01, 0.0), velocity=(0.0, 0.0, 0.0), n=6):
    """docs/systems.md's two arms on a head in water: the right one pulled by a cable (``pull``
    [N]) and pushed at its tip (``force`` [N], global), the left one by an actuator (``z`` [m]);
    the head free, fixed, or driven at constant velocities (``velocity``: v, or v and w)."""
    rod = rodmol.Rod(0.2, radius=(0.012, 0.006), material=MATERIAL)
    right = rodmol.Model(rod, n, cables=[rodmol.Cable((0.005, 0.0), 0.2, tension=pull, name="pull")],
                         loads=[rodmol.PointForce(0.2, force, name="push")])
    left = rodmol.Model(rod, n, cables=[rodmol.Cable((0.005, 0.0), 0.2, name="motor", displacement=z,
                                                     compliance=5e-3)])
    if motion == "driven":
        v = np.zeros(6)
        v[:len(velocity)] = velocity
        motion = rodmol.BaseMotion(velocity=lambda t: v[:3], angular_velocity=lambda t: v[3:])
    head = rodmol.RigidBody(**HEAD, motion=motion)
    joints = [rodmol.Joint(("head", (0.04, 0.0, 0.0)), ("right", "base")),
              rodmol.Joint(("head", (-0.04, 0.0, 0.0), TURN), ("left", "base"))]
    return rodmol.System({"right": right, "left": left}, {"head": head}, joints, medium="water",
                         gravity=(0.0, 0.0, -9.81))


def moving(system):
    """A state of ``system`` away from rest: its equilibrium (or its straight state if
    its head floats) with the rods' and a free head's velocities set."""
    assembly = Assembly(system)
    y = (assembly.undeformed_state() if system.bodies["head"].free else rodmol.equilibrium(system)).copy()
    rng = np.random.default_rng(1)
    for name, sd in assembly.rods.items():
        rod = y[assembly.parts[name]]
        sd.layout.field(rod, "v")[:] = 0.02 * rng.standard_normal(sd.layout.field(rod, "v").shape)
        sd.layout.field(rod, "w")[:] = 0.3 * rng.standard_normal(sd.layout.field(rod, "w").shape)
        y[assembly.parts[name]] = rod
    head = assembly.bodies["head"]
    if "v" in head.fields:
        y[head.fields["v"]], y[head.fields["w"]] = (0.01, -0.02, 0.005), (0.1, 0.0, -0.2)
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


@pytest.mark.parametrize("case", ["free head, moving", "parallel robot at rest"])
def test_state_jacobian_matches_central_differences_of_the_rates(case):
    """A against every column of the Assembly's rates by central differences at a
    step 10 times the linearisation's: the coloured columns miss no coupling (the
    rods' bases on the free head, the legs' tips held by the platform)."""
    if case == "free head, moving":
        system = arms("free")
        assembly, y = moving(system)
    else:
        system = parallel_robot.robot(6)
        assembly, y = Assembly(system), rodmol.equilibrium(system)
    lin = rodmol.linearize(system, y, t=0.1)
    assert lin.A.shape == (assembly.size, assembly.size)
    reference = central(lambda x: assembly(0.1, x).copy(), y, 1e-5 * np.maximum(np.abs(y), assembly.atol_scale()))
    assert_close(lin.A, reference, 1e-5)


def test_input_columns_match_systems_with_other_inputs():
    """Each B column against systems whose input is moved: the cable's tension, the
    motor's position, the push's components, the driven head's velocities."""
    system = arms("driven")
    assembly, y = moving(system)
    lin = rodmol.linearize(system, y, t=0.1)
    assert lin.inputs == ("right/pull tension [N]", "right/push x [N]", "right/push y [N]", "right/push z [N]",
                          "left/motor tension [N]", "left/motor displacement [m]",
                          "head v x [m/s]", "head v y [m/s]", "head v z [m/s]",
                          "head w x [rad/s]", "head w y [rad/s]", "head w z [rad/s]")

    def column(**changes):
        up, down = (Assembly(arms("driven", **{k: v[i] for k, v in changes.items()}))(0.1, y) for i in (0, 1))
        return up - down

    checks = {0: column(pull=(0.35, 0.25)) / 0.1, 5: column(z=(-0.00399, -0.00401)) / 2e-5}
    for k, e in enumerate(np.eye(3)):
        checks[1 + k] = column(force=(np.array([0.0, 0.01, 0.0]) + 0.1 * e, np.array([0.0, 0.01, 0.0]) - 0.1 * e)) / 0.2
    for k, e in enumerate(np.eye(6)):
        checks[6 + k] = column(velocity=(1e-3 * e, -1e-3 * e)) / 2e-3
    for j, reference in checks.items():
        assert_close(lin.B[:, j], reference, 1e-6)
    # the motor's tension column: the held tension at the actuator's pull
    assert lin.B[:, 4].any() and np.abs(lin.B[:, 5]).max() > 0.0


def test_outputs_are_the_tips_and_the_bodies_positions():
    system = parallel_robot.robot(6)
    assembly, y = Assembly(system), rodmol.equilibrium(system)
    lin = rodmol.linearize(system, y)
    assert lin.inputs == ()
    rng = np.random.default_rng(2)
    dy = 1e-7 * rng.standard_normal(y.size) * assembly.atol_scale()
    for leg in ("leg0", "leg2"):
        tip = lin.output(f"{leg}/tip")
        assert tip.outputs == tuple(f"{leg}/tip {axis} [m]" for axis in "xyz")
        sd, part = assembly.rods[leg], assembly.parts[leg]
        moved = sd.state_view(0.0, (y + dy)[part]).tip - sd.state_view(0.0, y[part]).tip
        assert np.allclose(tip.C @ dy, moved, rtol=1e-5, atol=1e-15)
    platform = lin.output("platform/position")
    assert np.array_equal(platform.C @ dy, dy[assembly.bodies["platform"].fields["x"]])
    with pytest.raises(rodmol.ParameterError, match="'leg0/tip'"):
        lin.output("tip")


@pytest.fixture(scope="module")
def at_rest():
    """The two arms on a fixed head at rest, their linear model."""
    system = arms("fixed")
    y = rodmol.equilibrium(system)
    return system, y, rodmol.linearize(system, y)


def test_a_tension_step_is_simulated_as_the_linear_model_predicts(at_rest):
    """0.01 N more on the right arm's cable from rest: the tip's path over 0.3 s by
    the sampled linear model and by simulate differ by a few percent of the motion."""
    system, y, lin = at_rest
    plant = lin.output("right/tip").discretize(0.03)
    u = 0.01 * np.eye(len(lin.inputs))[0]
    x, predicted = np.zeros(y.size), []
    for _ in range(10):
        x = plant.A @ x + plant.B @ u
        predicted.append(plant.C @ x)
    stepped = arms("fixed", pull=0.31)
    result = rodmol.simulate(stepped, 0.3, initial=y, output_dt=0.03)
    moved = result["right"].tip[1:] - result["right"].tip[0]
    assert np.abs(moved).max() > 1e-4
    assert np.abs(np.array(predicted) - moved).max() < 0.05 * np.abs(moved).max()


def test_reduced_static_gain_is_the_equilibria_s(at_rest):
    """The reduced model's static gain of the right tip to its cable is the
    equilibria's (to the time discretisation's drift of the orientations, O(ds^2))."""
    system, y, lin = at_rest
    small = lin.reduced(output="right/tip", order=6)
    assert small.A.shape[0] in (6, 7)
    tips = [Assembly(s).rods["right"].state_view(0.0, rodmol.equilibrium(s)[Assembly(s).parts["right"]]).tip
            for s in (arms("fixed", pull=0.31), arms("fixed", pull=0.29))]
    reference = (tips[0] - tips[1]) / 0.02
    assert np.linalg.norm(small.static_gain()[:, 0] - reference) < 0.01 * np.linalg.norm(reference)
    assert small.discretize(0.01).dt == 0.01


@pytest.mark.parametrize("state, named", [
    ("rest", "unknown `state`"),
    (np.zeros(3), "`state`"),
    ("nan", "`state`"),
    ("zero quaternion", "`state`"),
])
def test_bad_states_are_refused_before_any_work(at_rest, state, named):
    system, y, _ = at_rest
    if isinstance(state, str) and state == "nan":
        state = y.copy()
        state[5] = np.nan
    elif isinstance(state, str) and state == "zero quaternion":
        state = y.copy()
        state[Assembly(system).bodies["head"].fields["Q"]] = 0.0
    with pytest.raises(rodmol.ParameterError, match=named):
        rodmol.linearize(system, state)
