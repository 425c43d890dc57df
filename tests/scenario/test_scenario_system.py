"""System files: [system], [[rod]] with its nested tables, [[body]], [[joint]]."""

from pathlib import Path

import numpy as np
import pytest

import rodmol
from rodmol.scenario import tables
from rodmol.scenario.file import ScenarioError, load_scenario, parse_scenario
from rodmol.scenario.toml_lines import KeyLines

ROOT = Path(__file__).resolve().parents[2]
TWO_ARMS = ROOT / "examples" / "two_arms.toml"


def two_arms_in_python():
    """examples/two_arms.toml written in Python (docs/systems.md's example, N = 8 and 10)."""
    material = rodmol.Material(E=1e5, nu=0.5, mu=300.0, rho=1080.0)
    rod = rodmol.Rod(0.2, radius=(0.012, 0.006), material=material)

    def arm(side, n):
        pull = rodmol.Cable((side * 0.005, 0.0), 0.2, tension=((0.0, 0.0), (0.1, 0.3)), name="cable 1")
        return rodmol.Model(rod, n, cables=[pull])

    head = rodmol.RigidBody(mass=0.3, inertia=(2e-4, 2e-4, 2e-4), volume=2.5e-4,
                            added_mass=(0.1, 0.1, 0.1, 0.0, 0.0, 0.0), drag=(0.5, 0.5, 0.5, 1e-3, 1e-3, 1e-3))
    turn = np.diag([-1.0, -1.0, 1.0])
    return rodmol.System(
        rods={"right": arm(1.0, 8), "left": arm(-1.0, 10)}, bodies={"head": head},
        joints=[rodmol.Joint(("head", (0.04, 0.0, 0.0)), ("right", "base")),
                rodmol.Joint(("head", (-0.04, 0.0, 0.0), turn), ("left", "base"))],
        medium="water", gravity=(0.0, 0.0, -9.81))


def test_the_example_file_is_the_python_system_and_runs_the_same():
    spec = load_scenario(TWO_ARMS, overrides={"solver.t_end": 0.02})
    system, expected = spec.model, two_arms_in_python()
    assert isinstance(system, rodmol.System) and spec.solver["initial"] == "straight"
    assert {k: m.n_elements for k, m in system.rods.items()} == {"right": 8, "left": 10}
    assert [c.offset for m in system.rods.values() for c in m.cables] == [(0.005, 0.0), (-0.005, 0.0)]
    assert system.medium == expected.medium and np.array_equal(system.gravity, expected.gravity)
    for name in expected.rods:
        (body, point, rotation), (body_e, point_e, rotation_e) = system.clamps[name], expected.clamps[name]
        assert body == body_e and np.array_equal(point, point_e) and np.array_equal(rotation, rotation_e)
    assert np.array_equal(system.bodies["head"].mass_matrix, expected.bodies["head"].mass_matrix)
    from_file = spec.simulate()
    from_python = rodmol.simulate(expected, 0.02, output_dt=spec.solver["output_dt"], initial="straight")
    assert from_file.success and from_python.success
    assert np.array_equal(from_file.states, from_python.states)
    assert from_file["head"].position[-1, 2] < 0.0  # it sinks: heavier than the water it displaces


def test_a_table_under_an_array_of_tables_is_placed_in_its_last_entry():
    lines = KeyLines("[[rod]]\nname = 'a'\n[rod.material]\nE = 1\n[[rod]]\n[[rod.cable]]\n"
                     "anchor = 1\n[[rod.cable]]\n[[body]]\n[[rod.load]]\ns = 2\n")
    assert lines.find(("rod", 0, "material", "E")) == 4
    assert lines.find(("rod", 1, "cable", 0, "anchor")) == 7
    assert lines.find(("rod", 1, "cable", 1)) == 8
    assert lines.find(("rod", 1, "load", 0, "s")) == 11  # after [[body]]: the last [[rod]]'s


BAD = """\
medium = "water"
[system]
gravity = [0.0, -9.81]
[[rod]]
name = "arm"
length = 0.2
radius = 0.01
[rod.material]
E = -1.0
nu = 0.5
mu = 0.0
rho = 1000.0
[[rod.cable]]
offset = [0.002, 0.0]
anchor = 0.3
[[body]]
name = "head"
mass = -1.0
inertia = [1e-4, 1e-4, 1e-4]
[[joint]]
a = ["head", [0.0, 0.0, 0.0]]
b = ["amr", "base"]
[[rod]]
name = "arm"
length = 0.1
radius = 0.01
[rod.material]
E = 1e5
nu = 0.5
mu = 0.0
rho = 1000.0
[solver]
t_end = 1.0
initial = "upright"
"""


