"""Property: whatever is done to a shipped scenario file, the parser returns a
scenario or raises rodmol's own ScenarioError (never a raw Python error, a
hang or a huge allocation)."""

import re
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from rodmol.run_spec import RunSpec
from rodmol.scenario.file import ScenarioError, parse_scenario

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
TEXTS = {path.name: path.read_text(encoding="utf-8") for path in sorted(EXAMPLES.glob("*.toml"))}
ASSIGNMENT = re.compile(r"^(\s*[A-Za-z0-9_\"'.-]+\s*=\s*)(.*)$")
SETTINGS = settings(max_examples=40, deadline=None, derandomize=True,
                    suppress_health_check=[HealthCheck.too_slow])

#: TOML values of every type and size, edge cases included.
scalars = st.one_of(
    st.integers(min_value=-10**20, max_value=10**20).map(str),
    st.sampled_from(["0", "-1", "1e308", "-1e-320", "nan", "inf", "-inf", "1e300", "2", "1000000000",
                     "true", "false", '""', '"water"', '"a\\u0000b"', '"../../etc"', '"bending"',
                     "1979-05-27", "[]", "{}", "[[]]", '["x"]', "{ a = 1 }", "[1.0, 2.0]",
                     "[0.0, 1.0, 2.0]", "[[0.0, 0.0], [1.0, 1.0]]", "[[1.0, 0.0], [0.0, 1.0]]"]),
    st.floats(allow_nan=False, allow_infinity=False).map(repr),
    st.text(alphabet=st.characters(codec="utf-8", exclude_characters='"\\\n\r'), max_size=8)
    .map(lambda s: f'"{s}"'),
)
values = st.recursive(scalars, lambda inner: st.lists(inner, max_size=4).map(
    lambda items: "[" + ", ".join(items) + "]"), max_leaves=8)


def assignments(lines):
    return [i for i, line in enumerate(lines) if ASSIGNMENT.match(line)]


def check(text):
    try:
        spec = parse_scenario(text, base_dir=EXAMPLES, source="<mutated>")
    except ScenarioError as exc:
        assert str(exc).startswith("<mutated>: ")
        return
    assert isinstance(spec, RunSpec)


@pytest.mark.parametrize("name", sorted(TEXTS))
@SETTINGS
@given(data=st.data())
def test_replaced_values(name, data):
    lines = TEXTS[name].splitlines()
    for _ in range(data.draw(st.integers(1, 3))):
        i = data.draw(st.sampled_from(assignments(lines)))
        lines[i] = ASSIGNMENT.match(lines[i]).group(1) + data.draw(values)
    check("\n".join(lines))


@pytest.mark.parametrize("name", sorted(TEXTS))
@SETTINGS
@given(data=st.data())
def test_lines_dropped_duplicated_or_cut(name, data):
    lines = TEXTS[name].splitlines()
    for _ in range(data.draw(st.integers(1, 4))):
        i = data.draw(st.integers(0, len(lines) - 1))
        action = data.draw(st.sampled_from(["drop", "duplicate", "cut", "insert"]))
        if action == "drop":
            del lines[i]
        elif action == "duplicate":
            lines.insert(i, lines[i])
        elif action == "cut":
            lines[i] = lines[i][:data.draw(st.integers(0, len(lines[i])))]
        else:
            lines.insert(i, data.draw(st.text(max_size=30)))
        if not lines:
            lines = [""]
    check("\n".join(lines))


@SETTINGS
@given(st.binary(max_size=200))
def test_bytes_that_are_no_scenario(raw):
    check(raw.decode("utf-8", errors="replace"))
