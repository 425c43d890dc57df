"""Every input is checked where it enters, with a rodmol error naming the
parameter and the value (cut when long), before any work is done; the same
rules in Python and in scenario files."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scenario_texts import MINIMAL

import rodmol
from rodmol.errors import MAX_LINE, ParameterError
from rodmol.scenario.file import ScenarioError, parse_scenario

MATERIAL = rodmol.Material(E=110e3, nu=0.5, mu=300.0, rho=1080.0)
ROD = rodmol.Rod(0.3, (0.012, 0.005), MATERIAL)
MODEL = rodmol.Model(ROD, 6)


def refused(match, function, *args, **kwargs):
    with pytest.raises(ParameterError, match=match) as info:
        function(*args, **kwargs)
    return str(info.value)


@pytest.mark.parametrize("value", [True, np.bool_(False), "1e5", None, 10**400])
def test_material_refuses_non_numbers(value):
    refused(r"`E` must be a number", rodmol.Material, E=value, nu=0.5, rho=1000.0)


def test_marker_off_the_body():
    message = refused(r"marker 'far'.*lies outside the body", rodmol.Model, ROD, 6,
                      markers=[rodmol.Marker(0.1, offset=(1.0, 0.0), name="far")])
    assert "|p| = 1 m" in message
    rodmol.Model(ROD, 6, markers=[rodmol.Marker(0.3, offset=(0.0, 0.005))])  # on the surface: fine


def test_duplicate_cable_names():
    cables = [rodmol.Cable((0.004, 0.0), 0.2, name="a"), rodmol.Cable((-0.004, 0.0), 0.2, name="a")]
    refused("two cables are named 'a'", rodmol.Model, ROD, 6, cables=cables)


@pytest.mark.parametrize("options, match", [
    (dict(rtol=2.0), r"`rtol` must lie in \[1e-14, 0.1\], got 2.0"),
    (dict(rtol=0.0), r"`rtol` must be > 0"),
    (dict(max_order=9), r"`max_order` must be an integer in \[1, 5\], got 9"),
    (dict(max_order=2.5), r"`max_order` must be an integer"),
    (dict(max_step=-1), r"`max_step` must be >= 0"),
    (dict(max_nonlin_iters=0), r"`max_nonlin_iters` must be >= 1"),
    (dict(progress=5), r"`progress` must be True, False, None or a callable"),
    (dict(max_wall_time=-1.0), r"`max_wall_time` must be > 0"),
    (dict(linsolvr="band"), r"unknown option `linsolvr` for backend 'cvode'; did you mean 'linsolver'\?"),
    (dict(linsolver="bnd"), r"unknown `linsolver` 'bnd'; did you mean 'band'\?"),
    (dict(outputdt=0.1), r"unknown option `outputdt`.*did you mean 'output_dt'\?"),
    (dict(backend="rk23", linsolver="band"), r"unknown option `linsolver` for backend 'rk23'"),
    (dict(initial="equilibirum"), r"unknown `initial` 'equilibirum'; did you mean 'equilibrium'\?"),
    (dict(output_dt=1e-15), r"asks for 1e\+15 output frames; at most \d+ are allowed"),
    (dict(atol=[1.0] * 100_000), r"`atol` must have length"),
])
def test_simulate_refuses_before_any_work(options, match, checks_only):
    # Starting any work (building the system, the equilibrium) raises ChecksPassed: the test fails.
    refused(match, rodmol.simulate, MODEL, 1.0, **options)


def test_huge_end_time_is_refused_before_allocating():
    refused(r"t_end = 1e\+300 s with output_dt = 0.01 s asks for 1e\+302 output frames",
            rodmol.simulate, MODEL, 1e300)


def test_long_values_are_cut_in_messages():
    message = refused(r"knot times must increase", rodmol.Cable, (0.004, 0.0), 0.2,
                      tension=[[0.0, 1.0]] * 100_000)
    assert len(message) < 2 * MAX_LINE
    message = refused(r"`E` must be a number", rodmol.Material, E=list(range(100_000)), nu=0.5, rho=1.0)
    assert len(message) < 2 * MAX_LINE and "characters)" in message


def test_time_function_with_defaults_is_not_a_feedback_law():
    cable = rodmol.Cable((0.004, 0.0), 0.2, tension=lambda t, gain=2.0: gain * t)
    assert not cable.tension.feedback and cable.tension_at(0.5) == 1.0
    law = rodmol.Cable((0.004, 0.0), 0.2, tension=lambda t, state, gain=2.0: gain)
    assert law.tension.feedback


@pytest.mark.parametrize("content, match", [
    (b"t,T\n0,\xff\xfe1\n", "not UTF-8"),
    (b"t,T\n0,1\n0,2\n", "does not increase"),
])
def test_bad_tension_tables(tmp_path, content, match):
    path = tmp_path / "tension.csv"
    path.write_bytes(content)
    refused(match, rodmol.Cable, (0.004, 0.0), 0.2, tension=path)


def test_nul_byte_paths():
    refused("embedded null byte", rodmol.Cable, (0.004, 0.0), 0.2, tension="a\0b.csv")


# ------------------------------------------------------------------ scenario files

@pytest.mark.parametrize("extra, match", [
    ("rtol = 2.0", r"\[solver\] `rtol` must lie in \[1e-14, 0.1\], got 2.0"),
    ("output_dt = 1e-15", r"output frames; at most \d+ are allowed"),
    ("max_wall_time = -2.0", r"`max_wall_time` must be > 0 s"),
    ("initial = \"equilibirum\"", r"did you mean 'equilibrium'\?"),
    ("rtool = 1e-6", r"unknown key `rtool`; did you mean `rtol`\?"),
    # an array: the state's size, as in Python (N = 100 here)
    ("atol = [" + ", ".join(["1.0"] * 100_000) + "]", r"\[solver\] `atol` must have length \d+ \(the state size\)"),
])
def test_scenario_solver_rules_match_python(extra, match):
    with pytest.raises(ScenarioError, match=match) as info:
        parse_scenario(MINIMAL.replace("[solver]", "[solver]\n" + extra))
    assert all(len(line) <= MAX_LINE + 40 for line in str(info.value).splitlines())


def test_scenario_max_wall_time_reaches_simulate():
    spec = parse_scenario(MINIMAL.replace("[solver]", "[solver]\nmax_wall_time = 30.0"))
    assert spec.solver["max_wall_time"] == 30.0


@pytest.mark.parametrize("text, line", [
    ("x = " + "[" * 3000 + "]" * 3000, 1),
    ('a = 1\n[t]\nb = "[[[[" # [[\nx = [\n' + "[\n" * 1500 + "{y = " + "[" * 1500 + "]" * 1501 + "}" + "]" * 1500,
     1505),  # the deepest line, past a string and a comment holding brackets and 1500 lines of "["
])
def test_scenario_nested_too_deeply(text, line):
    with pytest.raises(ScenarioError, match=rf"s.toml:{line}: not a scenario: arrays or inline tables nested too deeply"):
        parse_scenario(text, source="s.toml")


@given(before=st.integers(0, 4), after=st.integers(0, 4), output_dt=st.booleans(), huge=st.sampled_from(["t_end", "both"]))
@settings(max_examples=20, deadline=None, derandomize=True)
def test_scenario_too_many_frames_cites_the_line_of_t_end(before, after, output_dt, huge):
    """The message opens with t_end: it cites t_end's line, not the output_dt beside it."""
    others = ["rtol = 1e-4", 'initial = "straight"', 'backend = "cvode"', "max_wall_time = 100.0"]
    solver = ["# a comment"] * before + ["t_end = 1e12  # s"] + others[:after]
    if output_dt:
        solver.insert(before + 1, "output_dt = 1e-3" if huge == "both" else "output_dt = 0.01")
    text = MINIMAL.replace("t_end = 1.0\n", "\n".join(solver) + "\n")
    line = text.splitlines().index("t_end = 1e12  # s") + 1
    with pytest.raises(ScenarioError, match=rf"s.toml:{line}: \[solver\] t_end = 1000000000000.0 s with output_dt"):
        parse_scenario(text, source="s.toml")