def test_every_problem_of_a_system_file_at_once_with_its_line_and_table():
    with pytest.raises(ScenarioError) as caught:
        parse_scenario(BAD)
    found = {(p.line, p.table, p.message.split()[0]) for p in caught.value.problems}
    assert found == {
        (1, "", "`medium`"),  # a single-rod key: its place in a system file is named
        (3, "[system]", "`gravity`"),
        (9, "[[rod]] #1 [material]", "`E`"),
        (15, "[[rod]] #1 [[cable]] #1", "`anchor`"),
        (18, "[[body]] #1", "`mass`"),
        (20, "[[joint]] #1", "`joints[0]`"),  # names no rod ("did you mean 'arm'?")
        (24, "[[rod]] #2", "the"),  # the name used twice
        (34, "[solver]", "unknown"),  # an initial state no system has
    }
    messages = "\n".join(p.message for p in caught.value.problems)
    for words in ("[system] medium", "used twice", "did you mean 'straight'", "did you mean 'arm'"):
        assert words in messages


def test_a_joint_naming_no_rod_is_placed_at_its_joint():
    text = TWO_ARMS.read_text().replace('b = ["left", "base"]', 'b = ["lft", "base"]')
    with pytest.raises(ScenarioError) as caught:
        parse_scenario(text)
    (problem,) = caught.value.problems
    assert problem.table == "[[joint]] #2" and "did you mean 'left'" in problem.message
    assert text.splitlines()[problem.line - 1] == "[[joint]]" and text.count("[[joint]]") == 2


def test_a_body_from_a_mesh_and_a_driven_body(tmp_path):
    meshio = pytest.importorskip("meshio")
    corners = np.array([[x, y, z] for x in (0, 0.1) for y in (0, 0.2) for z in (0, 0.3)], dtype=float)
    faces = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    triangles = [t for a, b, c, d in faces for t in ((a, b, c), (a, c, d))]
    meshio.write(tmp_path / "box.stl", meshio.Mesh(corners, [("triangle", np.array(triangles))]))
    text = TWO_ARMS.read_text().split("[[body]]")[0] + """
[[body]]
name = "head"
mesh = "box.stl"
density = 500.0
position = [0.0, 0.0, 1.0]

[[body]]
name = "cart"
mass = 1.0
inertia = [1.0, 1.0, 1.0]
position = [0.0, 2.0, 0.0]
motion = { velocity = [0.1, 0.0, 0.0] }

[[joint]]
a = ["head", [0.04, 0.0, 0.0]]
b = ["right", "base"]

[[joint]]
a = ["cart", [0.0, 0.0, 0.0]]
b = ["left", "base"]
"""
    system = parse_scenario(text, base_dir=tmp_path).model
    head, cart = system.bodies["head"], system.bodies["cart"]
    assert head.mass == pytest.approx(500.0 * 0.1 * 0.2 * 0.3, rel=1e-12)
    assert head.volume == pytest.approx(0.006, rel=1e-12)
    assert np.allclose(head.centre_of_mass, (0.05, 0.1, 0.15)) and np.array_equal(head.position, (0, 0, 1))
    assert cart.driven and np.array_equal(cart.position, (0.0, 2.0, 0.0))
    assert np.array_equal(cart.motion.velocity(3.0), (0.1, 0.0, 0.0))


def test_the_reference_documents_a_system_rods_own_keys():
    text = (ROOT / "docs" / "scenario-reference.md").read_text(encoding="utf-8")
    section = text.split("## `[[rod]]` (systems", 1)[1].split("\n## ", 1)[0]
    rows = {line.split("`")[1] for line in section.splitlines() if line.startswith("| `")}
    named = set(tables.SYSTEM_ROD.names()) - set(tables.ROD.names())
    assert rows == named
    assert all(f"`{key}`" in section for key in tables.ROD.names())


