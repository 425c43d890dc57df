"""The TOML scenario parser: schema, every problem at once, suggestions, paths, radius forms."""

from pathlib import Path

import numpy as np
import pytest
from scenario_texts import MINIMAL

import rodmol
from rodmol.discretise.sampling import SAMPLED, Sampled
from rodmol.scenario.file import Override, ScenarioError, load_scenario, parse_scenario

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"

def problems(text, base_dir="."):
    with pytest.raises(ScenarioError) as info:
        parse_scenario(text, base_dir=base_dir, source="s.toml")
    return info.value.problems


def test_minimal_file_gives_model_and_defaults():
    spec = parse_scenario(MINIMAL)
    assert spec.model.n_elements == 100 and spec.t_end == 1.0
    # rtol None: the scheme's default_rtol
    assert spec.solver == dict(backend="cvode", rtol=None, atol=None, output_dt=0.01, initial="equilibrium",
                               scheme="centred")
    assert spec.model.medium.rho == 0.0 and spec.model.base.fixed
    assert spec.output.vtk and spec.output.npz and spec.output.every is None  # all frames up to 6000
    np.testing.assert_array_equal(spec.model.gravity, [0.0, -9.81, 0.0])


@pytest.mark.parametrize("name", ["bending", "reaching", "fetching"])
def test_paper_examples_are_the_paper_model(name):
    spec = load_scenario(EXAMPLES / f"{name}.toml")
    ours, ref = spec.model, rodmol.scenarios.get(name).model(100)
    assert spec.t_end == rodmol.scenarios.get(name).t_end
    for attribute in ("s_nodes", "marker_offsets", "gravity"):
        np.testing.assert_array_equal(getattr(ours, attribute), getattr(ref, attribute), err_msg=attribute)
    for attribute in SAMPLED:
        np.testing.assert_array_equal(getattr(Sampled(ours), attribute), getattr(Sampled(ref), attribute),
                                      err_msg=attribute)
    np.testing.assert_array_equal([c.offset3 for c in ours.cables], [c.offset3 for c in ref.cables])
    assert ours.medium == ref.medium and ours.markers == ref.markers
    assert [c.name for c in ours.cables] == [c.name for c in ref.cables]
    for t in np.linspace(0.0, 10.0, 201):
        np.testing.assert_array_equal(ours.tensions(t), ref.tensions(t))


def test_paper_shortcut_equals_written_out_file():
    short = parse_scenario('arm = "paper"\nscenario = "reaching"\n')
    full = load_scenario(EXAMPLES / "reaching.toml")
    assert short.t_end == full.t_end == 9.0
    np.testing.assert_array_equal(Sampled(short.model).mass, Sampled(full.model).mass)
    for t in (0.3, 2.7, 6.2):
        np.testing.assert_array_equal(short.model.tensions(t), full.model.tensions(t))


def test_paper_shortcut_cable_override():
    spec = parse_scenario('arm = "paper"\nscenario = "bending"\n[[cable]]\nnumber = 3\ntension = 1.5\n')
    assert spec.model.tensions(5.0)[2] == 1.5 and spec.model.tensions(1.0)[10] == 2.0


def test_every_problem_is_reported_at_once_with_lines_and_suggestions():
    text = MINIMAL.replace("nu = 0.5", "nuu = 0.5").replace("E = 1e5", "E = -1.0") + """
[medium]
preset = "watr"

[[cable]]
offset = [0.002, 0.0]
ancor = 0.3

[output]
every = 0
"""
    found = problems(text)
    by_line = {p.line: str(p) for p in found}
    lines = text.splitlines()

    def line_of(fragment):
        return next(i for i, line in enumerate(lines, start=1) if line.startswith(fragment))

    assert "unknown key `nuu`; did you mean `nu`?" in by_line[line_of("nuu")]
    assert "`E` must be > 0 Pa, got -1.0" in by_line[line_of("E =")]
    assert "did you mean 'water'?" in by_line[line_of("preset")]
    assert "unknown key `ancor`; did you mean `anchor`?" in by_line[line_of("ancor")]
    assert "[[cable]] #1" in by_line[line_of("ancor")]
    assert "`every` must be >= 1" in by_line[line_of("every")]
    assert any("missing `nu`" in str(p) for p in found)
    assert any("missing required key `anchor`" in str(p) for p in found)
    message = str(ScenarioError("s.toml", found))
    assert message.startswith(f"s.toml: {len(found)} problems:")
    assert all(f"s.toml:{p.line}:" in message for p in found)


def test_unknown_table_and_top_level_key():
    found = problems("gravty = 1\n" + MINIMAL + "\n[solvr]\nrtol = 1e-6\n")
    texts = [str(p) for p in found]
    assert any("unknown key `solvr`; did you mean `solver`?" in t for t in texts)
    assert any("unknown key `gravty`; did you mean `gravity`?" in t for t in texts)


