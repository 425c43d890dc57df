"""[[load]] tables and [material] G in scenario files: the same model as in Python, and
every problem of a bad load table with its line."""

import numpy as np
import pytest
from scenario_texts import MINIMAL

import rodmol
from rodmol.discretise.sampling import Sampled
from rodmol.scenario.file import ScenarioError, load_scenario, parse_scenario

ARM = MINIMAL + """
[discretization]
n_elements = 20
"""

LOADS = """
[[load]]
type = "point_force"
s = 0.3
force = [[0.0, 0.0, 0.0, 0.0], [1.0, 0.0, 0.0, 0.02]]

[[load]]
type = "point_moment"
s = 0.15
moment = "moment.csv"
frame = "local"
name = "wrist"

[[load]]
type = "distributed_force"
force = [0.0, 0.0, 0.01]

[[load]]
type = "distributed_moment"
moment = [0.0, 0.001, 0.0]
frame = "local"

[[load]]
type = "plane_contact"
point = [0.0, -0.05, 0.0]
normal = [0.0, 2.0, 0.0]
stiffness = 1e4
friction = 0.3

[[load]]
type = "sphere_contact"
centre = [0.25, -0.08, 0.0]
radius = 0.03
stiffness = 1e4
damping = 5.0

[[load]]
type = "capsule_contact"
start = [0.1, 0.0, 0.05]
end = [0.2, 0.0, 0.05]
radius = 0.02
stiffness = 2e4
slip_speed = 1e-3
smoothing_depth = 1e-4
"""

MOMENT_CSV = "t, x, y, z\n0.0, 0.0, 0.0, 0.0\n1.0, 0.0, 0.0, 0.004\n"


def python_loads(csv):
    return [rodmol.PointForce(0.3, [(0.0, 0, 0, 0), (1.0, 0, 0, 0.02)]),
            rodmol.PointMoment(0.15, csv, frame="local", name="wrist"),
            rodmol.DistributedForce((0.0, 0.0, 0.01)),
            rodmol.DistributedMoment((0.0, 0.001, 0.0), frame="local"),
            rodmol.PlaneContact((0, -0.05, 0), (0, 1, 0), 1e4, friction=0.3),
            rodmol.SphereContact((0.25, -0.08, 0.0), 0.03, 1e4, damping=5.0),
            rodmol.CapsuleContact((0.1, 0, 0.05), (0.2, 0, 0.05), 0.02, 2e4, slip_speed=1e-3,
                                  smoothing_depth=1e-4)]


@pytest.fixture
def scenario(tmp_path):
    (tmp_path / "moment.csv").write_text(MOMENT_CSV)
    path = tmp_path / "loaded.toml"
    path.write_text(ARM + LOADS)
    return path


def problems(text, base_dir="."):
    with pytest.raises(ScenarioError) as info:
        parse_scenario(text, base_dir=base_dir, source="s.toml")
    return info.value.problems


def line_of(text, fragment, after=None):
    """Line number of the first line starting with ``fragment`` (after line ``after``)."""
    lines = text.splitlines()
    start = 0 if after is None else after
    return next(i for i, line in enumerate(lines, start=1) if i > start and line.startswith(fragment))


def test_toml_loads_give_the_python_model(scenario, tmp_path):
    ours = load_scenario(scenario).model
    rod = rodmol.Rod(0.3, 0.01, rodmol.Material(1e5, 0.5, 10.0, 1000.0))
    ref = rodmol.Model(rod, 20, loads=python_loads(tmp_path / "moment.csv"))
    assert [type(a) for a in ours.loads] == [type(b) for b in ref.loads]
    assert [a.name for a in ours.loads][:2] == ["point force", "wrist"]
    for t in (0.0, 0.5, 1.0):  # the knots and the CSV table interpolated in time
        y_ours, y_ref = rodmol.equilibrium(ours, t), rodmol.equilibrium(ref, t)
        np.testing.assert_allclose(y_ours, y_ref, rtol=0, atol=1e-12)
    # The loads act: the contact lifts the sagging rod, the point force bends it sideways.
    free = rodmol.equilibrium(rodmol.Model(rod, 20), 0.5)
    assert np.max(np.abs(y_ours - free)) > 1e-3


def test_loads_reach_the_dynamics_as_in_python(scenario, tmp_path):
    spec = load_scenario(scenario)
    rod = rodmol.Rod(0.3, 0.01, rodmol.Material(1e5, 0.5, 10.0, 1000.0))
    ref = rodmol.Model(rod, 20, loads=python_loads(tmp_path / "moment.csv"))
    a = rodmol.simulate(spec.model, 0.02, output_dt=0.01)
    b = rodmol.simulate(ref, 0.02, output_dt=0.01)
    np.testing.assert_allclose(a.positions, b.positions, rtol=0, atol=1e-12)
    np.testing.assert_allclose(a.external_force, b.external_force, rtol=0, atol=1e-12)
    assert np.max(np.abs(a.external_force[-1, 1:, 1])) > 1.0  # the floor pushes up