def test_scenario_marker_off_the_body():
    text = MINIMAL + '[[marker]]\nname = "far"\ns = 0.1\noffset = [1.0, 0.0]\n'
    with pytest.raises(ScenarioError, match=r"marker 'far'.*lies outside the body"):
        parse_scenario(text)


def test_scenario_output_directory_with_nul():
    with pytest.raises(ScenarioError, match="without NUL characters"):
        parse_scenario(MINIMAL + '[output]\ndirectory = "a\\u0000b"\n')


@pytest.mark.parametrize("options, match", [
    (dict(cables=5), r"`cables` must be a sequence, each item a rodmol.Cable, got 5"),
    (dict(cables=rodmol.Cable((0.004, 0.0), 0.2)), r"`cables` must be a sequence \(a single one: cables=\[...\]\)"),
    (dict(markers=0.1), r"`markers` must be a sequence, each item a rodmol.Marker, got 0.1"),
    (dict(loads=None), r"`loads` must be a sequence"),
    (dict(drag="no"), r"`drag` must be True or False, got 'no'"),
    (dict(drag_law=np.array([1.0, 2.0])), r"unknown `drag_law` array"),
])
def test_model_refuses_wrong_types(options, match):
    refused(match, rodmol.Model, ROD, 6, **options)


@pytest.mark.parametrize("out", ["", "  "])
def test_an_empty_output_directory_is_refused_before_any_work(out, tmp_path, monkeypatch):
    """Path("") is the current directory: a run streamed there by an empty name was never meant."""
    monkeypatch.chdir(tmp_path)
    model = rodmol.scenarios.get("bending").model(4)
    system = rodmol.System({"arm": model})
    for run in (model, system):
        with pytest.raises(rodmol.ParameterError, match="`out` must name a directory"):
            rodmol.simulate(run, 0.01, out=out, overwrite=True)
    assert not any(tmp_path.iterdir())
