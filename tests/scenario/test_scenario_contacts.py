"""A system file's [[contact]] tables: rods touching a body (rodmol.Contact)."""

import dataclasses
from pathlib import Path

import numpy as np
import pytest

import rodmol
from rodmol.scenario.file import ScenarioError, load_scenario, parse_scenario

ROOT = Path(__file__).resolve().parents[2]
G, L, RADIUS, N = 9.81, 0.2, 0.01, 10
BALL_R, BALL_M = 0.03, 0.02

#: A ball resting on a beam clamped at its base and held at its tip.
BALL_ON_BEAM = f"""\
[system]
gravity = [0.0, {-G}, 0.0]

[[rod]]
name = "beam"
length = {L}
radius = {RADIUS}
n_elements = {N}

[rod.material]
E = 1e6
nu = 0.5
mu = 5e3
rho = 1000.0

[[body]]
name = "ball"
mass = {BALL_M}
inertia = [{0.4 * BALL_M * BALL_R**2}, {0.4 * BALL_M * BALL_R**2}, {0.4 * BALL_M * BALL_R**2}]
position = [{L / 2 + L / N / 2}, {RADIUS + BALL_R}, 0.0]

[[joint]]
a = ["beam", "tip"]
b = "world"

[[contact]]
body = "ball"
rods = "beam"
type = "sphere_contact"
centre = [0.0, 0.0, 0.0]
radius = {BALL_R}
stiffness = 2e3
damping = 100.0

[solver]
t_end = 0.1
output_dt = 0.05
"""


def ball_on_beam_in_python():
    """BALL_ON_BEAM written in Python."""
    material = rodmol.Material(E=1e6, nu=0.5, mu=5e3, rho=1000.0)
    beam = rodmol.Model(rodmol.Rod(L, radius=RADIUS, material=material), N)
    ball = rodmol.RigidBody(BALL_M, (0.4 * BALL_M * BALL_R**2,) * 3, position=(L / 2 + L / N / 2, RADIUS + BALL_R, 0.0))
    shape = rodmol.SphereContact((0.0, 0.0, 0.0), BALL_R, stiffness=2e3, damping=100.0)
    return rodmol.System({"beam": beam}, {"ball": ball}, [rodmol.Joint(("beam", "tip"), "world")],
                         contacts=[rodmol.Contact("ball", "beam", shape)], medium="air", gravity=(0.0, -G, 0.0))


def same(a, b):
    """True if ``a`` and ``b`` are equal, their arrays and dataclasses compared field by field, exactly."""
    if dataclasses.is_dataclass(a):
        return type(a) is type(b) and all(same(getattr(a, f.name), getattr(b, f.name))
                                          for f in dataclasses.fields(a))
    if isinstance(a, (tuple, list)):
        return type(a) is type(b) and len(a) == len(b) and all(map(same, a, b))
    if isinstance(a, np.ndarray):
        return np.array_equal(a, b)
    return a == b


def test_a_contact_table_builds_the_python_system_and_runs_the_same():
    spec = parse_scenario(BALL_ON_BEAM)
    system, expected = spec.model, ball_on_beam_in_python()
    assert same(system.contacts, expected.contacts) and len(system.contacts) == 1
    assert same(system.rod_contacts, expected.rod_contacts)
    assert same(system.rods["beam"].loads, expected.rods["beam"].loads)
    from_file = spec.simulate()
    from_python = rodmol.simulate(expected, 0.1, output_dt=0.05, initial="straight")
    assert from_file.success and from_python.success
    assert np.array_equal(from_file.states, from_python.states)
    assert from_file["ball"].position[-1, 1] < RADIUS + BALL_R  # it weighs on the beam


def test_a_contact_takes_a_list_of_rods_and_every_contact_type():
    text = BALL_ON_BEAM.replace("[[joint]]", """[[rod]]
name = "other"
length = 0.1
radius = 0.005
[rod.material]
E = 1e6
nu = 0.5
mu = 0.0
rho = 1000.0
[rod.base]
position = [0.0, 0.2, 0.0]

[[contact]]
body = "ball"
rods = ["beam", "other"]
type = "plane_contact"
point = [0.0, -0.1, 0.0]
normal = [0.0, 1.0, 0.0]
stiffness = 1e3
friction = 0.3

[[contact]]
body = "ball"
rods = ["other"]
type = "capsule_contact"
start = [0.0, 0.0, -0.01]
end = [0.0, 0.0, 0.01]
radius = 0.02
stiffness = 1e3

[[joint]]""")
    system = parse_scenario(text).model
    plane, capsule, sphere = system.contacts
    assert plane.rods == ("beam", "other") and capsule.rods == ("other",) and sphere.rods == ("beam",)
    assert same(plane.shape, rodmol.PlaneContact((0.0, -0.1, 0.0), (0.0, 1.0, 0.0), 1e3, friction=0.3))
    assert same(capsule.shape, rodmol.CapsuleContact((0.0, 0.0, -0.01), (0.0, 0.0, 0.01), 0.02, 1e3))
    assert [(r.index, r.rod) for r in system.rod_contacts] == [(0, "beam"), (0, "other"), (1, "other"),
                                                               (2, "beam")]