def test_loads_with_the_paper_arm():
    text = 'arm = "paper"\nscenario = "bending"\n\n[[load]]\ntype = "point_force"\ns = 0.418\n' \
           'force = [0.0, 0.0, 0.05]\n\n[[load]]\ntype = "distributed_moment"\nmoment = [0.0, 0.0, 0.01]\n'
    spec = parse_scenario(text + "[discretization]\nn_elements = 12\n")
    scenario = rodmol.scenarios.get("bending")
    ref = rodmol.paper_arm(12, tensions=scenario.tensions,
                           loads=[rodmol.PointForce(0.418, (0, 0, 0.05)),
                                  rodmol.DistributedMoment((0, 0, 0.01))])
    np.testing.assert_allclose(rodmol.equilibrium(spec.model, 5.0), rodmol.equilibrium(ref, 5.0),
                               rtol=0, atol=1e-12)
    unloaded = parse_scenario('arm = "paper"\nscenario = "bending"\n[discretization]\nn_elements = 12\n')
    assert not np.allclose(rodmol.equilibrium(unloaded.model, 5.0), rodmol.equilibrium(ref, 5.0))
    (problem,) = problems(text.replace("s = 0.418", "s = 0.5"))
    assert problem.table == "[[load]] #1" and problem.line == 6 and "within the rod" in problem.message


def test_shear_modulus_instead_of_poisson_ratio():
    spec = parse_scenario(ARM.replace("nu = 0.5", "G = 2000.0"))
    assert spec.model.rod.material.G == 2000.0
    ref = rodmol.Model(rodmol.Rod(0.3, 0.01, rodmol.Material(1e5, mu=10.0, rho=1000.0, G=2000.0)), 20)
    np.testing.assert_array_equal(Sampled(spec.model).kl, Sampled(ref).kl)
    np.testing.assert_array_equal(Sampled(spec.model).kth, Sampled(ref).kth)
    np.testing.assert_allclose(rodmol.equilibrium(spec.model), rodmol.equilibrium(ref), rtol=0, atol=1e-12)
    # Shear is softer than with nu = 0.5 (G = E/3): the stiffness differs.
    assert not np.array_equal(Sampled(spec.model).kl, Sampled(parse_scenario(ARM).model).kl)


def test_exactly_one_of_nu_and_g():
    both = ARM.replace("nu = 0.5", "nu = 0.5\nG = 2000.0")
    (problem,) = problems(both)
    assert problem.table == "[material]" and problem.line == line_of(both, "G =")
    assert "either `nu`" in problem.message and "not both" in problem.message
    neither = ARM.replace("nu = 0.5\n", "")
    (problem,) = problems(neither)
    assert problem.line == line_of(neither, "[material]") and "missing `nu`" in problem.message
    assert "`G`" in problem.message
    bad = ARM.replace("nu = 0.5", "G = -3.0").replace("E = 1e5", "E = 0").replace("rho = 1000.0\n", "")
    texts = {p.line: p.message for p in problems(bad)}  # each value checked alone, all reported
    assert "`G` must be > 0 Pa" in texts[line_of(bad, "G =")]
    assert "`E` must be > 0 Pa" in texts[line_of(bad, "E =")]


def test_every_problem_of_bad_load_tables_has_its_line_and_table(tmp_path):
    text = ARM + """
[[load]]
type = "point_forse"
s = 0.1

[[load]]
type = "point_force"
s = 0.1
forse = [0.0, 0.0, 1.0]
frame = "lokal"

[[load]]
type = "plane_contact"
point = [0.0, -0.05]
normal = [0.0, 1.0, 0.0]
stiffness = -1.0
friction = "high"

[[load]]
type = "distributed_force"
force = [[0.0, 0.0, 0.0, 1.0]]

[[load]]
s = 0.2

[[load]]
type = "point_moment"
s = 0.4
moment = [[1.0, 0.0, 0.0, 0.1], [0.5, 0.0, 0.0, 0.2]]

[[load]]
type = "sphere_contact"
centre = [0.0, 0.0, 0.0]
radius = 0.02
stiffness = 1e3
normal = [0.0, 1.0, 0.0]

[[load]]
type = "point_force"
s = 0.1
force = "missing.csv"
"""
    found = problems(text, base_dir=tmp_path)
    at = {(p.table, p.line): p.message for p in found}

    def message(number, fragment, after_header=True):
        header = [i for i, line in enumerate(text.splitlines(), 1) if line == "[[load]]"][number - 1]
        line = line_of(text, fragment, after=header) if after_header else header
        return at[(f"[[load]] #{number}", line)]

    assert "`type` 'point_forse'; did you mean 'point_force'?" in message(1, "type")
    assert "'plane_contact'" in message(1, "type") and "'capsule_contact'" in message(1, "type")
    assert "unknown key `forse`; did you mean `force`?" in message(2, "forse")
    assert "missing required key `force` [N]" in message(2, "", after_header=False)
    assert "`frame` must be 'global' (dead load) or 'local' (follower load), got 'lokal'; did you mean 'local'?" \
        in message(2, "frame")
    # Each value checked by the load's class, all of a table's reported, each at its line
    assert "`plane contact point` must have three components" in message(3, "point")
    assert "`plane contact stiffness` must be > 0 N/m^2" in message(3, "stiffness")
    assert "`plane contact friction` must be a number" in message(3, "friction")
    assert "`distributed force force` must have three components" in message(4, "force")
    assert "missing required key `type`; valid types: point_force, point_moment" in message(5, "", False)
    assert "knot times must increase" in message(6, "moment")
    assert "unknown key `normal`" in message(7, "normal") and "sphere_contact" in message(7, "normal")
    assert "missing.csv" in message(8, "force")
    assert len(found) == 12
    assert str(ScenarioError("s.toml", found)).count("s.toml:") == 13


