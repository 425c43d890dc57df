"""Named parameters (rodmol.named_parameters): which keys are parameters, their values,
the model rebuilt at other values, and the two models of a central difference."""

import numpy as np
import pytest

import rodmol
from rodmol import named_parameters
from rodmol.discretise.assembly import Assembly
from rodmol.discretise.system import SemiDiscrete
from rodmol.errors import ParameterError

KNOTS = [(0.0, 0.0), (0.2, 2.0), (0.5, 2.0)]


def _arm():
    return rodmol.paper_arm(8, tensions={11: KNOTS})


def _system():
    material = rodmol.Material(E=1e5, nu=0.5, mu=300.0, rho=1080.0)
    cable = rodmol.Cable((0.005, 0.0), 0.2, name="c", tension=[(0.0, 0.0), (0.1, 0.2)])
    arm = rodmol.Model(rodmol.Rod(0.2, radius=0.01, material=material), 6, cables=[cable])
    head = rodmol.RigidBody(0.05, (2e-5, 3e-5, 4e-5))
    return rodmol.System({"arm": arm}, {"head": head}, [rodmol.Joint(("head", (0.02, 0, 0)), ("arm", "base"))])


@pytest.mark.parametrize("key, value, unit", [
    ("material.E", [1.1e5], "Pa"), ("medium.Cy,Cz", [2.5], "-"), ("tension.11", [0.0, 2.0, 2.0], "N"),
    ("tension.cable 3", [0.0], "N"), ("material.nu", [0.5], "-")])
def test_a_rods_parameters_have_the_models_values(key, value, unit):
    p = named_parameters.parameter(_arm(), key)
    np.testing.assert_allclose(p.value, value)
    assert p.unit == unit and p.size == len(value)


def test_a_knot_tension_is_one_value_per_knot_and_rebuilds_the_input():
    arm = _arm()
    p = named_parameters.parameter(arm, "tension.11")
    np.testing.assert_array_equal(p.knots, [0.0, 0.2, 0.5])
    other = p.at(arm, [0.0, 1.0, 3.0])
    assert other.cables[10].tension_at(0.1) == pytest.approx(0.5)  # halfway up the first ramp to 1 N
    assert other.cables[10].tension_at(0.35) == pytest.approx(2.0)
    assert arm.cables[10].tension_at(0.35) == pytest.approx(2.0) and arm.cables[10].tension_at(0.1) == 1.0


def test_rebuilt_model_changes_the_rates_and_leaves_the_original():
    arm = _arm()
    system = SemiDiscrete(arm)
    y = system.undeformed_state()
    y[system.layout.field(np.arange(system.size), "k")[:, 2]] = 1.0  # bent: the stiffness acts
    before = system(0.3, y).copy()
    stiffer = SemiDiscrete(named_parameters.parameter(arm, "material.E").at(arm, 2.2e5))
    assert stiffer.model.rod.material.E == 2.2e5 and arm.rod.material.E == 1.1e5
    assert not np.allclose(stiffer(0.3, y), before)
    np.testing.assert_array_equal(system(0.3, y), before)


def test_a_comma_key_sets_every_field_to_one_value():
    arm = _arm()
    other = named_parameters.parameter(arm, "medium.Cy,Cz").at(arm, 3.0)
    assert (other.medium.Cy, other.medium.Cz, other.medium.Cx) == (3.0, 3.0, arm.medium.Cx)


def test_the_pair_of_a_central_difference_stays_inside_the_fields_interval():
    arm = _arm()
    # A zero tension knot: both values >= 0 (the pair moves up by h); nu = 0.5: both <= 0.5.
    p = named_parameters.parameter(arm, "tension.11")
    up, down, h = p.pair(arm, 0)
    assert h == pytest.approx(2e-6)
    np.testing.assert_allclose([up.cables[10].tension_at(0.0), down.cables[10].tension_at(0.0)], [2 * h, 0.0])
    up, down, h = named_parameters.parameter(arm, "material.nu").pair(arm)
    assert (up.rod.material.nu, down.rod.material.nu) == (0.5, pytest.approx(0.5 - 2 * h))
    up, down, h = named_parameters.parameter(arm, "material.E").pair(arm)
    np.testing.assert_allclose([up.rod.material.E - 1.1e5, 1.1e5 - down.rod.material.E], [h, h], rtol=1e-6)


def test_a_systems_parameters_name_their_part():
    system = _system()
    mass = named_parameters.parameter(system, "bodies.head.mass")
    assert mass.unit == "kg" and mass.value[0] == 0.05
    heavier = mass.at(system, 0.06)
    assert heavier.given_bodies["head"].mass == 0.06
    Assembly(heavier)  # builds without compiling anything new
    p = named_parameters.parameter(system, "rods.arm.tension.c")
    np.testing.assert_allclose(p.value, [0.0, 0.2])
    assert p.at(system, [0.0, 0.4]).given_rods["arm"].cables[0].tension_at(0.1) == pytest.approx(0.4)
    assert named_parameters.parameter(system, "bodies.head.inertia.1").value[0] == pytest.approx(3e-5)
    assert named_parameters.parameter(system, "rods.arm.material.E").value[0] == 1e5


@pytest.mark.parametrize("key, words", [
    ("discretization.n_elements", "the grid is structure"), ("discretization.scheme", "structure"),
    ("solver.rtol", "setting of the run"), ("medium.drag", "switch"), ("material.Q", "did you mean 'material.G'"),
    ("tension.99", "no cable named '99'"), ("medium.Cx,Cy", "fields differ"), (3, "dotted name")])
def test_what_is_not_a_parameter_is_refused_naming_the_key(key, words):
    with pytest.raises(ParameterError, match=words):
        named_parameters.parameters(_arm(), [key])


def test_a_tension_without_values_and_a_key_given_twice_are_refused():
    arm = rodmol.paper_arm(8, tensions={11: lambda t: 1.0})
    with pytest.raises(ParameterError, match="'tension.11'.*only knots"):
        named_parameters.parameters(arm, ["tension.11"])
    with pytest.raises(ParameterError, match="given twice"):
        named_parameters.parameters(arm, ["medium.Cy", "medium.Cy,Cz"])
    with pytest.raises(ParameterError, match="(?s)bodies.head.inertia.*component"):
        named_parameters.parameters(_system(), ["bodies.head.inertia"])
    with pytest.raises(ParameterError, match="rods.arm.discretization.n_elements.*structure"):
        named_parameters.parameters(_system(), ["rods.arm.discretization.n_elements"])
