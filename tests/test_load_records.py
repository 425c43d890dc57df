"""The load kinds' records (rodmol.loads.KERNELS, SCENARIO_TYPES) and the
floors: the problem's nouns import nothing from discretise/, and what a
record says about a kind is what its compiled branch does."""

import ast
from pathlib import Path

import numpy as np
import pytest

import rodmol
from rodmol import loads
from rodmol.arm import paper_rod
from rodmol.discretise import external, load_entries
from rodmol.scenario import tables

NOUNS = ("rod", "parameters", "cables", "cable_routing", "load_kinds", "loads", "holds", "markers", "base_motion", "inputs",
         "model")


@pytest.mark.parametrize("noun", NOUNS)
def test_the_problem_imports_nothing_from_discretise(noun):
    path = Path(rodmol.__file__).parent / f"{noun}.py"
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.ImportFrom):
            module = "." * node.level + (node.module or "")
            assert "discretise" not in module, f"{noun}.py imports {module}"


@pytest.mark.parametrize("name", [n for n, k in loads.KERNELS.items() if k.quantity in ("force", "moment")])
def test_a_vector_kernel_writes_the_quantity_its_record_names(name):
    """Straight, unrotated section: dead and follower loads give the value
    itself, as a force or as a moment as the record says (the load scale adds
    it up as such)."""
    kernel = loads.KERNELS[name]
    value = (0.3, -1.2, 2.5)
    force, moment = external.load(kernel.code, np.zeros(loads.N_PARAMS), value, (0.1, 0.0, 0.0),
                                  (1.0, 0.0, 0.0, 0.0), (0.0, 0.0, 0.0), (0.0, 0.0, 0.0))
    written, other = (force, moment) if kernel.quantity == "force" else (moment, force)
    np.testing.assert_array_equal(written, value)
    np.testing.assert_array_equal(other, 0.0)


def test_kernel_codes_are_distinct_and_every_code_has_its_dependencies():
    codes = [k.code for k in loads.KERNELS.values()]
    assert sorted(codes) == list(range(len(codes)))
    assert {k.code: k.depends for k in loads.KERNELS.values()} == external.DEPENDS


@pytest.mark.parametrize("kind", list(loads.SCENARIO_TYPES))
def test_every_scenario_key_with_a_unit_has_it(kind):
    table = tables.LOADS[kind]
    assert set(table.required()) <= set(table.names()) and "name" in table.names()
    assert set(table.units) == set(table.names()) - {"type", "frame", "name"}


def test_load_scale_adds_point_forces_and_moments_over_length():
    """No weight, no cables: the scale is |F| + |M| / L, whatever nodes share
    the point loads (shares off the base sum to one)."""
    rod = paper_rod()
    model = rodmol.Model(rod, 10, gravity=(0.0, 0.0, 0.0), loads=[
        rodmol.PointForce(s=0.237, force=(0.0, 3.0, 4.0)),
        rodmol.PointMoment(s=rod.length, moment=(0.0, 0.0, 2.0), frame="local")])
    grid = load_entries.of_model(model)
    assert list(grid.node) == [5, 6, 10]
    np.testing.assert_allclose(load_entries.load_scale(model), 5.0 + 2.0 / rod.length, rtol=1e-13)


def test_a_point_load_near_the_base_loses_its_share_to_the_clamp():
    rod = paper_rod()
    model = rodmol.Model(rod, 10, gravity=(0.0, 0.0, 0.0),
                         loads=[rodmol.PointForce(s=0.25 * rod.length / 10, force=(0.0, 1.0, 0.0))])
    grid = load_entries.of_model(model)
    assert list(grid.node) == [1]
    np.testing.assert_allclose(grid.weight * model.ds, [0.25], rtol=1e-13)