def test_point_loads_beyond_the_tip_all_reported():
    text = ARM + ('\n[[load]]\ntype = "point_force"\ns = 0.31\nforce = [0.0, 1.0, 0.0]\n'
                  '\n[[load]]\ntype = "point_moment"\ns = 0.5\nmoment = [0.0, 1.0, 0.0]\n')
    found = problems(text)
    assert [(p.table, p.line) for p in found] == [("[[load]] #1", line_of(text, "s = 0.31")),
                                                  ("[[load]] #2", line_of(text, "s = 0.5"))]
    assert all("`s` must lie within the rod, <= L = 0.3 m" in p.message for p in found)


def test_bad_csv_rows_name_the_table_line(tmp_path):
    (tmp_path / "f.csv").write_text("t,x,y,z\n0,0,0,0\n1,0,oops,0\n")
    text = ARM + '\n[[load]]\ntype = "point_force"\ns = 0.3\nforce = "f.csv"\n'
    (problem,) = problems(text, base_dir=tmp_path)
    assert problem.line == line_of(text, "force =") and problem.table == "[[load]] #1"
    assert "f.csv:3: not a number" in problem.message


def test_load_must_be_an_array_of_tables():
    (problem,) = problems('load = "heavy"\n' + ARM)
    assert "`load` must be an array of tables `[[load]]`" in problem.message


HOLDS = """
[[load]]
type = "hold"
s = 0.3
kind = "clamp"
position = [0.28, 0.0, -0.05]
rotation = [[0.0, 0.0, -1.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]]
stiffness = 5e3
damping = 2.0
name = "wall"

[[load]]
type = "hold"
s = 0.15
"""


def test_hold_tables_give_the_python_holds():
    """A [[load]] type = "hold" table builds the Hold the same keys give in
    Python (the reader takes its keys and units from the load's record), and
    the held model's rest state is the Python one's."""
    spec = parse_scenario(ARM + HOLDS)
    turned = np.array([[0.0, 0.0, -1.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]])
    ref = [rodmol.Hold(0.3, kind="clamp", position=(0.28, 0.0, -0.05), rotation=turned, stiffness=5e3,
                       damping=2.0, name="wall"), rodmol.Hold(0.15)]
    for ours, theirs in zip(spec.model.loads, ref, strict=True):
        assert (ours.s, ours.kind, ours.stiffness, ours.damping, ours.name) == \
            (theirs.s, theirs.kind, theirs.stiffness, theirs.damping, theirs.name)
    np.testing.assert_array_equal(spec.model.loads[0].rotation, turned)
    np.testing.assert_array_equal(spec.model.loads[0].position, (0.28, 0.0, -0.05))
    assert spec.model.loads[1].position is None and spec.model.loads[1].rotation is None
    rod = rodmol.Rod(0.3, 0.01, rodmol.Material(1e5, 0.5, 10.0, 1000.0))
    y_ref = rodmol.equilibrium(rodmol.Model(rod, 20, loads=ref))
    np.testing.assert_allclose(rodmol.equilibrium(spec.model), y_ref, rtol=0, atol=1e-12)
    tip = rodmol.StateLayout(20).field(y_ref, "u")[-1]
    np.testing.assert_allclose(tip, (0.28, 0.0, -0.05), atol=1e-3)  # the hold acts


def test_a_hold_off_the_grid_is_reported_at_its_table():
    text = ARM + HOLDS.replace("s = 0.15", "s = 0.16")
    (problem,) = problems(text)
    assert problem.table == "[[load]] #2" and "velocity node" in problem.message
    assert problem.line == line_of(text, "s = 0.16")