PAYLOAD = """\
[solver]
t_end = 0.1
[system]
medium = "air"
[discretization]
n_elements = 8
[[rod]]
name = "beam"
length = 0.2
radius = 0.005
[rod.material]
E = 1e7
nu = 0.5
mu = 1000.0
rho = 1000.0
[[body]]
name = "mass"
mass = 0.01
inertia = [1e-6, 1e-6, 1e-6]
position = [0.2, 0.0, 0.0]
[[joint]]
a = ["mass", [0.0, 0.0, 0.0]]
b = ["beam", "tip"]
kind = "pin"
stiffness = 1e6
damping = 3.0
"""


def test_a_penalty_joint_takes_every_argument_of_joint():
    """A tip pinned to a payload with its own stiffness and damping: every argument of
    rodmol.Joint reaches it from the file (the reader re-types none of them)."""
    system = parse_scenario(PAYLOAD).model
    (joint,) = system.penalty_joints
    assert (joint.rod, joint.body, joint.kind) == ("beam", "mass", "pin")
    hold = system.rods["beam"].loads[joint.load]
    assert (hold.stiffness, hold.damping) == (1e6, 3.0)


def test_a_system_file_with_a_free_body_starts_at_its_equilibrium():
    """`initial = "equilibrium"` with a free payload clamped to a tip: the run's first frame is
    rodmol.equilibrium's state of the file's system, and the run stays there."""
    text = PAYLOAD.replace("t_end = 0.1", 't_end = 0.02\ninitial = "equilibrium"').replace(
        'medium = "air"', 'medium = "air"\ngravity = [0.0, 0.0, -9.81]')
    spec = parse_scenario(text.replace('kind = "pin"', 'kind = "clamp"'))  # a pinned payload may turn freely
    run = spec.simulate()
    rest = rodmol.equilibrium(spec.model)
    assert run.success and np.abs(run.states[0] - rest).max() < 1e-8
    sag = run["mass"].position[0, 2]
    assert sag < -1e-4  # the payload hangs below the unloaded tip ...
    assert np.abs(run["mass"].position - run["mass"].position[0]).max() < 1e-3 * abs(sag)  # ... and stays


@pytest.mark.parametrize("backend", ["galpha", "rk23"])
def test_a_system_file_runs_with_the_galpha_and_rk23_backends(backend):
    text = TWO_ARMS.read_text().replace("t_end = 0.5", f't_end = 0.02\nbackend = "{backend}"')
    run = parse_scenario(text).simulate()
    assert run.success and run.t[-1] == pytest.approx(0.02)
    assert ("dt" in run.stats) == (backend == "galpha")  # the backend named in the file ran


BOX_ON_FLOOR = TWO_ARMS.read_text().split("[[body]]")[0] + """
[[body]]
name = "head"
mass = 0.3
inertia = [2e-4, 2e-4, 2e-4]
contact_points = [[0.0, 0.0, 0.0], [0.0, 0.0, 0.01]]
contact_radius = [0.02, 0.01]

[[body.contact]]
type = "plane_contact"
point = [0.0, 0.0, -0.02]
normal = [0.0, 0.0, 1.0]
stiffness = 1e4
friction = 0.5

[[body.contact]]
type = "sphere_contact"
centre = [0.3, 0.0, 0.0]
radius = 0.1
stiffness = 2e4
damping = 10.0

[[joint]]
a = ["head", [0.04, 0.0, 0.0]]
b = ["right", "base"]
"""


def test_a_bodys_contacts_are_its_body_contact_tables():
    head = parse_scenario(BOX_ON_FLOOR).model.bodies["head"]
    floor, ball = head.contacts
    assert isinstance(floor, rodmol.PlaneContact) and floor.stiffness == 1e4 and floor.friction == 0.5
    assert isinstance(ball, rodmol.CapsuleContact) and ball.radius == 0.1 and ball.damping == 10.0
    np.testing.assert_array_equal(head.contact_points, [(0.0, 0.0, 0.0), (0.0, 0.0, 0.01)])
    np.testing.assert_array_equal(head.contact_radius, (0.02, 0.01))
    # The law's units for a body are per contact point (the reference and the messages say N/m).
    assert tables.BODY_CONTACTS["plane_contact"].unit("stiffness") == "N/m"
    assert tables.LOADS["plane_contact"].unit("stiffness") == "N/m^2"
    with pytest.raises(ScenarioError) as caught:
        parse_scenario(BOX_ON_FLOOR.replace('type = "sphere_contact"', 'type = "point_force"'))
    (problem,) = caught.value.problems
    assert problem.table == "[[body]] #1 [[contact]] #2" and "plane_contact" in problem.message