def test_constructor_errors_are_collected_with_their_table():
    text = MINIMAL.replace("nu = 0.5", "nu = 0.7") + """
[[cable]]
name = "outside"
offset = [0.02, 0.0]
anchor = 0.2
"""
    found = problems(text)
    messages = {p.table: p.message for p in found}
    assert "`nu` must lie in (-1, 0.5]" in messages["[material]"]
    # The cable is only checked against the body once the rod is valid.
    found = problems(text.replace("nu = 0.7", "nu = 0.5"))
    assert len(found) == 1 and found[0].table == "[[cable]] #1" and "outside the body" in found[0].message
    assert found[0].line == text.splitlines().index("[[cable]]") + 1


def test_multiline_arrays_do_not_confuse_line_numbers():
    text = MINIMAL + """
[[cable]]
offset = [0.002, 0.0]
anchor = 0.3
tension = [
  [0.0, 0.0],
  [1.0, 2.0],
]
oops = 1
"""
    (problem,) = problems(text)
    assert problem.line == text.splitlines().index("oops = 1") + 1


@pytest.mark.parametrize("radius, at_half", [
    ("0.01", 0.01),
    ("[0.02, 0.01]", 0.015),
    ("[[0.0, 0.02], [0.1, 0.01], [0.3, 0.01]]", 0.01),
    ("[[0.0, 0.02], [0.3, 0.008]]", 0.014),
])
def test_radius_forms(radius, at_half):
    spec = parse_scenario(MINIMAL.replace("radius = 0.01", f"radius = {radius}"))
    assert spec.model.rod.radius_at(0.15) == pytest.approx(at_half)


@pytest.mark.parametrize("radius, needle", [
    ("[[0.0, 0.02], [0.2, 0.01]]", "span s = 0 to the length 0.3 m"),
    ("[[0.0, 0.02], [0.2, 0.01], [0.1, 0.01], [0.3, 0.01]]", "increasing s"),
    ("[[0.0, 0.02], [0.3, -0.01]]", "must be finite and > 0 m"),
    ("[0.01, 0.02, 0.03]", "a (base, tip) pair"),
    ('"thick"', "a (base, tip) pair"),
])
def test_bad_radius(radius, needle):
    (problem,) = problems(MINIMAL.replace("radius = 0.01", f"radius = {radius}"))
    assert needle in problem.message and problem.table == "[rod]" and problem.line == 4


def test_rest_strains_as_in_python():
    """`rest_curvature` and `rest_stretch` in [rod]: a 3-vector or [s, x, y, z] points, the same Rod
    as the Python constructor; a bad one is reported at its line, naming the key."""
    text = MINIMAL.replace("radius = 0.01", "radius = 0.01\nrest_curvature = [0.0, 0.0, 5.0]\n"
                           "rest_stretch = [[0.0, 1.0, 0.0, 0.0], [0.3, 1.1, 0.01, 0.0]]")
    rod = parse_scenario(text).model.rod
    python = rodmol.Rod(0.3, 0.01, rod.material, rest_curvature=(0.0, 0.0, 5.0),
                        rest_stretch=[(0.0, 1.0, 0.0, 0.0), (0.3, 1.1, 0.01, 0.0)])
    assert rod == python and not rod.straight
    for value, needle in (("[0.0, 5.0]", "must be a 3-vector (local frame)"),
                          ("[[0.0, 0.0, 0.0, 5.0], [0.2, 0.0, 0.0, 5.0]]", "span s = 0 to the length 0.3 m")):
        (problem,) = problems(MINIMAL.replace("radius = 0.01", f"radius = 0.01\nrest_curvature = {value}"))
        assert needle in problem.message and "rest_curvature" in problem.message and problem.line == 5
        assert problem.table == "[rod]"


def test_csv_path_is_relative_to_the_file(tmp_path):
    (tmp_path / "tables").mkdir()
    (tmp_path / "tables" / "pull.csv").write_text("t,T\n0,0\n1,2\n")
    scenario = tmp_path / "run.toml"
    scenario.write_text(MINIMAL + '\n[[cable]]\noffset = [0.002, 0]\nanchor = 0.3\n'
                        'tension = "tables/pull.csv"\n\n[output]\ndirectory = "results/run"\n')
    spec = load_scenario(scenario)
    assert spec.model.tensions(0.5) == pytest.approx([1.0])
    assert spec.output.directory == tmp_path / "results" / "run"
    (problem,) = problems(MINIMAL + '\n[[cable]]\noffset = [0.002, 0]\nanchor = 0.3\ntension = "no.csv"\n',
                          base_dir=tmp_path)
    assert "no.csv" in problem.message and problem.table == "[[cable]] #1"


def test_uniform_example_reads_its_csv_table():
    spec = load_scenario(EXAMPLES / "uniform_arm_air.toml")
    east = spec.model.cables[0]
    assert east.name == "east" and east.tension(2.0) == pytest.approx(2.5)
    assert spec.model.medium.rho == 0.0
    np.testing.assert_allclose(np.asarray(spec.model.base.rotation)[:, 0], [0.0, -1.0, 0.0])


