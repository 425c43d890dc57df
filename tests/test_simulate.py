"""simulate builds one system and takes its sizes and default tolerances from it."""

import numpy as np

import rodmol
from rodmol.discretise.system import SemiDiscrete


def test_equilibrium_of_a_built_system_is_the_models():
    model = rodmol.scenarios.get("fetching").model(8)
    for scheme in rodmol.SCHEMES:
        system = SemiDiscrete(model, scheme)
        np.testing.assert_array_equal(rodmol.equilibrium(system, 0.1),
                                      rodmol.equilibrium(model, 0.1, scheme=scheme))


def test_default_atol_is_the_systems_scale_times_rtol_and_simulates_as_the_default():
    model = rodmol.scenarios.get("bending").model(6)
    system = SemiDiscrete(model)
    np.testing.assert_array_equal(rodmol.default_atol(model, 1e-5), 1e-5 * system.atol_scale())
    by_default = rodmol.simulate(model, 0.02, rtol=1e-5)
    given = rodmol.simulate(model, 0.02, rtol=1e-5, atol=rodmol.default_atol(model, 1e-5))
    np.testing.assert_array_equal(by_default.states, given.states)
    assert by_default.stats["steps"] == given.stats["steps"]
