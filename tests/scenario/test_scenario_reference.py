"""docs/scenario-reference.md against the one source of the scenario's keys,
rodmol.scenario.tables (itself read from the constructors' signatures)."""

import inspect
import re
from pathlib import Path

import pytest
from scenario_texts import MINIMAL

import rodmol
from rodmol.scenario import tables
from rodmol.scenario.file import parse_scenario

REFERENCE = Path(__file__).resolve().parents[2] / "docs" / "scenario-reference.md"


def sections(text):
    """{section title: its text} of the ``## `...` `` sections."""
    parts = re.split(r"^## ", text, flags=re.M)[1:]
    return {part.split("\n", 1)[0].strip(): part for part in parts}


def documented_keys(section):
    """The keys a section's tables name in their first column (`` `Cy`, `Cz` `` rows too)."""
    keys = set()
    for line in section.splitlines():
        if line.startswith("| `"):
            first = line.split("|")[1]
            keys.update(re.findall(r"`([A-Za-z_]+)`", first))
    return keys


def gaps(documented, table):
    """(keys the table takes but the reference does not name, names that are no key)."""
    names = set(table.names())
    return sorted(names - documented), sorted(documented - names)


SECTIONS = sections(REFERENCE.read_text(encoding="utf-8"))


@pytest.mark.parametrize("name", [n for n in tables.TABLES if n not in ("cable", "load", "contact")])
def test_each_table_documents_exactly_its_constructors_keys(name):
    title = f"`[[{name}]]`" if name in tables.ARRAYS else f"`[{name}]`"
    section = next(text for head, text in SECTIONS.items() if head.startswith(title))
    assert gaps(documented_keys(section), tables.TABLES[name]) == ([], [])


def test_cables_document_the_full_and_the_paper_arm_forms():
    section = next(text for head, text in SECTIONS.items() if head.startswith("`[[cable]]`"))
    both = tables.Table(tables.CABLE.sources + tables.PAPER_CABLE.sources, own=tables.PAPER_CABLE.own)
    assert gaps(documented_keys(section), both) == ([], [])


def test_top_level_documents_its_keys_and_lists_every_table():
    section = next(text for head, text in SECTIONS.items() if head.startswith("Top level"))
    scalars = set(tables.TOP.names()) - (set(tables.TABLES) - {"medium"})
    assert sorted(documented_keys(section)) == sorted(scalars)
    listed = re.search(r"^Tables: (.*?)\.$", section, flags=re.M | re.S).group(1)
    assert set(re.findall(r"`\[+(\w+)\]+`", listed)) == set(tables.TABLES)


def assert_documents_types(heading, types):
    """The section ``heading`` lists every type of ``types`` with its required keys, and documents
    every key of them; returns the section and the table of all their keys."""
    section = next(text for head, text in SECTIONS.items() if head.startswith(heading))
    rows = {m.group(1): m.group(2) for m in re.finditer(r'^\| `"(\w+)"` \| `\w+` \| ([^|]*) \|', section, re.M)}
    assert set(rows) == set(types)
    for kind, table in types.items():
        assert set(re.findall(r"`(\w+)`", rows[kind])) == set(table.required()), kind
    every = tables.Table(tuple(s for t in types.values() for s in t.sources), own=("type",))
    assert gaps(documented_keys(section), every) == ([], [])
    return section, every


def test_loads_document_every_type_its_required_keys_and_every_key():
    assert_documents_types("`[[load]]`", tables.LOADS)


def test_rod_contacts_document_every_type_its_required_keys_and_every_key():
    section, every = assert_documents_types("`[[contact]]`", tables.CONTACTS)
    for match in re.finditer(r"^\| `(\w+)` \| [^|]* \| `([-\w.\"]+)` \|", section, re.M):
        key, shown = match.groups()
        assert float(shown) == every.default(key), key


def test_a_new_constructor_parameter_is_a_new_key_and_a_reference_gap():
    """What a new parameter costs: nothing in the reader; the reference test names it."""
    signature = inspect.signature(rodmol.Rod)
    grown_rod = lambda *args, **kwargs: None  # noqa: E731 (a stand-in for a Rod that gained a parameter)
    grown_rod.__signature__ = signature.replace(parameters=[
        *signature.parameters.values(),
        inspect.Parameter("taper_exponent", inspect.Parameter.KEYWORD_ONLY, default=1.0)])
    grown = tables.Table((tables.Source(grown_rod, skip=("material",)),))
    assert grown.names() == tables.ROD.names() + ("taper_exponent",)
    assert grown.required() == tables.ROD.required()
    section = next(text for head, text in SECTIONS.items() if head.startswith("`[rod]`"))
    assert gaps(documented_keys(section), grown) == (["taper_exponent"], [])


def test_every_documented_default_of_a_key_that_has_one_is_the_constructors():
    """The defaults the reference shows in its `default` columns are the signatures'."""
    checked = 0
    for name, table in tables.TABLES.items():
        head = f"`[[{name}]]`" if name in tables.ARRAYS else f"`[{name}]`"
        section = next((text for title, text in SECTIONS.items() if title.startswith(head)), "")
        for match in re.finditer(r"^\| `(\w+)` \| [^|]* \| `([-\w.\"]+)` \|", section, re.M):
            key, shown = match.groups()
            default = table.default(key) if table and key in table.parameters() else None
            if isinstance(default, bool):
                assert shown == str(default).lower(), (name, key)
            elif isinstance(default, (int, float)):
                assert float(shown) == default, (name, key)
            elif isinstance(default, str):
                assert shown == f'"{default}"', (name, key)
            else:
                continue
            checked += 1
    assert checked >= 10


def test_every_cable_parameter_reaches_the_cable():
    """Each [[cable]] key (a Cable parameter) lands in the built Cable as the
    Python argument would."""
    spec = parse_scenario(MINIMAL + """
[[cable]]
name = "c"
offset = [0.02, 0.0]
anchor = 0.25
outside_body = true
displacement = -0.001
compliance = 1e-3
base_to_actuator = 0.1
rest_length = 0.4
friction = 0.1
slip_speed = 2e-4
""")
    (cable,) = spec.model.cables
    assert (cable.name, cable.offset, cable.anchor, cable.outside_body) == ("c", (0.02, 0.0), 0.25, True)
    assert (cable.compliance, cable.base_to_actuator, cable.rest_length) == (1e-3, 0.1, 0.4)
    assert (cable.friction, cable.slip_speed) == (0.1, 2e-4)
