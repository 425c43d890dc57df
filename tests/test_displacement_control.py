"""Displacement-controlled cables (``Cable(displacement=..., compliance=...)``):
the tendon law T = max(0, (path + base_to_actuator - l) / (l C)), l = rest
length + z, in statics and in the Result's actuator-space records."""

import numpy as np
import pytest

import rodmol

L, RADIUS, OFFSET = 0.3, 0.01, 0.005
COMPLIANCE, BASE_TO_ACTUATOR, PULL = 1e-3, 0.05, 0.01
ROD = rodmol.Rod(L, RADIUS, rodmol.Material(E=1e6, nu=0.5, mu=100.0, rho=1000.0))


def _cable(displacement, **extra):
    return rodmol.Cable((OFFSET, 0.0), L, displacement=displacement, compliance=COMPLIANCE,
                        base_to_actuator=BASE_TO_ACTUATOR, name="motor", **extra)


def path_length(model, y):
    """Independent: sum over cells of ds |q + k x p| (constant offset, anchor at the tip)."""
    lay = rodmol.StateLayout(model.n_elements)
    c = lay.field(y, "q") + np.cross(lay.field(y, "k"), [0.0, OFFSET, 0.0])
    return model.ds * np.sum(np.linalg.norm(c, axis=1))


def test_pulling_the_actuator_shortens_the_path_by_dz_minus_the_tendon_stretch():
    model = rodmol.Model(ROD, 20, cables=[_cable([(0.0, 0.0), (1.0, -PULL)])])
    system = rodmol.SemiDiscrete(model)
    rest = L + BASE_TO_ACTUATOR  # default rest length: straight path + base to actuator
    lengths, stretches = [], []
    for t, z in ((0.0, 0.0), (1.0, -PULL)):
        y = rodmol.equilibrium(model, t)
        tension = system.tensions(t, y)[0]
        # Independent of the tendon law: the same rod pulled by that tension rests in that state.
        twin = rodmol.Model(ROD, 20, cables=[rodmol.Cable((OFFSET, 0.0), L, tension=tension)])
        np.testing.assert_allclose(rodmol.equilibrium(twin), y, atol=1e-8)
        free = rest + z
        lengths.append(path_length(model, y))
        stretches.append(COMPLIANCE * free * tension)
        assert tension > 0.5  # taut under gravity already at z = 0
        # The state obeys the tendon law to the closed loop's tolerance.
        assert tension == pytest.approx((lengths[-1] + BASE_TO_ACTUATOR - free) / (free * COMPLIANCE), rel=1e-8)
    shortening = lengths[0] - lengths[1]
    print(f"\npath {lengths} m, tendon stretch {stretches} m: shortened by {shortening:.9f} m "
          f"= dz - stretch change {PULL - (stretches[1] - stretches[0]):.9f} m")
    assert shortening == pytest.approx(PULL - (stretches[1] - stretches[0]), abs=1e-10)
    assert stretches[1] > stretches[0]  # a real correction, not round-off
    assert stretches[1] - stretches[0] > 100 * 1e-10


def test_a_slack_cable_leaves_the_arm_as_without_it():
    slack = rodmol.Model(ROD, 10, cables=[_cable(0.02)])  # actuator let out by 2 cm
    free = rodmol.Model(ROD, 10)
    y = rodmol.equilibrium(slack)
    assert rodmol.SemiDiscrete(slack).tensions(0.0, y)[0] == 0.0
    np.testing.assert_allclose(y, rodmol.equilibrium(free), atol=1e-10)


def test_result_records_actuator_space_quantities():
    model = rodmol.Model(ROD, 10, cables=[_cable([(0.0, 0.0), (0.2, -PULL)]),
                                          rodmol.Cable((0.0, OFFSET), L, 0.3, name="pulled")])
    result = rodmol.simulate(model, 0.4, output_dt=0.1)
    assert result.success, result.message
    lengths = [path_length(model, y) for y in result.states]
    np.testing.assert_allclose(result.cable_lengths[:, 0], lengths, rtol=1e-12)
    np.testing.assert_allclose(result.actuator_positions[:, 0], [0.0, -0.005, -0.01, -0.01, -0.01])
    assert result.actuator_positions.shape == (5, 1) and result.meta["actuators"] == ["motor"]
    free = L + BASE_TO_ACTUATOR + result.actuator_positions[:, 0]
    law = np.maximum(0.0, (result.cable_lengths[:, 0] + BASE_TO_ACTUATOR - free) / (free * COMPLIANCE))
    np.testing.assert_allclose(result.tensions[:, 0], law, rtol=1e-12)
    np.testing.assert_allclose(result.tensions[:, 1], 0.3)


@pytest.mark.parametrize("options, match", [
    (dict(displacement=0.0), "compliance"),
    (dict(displacement=0.0, compliance=-1.0), "compliance"),
    (dict(displacement=0.0, compliance=1e-4, base_to_actuator=-0.1), "base_to_actuator"),
    (dict(displacement=0.0, compliance=1e-4, tension=1.0), "either `tension` or `displacement`"),
    (dict(compliance=1e-4), "compliance"),
    (dict(base_to_actuator=0.1), "base_to_actuator"),
    (dict(displacement="no_such_file.csv", compliance=1e-4), "no_such_file"),
    (dict(displacement=[(0.0, 0.0), (0.0, 1.0)], compliance=1e-4), "displacement"),
    (dict(friction=-0.1), "friction"),
    (dict(slip_speed=0.0), "slip_speed"),
])
def test_bad_cable_options_are_refused(options, match):
    with pytest.raises(rodmol.ParameterError, match=match):
        rodmol.Cable((OFFSET, 0.0), L, name="c", **options)