BAD = BALL_ON_BEAM.replace('rods = "beam"', 'rods = "beam"\nstifness = 1.0') + """
[[contact]]
body = "ball"
rods = "beam"
type = "plane_contact"
point = [0.0, 0.0]
normal = [0.0, 1.0, 0.0]
stiffness = -1.0

[[contact]]
rods = "beam"
type = "sphere_contact"
centre = [0.0, 0.0, 0.0]
radius = 0.1
stiffness = 1.0

[[contact]]
body = "ball"
rods = "beam"
type = "point_force"
"""


def test_every_problem_of_the_contact_tables_at_once_with_its_line():
    with pytest.raises(ScenarioError) as caught:
        parse_scenario(BAD)
    lines = BAD.splitlines()
    found = {(p.table, lines[p.line - 1].split(" =")[0]) for p in caught.value.problems}
    assert found == {("[[contact]] #1", "stifness"), ("[[contact]] #2", "point"), ("[[contact]] #2", "stiffness"),
                     ("[[contact]] #3", "[[contact]]"), ("[[contact]] #4", "type")}
    messages = "\n".join(p.message for p in caught.value.problems)
    assert "did you mean `stiffness`?" in messages and "missing required key `body`" in messages
    assert "sphere_contact" in messages  # the valid types are named


def test_a_contact_naming_no_body_is_placed_at_its_table_with_the_names_nearby():
    text = BALL_ON_BEAM.replace('body = "ball"', 'body = "bal"')
    with pytest.raises(ScenarioError) as caught:
        parse_scenario(text)
    (problem,) = caught.value.problems
    assert problem.table == "[[contact]] #1" and "did you mean 'ball'" in problem.message
    assert text.splitlines()[problem.line - 1] == "[[contact]]"
    text = BALL_ON_BEAM.replace('rods = "beam"', 'rods = ["beam", "bam"]')
    with pytest.raises(ScenarioError, match="did you mean 'beam'"):
        parse_scenario(text)


def test_the_arm_pushing_a_ball_example_runs_coarse_and_pushes_it():
    spec = load_scenario(ROOT / "examples" / "arm_pushing_ball.toml",
                         overrides={"solver.t_end": 0.6, "solver.output_dt": 0.1, "discretization.n_elements": 6})
    run = spec.simulate()
    assert run.success
    ball, arm = run["ball"], run["arm"]
    on_ball = np.einsum("nij,nj->ni", ball.rotation, ball.rod_contact_force)  # global
    on_arm = np.einsum("tni,n->ti", arm.external_force, arm.node_length)  # its contact forces only
    assert np.abs(on_ball[:, 2]).max() > 1e-3  # the arm touched it, pushing toward +z
    np.testing.assert_allclose(on_ball, -on_arm, rtol=0, atol=1e-9)
    assert ball.position[-1, 2] > ball.position[0, 2]


#: Two rods crossing, the upper one resting across the lower one: [[contact]] type "rods".
CROSSING = """\
[solver]
t_end = 0.1

[system]
gravity = [0.0, -9.81, 0.0]

[[rod]]
name = "upper"
length = 0.3
radius = 0.01
n_elements = 6
[rod.material]
E = 1e7
nu = 0.5
mu = 2e4
rho = 1000.0
[rod.base]
position = [0.0, 0.02, 0.0]

[[rod]]
name = "lower"
length = 0.3
radius = 0.01
n_elements = 6
[rod.material]
E = 1e8
nu = 0.5
mu = 2e4
rho = 1000.0
[rod.base]
position = [0.2, 0.0, -0.15]
rotation = [[0.0, 0.0, -1.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]]

[[contact]]
type = "rods"
a = "upper"
b = "lower"
friction = 0.3
"""


def test_a_rods_contact_table_is_the_systems_rod_contact():
    system = parse_scenario(CROSSING).model
    assert system.rod_pairs == [(0, rodmol.RodContact("upper", "lower", friction=0.3))]
    law = system.rod_pairs[0][1].law(system.rods["upper"], system.rods["lower"])
    assert law[0] == 1e7  # the softer rod's E


@pytest.mark.parametrize("change, words", [
    (('b = "lower"', 'b = "lowr"'), r"contact.*'lowr'.*not in `rods`"),
    (("friction = 0.3", "stiffness = -1.0"), r"contact.*stiffness` must be > 0"),
])
def test_a_bad_rods_contact_table_is_refused_naming_it(change, words):
    with pytest.raises(ScenarioError, match=f"(?s){words}"):
        parse_scenario(CROSSING.replace(*change))
