"""Issue 14's options in scenario files: per-component viscosity, the
componentwise drag law, routed, displacement-controlled and rubbing cables."""

import importlib.util
from pathlib import Path

import numpy as np
import pytest
from scenario_texts import MINIMAL

from rodmol.discretise.sampling import SAMPLED, Sampled
from rodmol.scenario.file import ScenarioError, load_scenario, parse_scenario

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


def test_till_scenario_file_is_the_python_example():
    spec = load_scenario(EXAMPLES / "till_tendon_robot.toml")
    loader = importlib.util.spec_from_file_location("till", EXAMPLES / "till_tendon_robot.py")
    module = importlib.util.module_from_spec(loader)
    loader.loader.exec_module(module)
    ours, ref = spec.model, module.model(50)
    for attribute in ("s_nodes", "gravity"):
        np.testing.assert_allclose(getattr(ours, attribute), getattr(ref, attribute), rtol=1e-14,
                                   err_msg=attribute)
    for attribute in SAMPLED:
        np.testing.assert_allclose(getattr(Sampled(ours), attribute), getattr(Sampled(ref), attribute),
                                   rtol=1e-14, err_msg=attribute)
    assert ours.drag_law == "componentwise"
    (a,), (b,) = ours.cables, ref.cables
    for key in ("offset", "anchor", "outside_body", "compliance", "base_to_actuator", "rest_length", "friction"):
        assert getattr(a, key) == getattr(b, key), key
    for t in (0.0, 3.8, 10.0, 17.8, 25.0):
        assert a.displacement.value(t) == b.displacement.value(t)


def test_routing_and_friction_keys():
    text = MINIMAL + """
[[cable]]
name = "helix"
offset = [[0.0, 0.005, 0.0], [0.15, 0.0, 0.005], [0.3, -0.005, 0.0]]
anchor = 0.3
tension = 1.0
friction = 0.2
slip_speed = 1e-3
"""
    cable = parse_scenario(text).model.cables[0]
    assert cable.offset == ((0.0, 0.005, 0.0), (0.15, 0.0, 0.005), (0.3, -0.005, 0.0))
    assert cable.friction == 0.2 and cable.slip_speed == 1e-3


@pytest.mark.parametrize("extra, needle", [
    ("[[cable]]\noffset = [0.02, 0.0]\nanchor = 0.3\n", "outside_body=True"),
    ("[[cable]]\noffset = [0.002, 0.0]\nanchor = 0.3\ndisplacement = -0.01\n", "compliance"),
    ("[[cable]]\noffset = [0.002, 0.0]\nanchor = 0.3\ndisplacement = 0.0\ncompliance = -1.0\n", "compliance"),
    ("[[cable]]\noffset = [[0.0, 0.002]]\nanchor = 0.3\n", "offset"),
    ("[medium]\ndrag_law = \"quadratic\"\n", "drag_law"),
    ("[medium]\ndrag_law = \"componentwise\"\n", "drag_coefficients"),
])
def test_bad_new_keys_are_reported(extra, needle):
    with pytest.raises(ScenarioError) as info:
        parse_scenario(MINIMAL + extra, source="s.toml")
    assert needle in str(info.value), str(info.value)


def test_bad_viscosity_table_is_reported():
    text = MINIMAL.replace("mu = 10.0", "mu = 10.0\nviscosity = { shear = [1.0, 1.0, 1.0] }")
    with pytest.raises(ScenarioError) as info:
        parse_scenario(text, source="s.toml")
    assert "viscosity" in str(info.value) and "shear_extension" in str(info.value)