def test_medium_table_preset_switches_and_base_motion():
    spec = parse_scenario(MINIMAL + """
[medium]
preset = "water"
Cy = 1.0
drag = false
munk_moment = true

[base]
velocity = [0.0, 0.1, 0.0]
""")
    assert spec.model.medium.rho == 1022.0 and spec.model.medium.Cy == 1.0
    assert not spec.model.drag and spec.model.munk_moment
    np.testing.assert_array_equal(spec.model.base.velocities(3.0)[0], [0.0, 0.1, 0.0])
    (problem,) = problems(MINIMAL + "\n[base]\nfixed = true\nvelocity = [0, 0, 1]\n")
    assert "fixed = true" in problem.message


def test_overrides_replace_values_and_name_the_option():
    spec = parse_scenario(MINIMAL, overrides={"discretization.n_elements": Override(8, "--n-elements"),
                                              "solver.t_end": 0.25})
    assert spec.model.n_elements == 8 and spec.t_end == 0.25
    (problem,) = problems_with_overrides({"discretization.n_elements": Override(1, "--n-elements")})
    assert problem.line == "--n-elements" and "`n_elements` must be >= 2" in str(problem)
    assert "command line --n-elements" in str(problem)


def problems_with_overrides(overrides):
    with pytest.raises(ScenarioError) as info:
        parse_scenario(MINIMAL, overrides=overrides)
    return info.value.problems


def test_paper_arm_rejects_rod_tables_and_needs_t_end_without_scenario():
    found = problems('arm = "paper"\n[rod]\nlength = 1.0\n')
    texts = " | ".join(map(str, found))
    assert "`rod` cannot be changed" in texts and "missing required key `t_end`" in texts
    (problem,) = problems('arm = "paper"\nscenario = "bendng"\n')
    assert "did you mean 'bending'?" in problem.message and problem.line == 2


def test_toml_syntax_error_has_a_line():
    (problem,) = problems("[rod]\nlength = = 1\n")
    assert problem.line == 2 and "not valid TOML" in problem.message


def test_scenario_error_is_a_parameter_error():
    assert issubclass(ScenarioError, rodmol.ParameterError)


def test_all_anchors_and_markers_beyond_the_tip_are_reported():
    text = MINIMAL + """
[[cable]]
offset = [0.002, 0.0]
anchor = 0.5

[[marker]]
s = 0.4
"""
    found = problems(text)
    lines = text.splitlines()
    expected = [("[[cable]] #1", lines.index("anchor = 0.5") + 1),
                ("[[marker]] #1", lines.index("s = 0.4") + 1)]
    assert [(p.table, p.line) for p in found] == expected
    assert "`anchor` must lie within the rod" in found[0].message


def test_bad_values_of_every_kind_of_table_are_reported_together():
    """Constructors' checks (Material), the Model's (gravity, drag_law, n_elements,
    checked on a stand-in arm when the file's arm is broken) and simulate's (backend):
    all at once, each at its line."""
    text = "gravity = [1, 2]\n" + MINIMAL.replace("E = 1e5", "E = -1").replace(
        "[solver]", "[medium]\ndrag_law = 'quad'\n[discretization]\nn_elements = 1\n[solver]\nbackend = 'rk2'\n")
    found = problems(text)
    lines = text.splitlines()
    at = {p.line: p.message for p in found}
    assert len(found) == 5
    assert "`gravity` must have three components" in at[1]
    assert "`E` must be > 0 Pa" in at[lines.index("E = -1") + 1]
    assert "unknown `drag_law` 'quad'" in at[lines.index("drag_law = 'quad'") + 1]
    assert "`n_elements` must be >= 2" in at[lines.index("n_elements = 1") + 1]
    assert "did you mean 'rk23'?" in at[lines.index("backend = 'rk2'") + 1]


@pytest.mark.parametrize("table, line, python", [
    ("[rod]", "length = -0.3", lambda m: rodmol.Rod(-0.3, 0.01, m)),
    ("[material]", "mu = -10.0", lambda m: rodmol.Material(1e5, 0.5, -10.0, 1000.0)),
    ("[[cable]]", "offset = [0.002, 0.0]\nanchor = 0.3\nfriction = -1.0",
     lambda m: rodmol.Cable((0.002, 0.0), 0.3, name="cable 1", friction=-1.0)),
    ("[[marker]]", "s = 0.1\noffset = [1.0]", lambda m: rodmol.Marker(0.1, (1.0,), name="marker 1")),
    ("[output]", "every = 0", lambda m: rodmol.output.options.OutputOptions(every=0)),
])
def test_a_file_is_refused_with_the_constructors_own_message(table, line, python):
    """Values are checked once, by the classes: the file's message is Python's."""
    material = rodmol.Material(1e5, 0.5, 10.0, 1000.0)
    key = line.split("\n")[-1].split(" =")[0]
    if table in ("[rod]", "[material]"):
        old = next(x for x in MINIMAL.splitlines() if x.startswith(key + " ="))
        text = MINIMAL.replace(old, line)
    else:
        text = MINIMAL + f"\n{table}\n{line}\n"
    (problem,) = problems(text)
    with pytest.raises(rodmol.ParameterError) as expected:
        python(material)
    assert problem.message == str(expected.value) and problem.table.split(" #")[0] == table
    assert problem.line == text.splitlines().index(line.split("\n")[-1]) + 1