def test_joints_of_bodies_and_a_pinned_base_are_read_from_a_file():
    text = TWO_ARMS.read_text() + """
[[body]]
name = "tail"
mass = 0.1
inertia = [1e-5, 1e-5, 1e-5]
position = [0.0, -0.05, 0.0]

[[joint]]
a = ["head", [0.0, -0.05, 0.0]]
b = ["tail", [0.0, 0.0, 0.0]]
kind = "pin"

[[joint]]
a = ["tail", [0.0, 0.0, 0.0]]
b = "world"
"""
    system = parse_scenario(text).model
    assert [(j.a, j.b, j.kind) for j in system.body_joints] == [("head", "tail", "pin"), ("tail", None, "clamp")]
    pinned = parse_scenario(text.replace('b = ["right", "base"]', 'b = ["right", "base"]\nkind = "pin"')).model
    assert pinned.base_bodies == {"right": "right.base"} and pinned.clamps["right"][0] == "right.base"


def _problems(text):
    with pytest.raises(ScenarioError) as caught:
        parse_scenario(text)
    return caught.value.problems


def _line(text, wanted, occurrence=1):
    """The line number of the ``occurrence``-th line of ``text`` equal to ``wanted``."""
    return [i for i, line in enumerate(text.splitlines(), start=1) if line == wanted][occurrence - 1]


def test_a_rod_and_a_body_of_one_name_are_reported_at_the_later_name_naming_the_first():
    # The head renamed "left" (and the joints with it): before, one problem at the [system] header.
    text, left = TWO_ARMS.read_text().replace('"head"', '"left"'), 'name = "left"'
    (problem,) = _problems(text)  # nothing follows about the joints that name the body "left"
    assert (problem.line, problem.table) == (_line(text, left, 2), "[[body]] #1")
    assert problem.message == (f"the body name 'left' is used twice: [[rod]] #2 (line {_line(text, left)}) has "
                               "it too; rods and bodies share one set of names, each unique")
    # A body before the rods: the rod, the later, is reported.
    body = text[text.index("[[body]]"):text.index("[[joint]]")]
    first = text.replace(body, "").replace("[[rod]]", body + "[[rod]]", 1)
    (problem,) = _problems(first)
    assert (problem.line, problem.table) == (_line(first, left, 2), "[[rod]] #2")
    assert f"[[body]] #1 (line {_line(first, left)}) has it too" in problem.message


def test_a_rod_or_body_named_world_is_reported_at_its_name():
    text = TWO_ARMS.read_text().replace('name = "left"', 'name = "world"').replace('["left", "base"]', '["world"]')
    found = _problems(text)
    assert [(p.line, p.table) for p in found][0] == (_line(text, 'name = "world"'), "[[rod]] #2")
    assert "the rod name 'world' is reserved: a joint's end `\"world\"` is the fixed frame" in found[0].message


def test_two_rods_or_cables_of_one_name_are_reported_at_the_later_naming_the_first():
    text = TWO_ARMS.read_text()
    rod = text[text.index("[[rod]]"):text.index("[[rod]]", text.index("[[rod]]") + 1)]
    text = text.replace("[[body]]", rod + "[[body]]")  # a third rod, named "right" too
    text = text.replace("[[rod.cable]]\n", '[[rod.cable]]\nname = "pull"\n').replace(
        "tension = [[0.0, 0.0], [0.1, 0.3]]\n", 'tension = [[0.0, 0.0], [0.1, 0.3]]\n[[rod.cable]]\nname = "pull"\n'
        'offset = [0.0, 0.005]\nanchor = 0.1\n', 1)
    found = {(p.line, p.table): p.message for p in _problems(text)}
    first_rod, first_cable = _line(text, 'name = "right"'), _line(text, 'name = "pull"')
    assert found == {
        (_line(text, 'name = "right"', 2), "[[rod]] #3"):
            f"the rod name 'right' is used twice: [[rod]] #1 (line {first_rod}) has it too; rods and bodies share "
            "one set of names, each unique",
        # before: reported at the first cable, whose name the Model's message quoted
        (_line(text, 'name = "pull"', 2), "[[rod]] #1 [[cable]] #2"):
            f"the cable name 'pull' is used twice: [[rod]] #1 [[cable]] #1 (line {first_cable}) has it too; "
            "cable names must be unique (one without `name` is 'cable K', the K-th [[cable]])",
    }
