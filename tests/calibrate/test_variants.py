"""Dotted overrides applied to a checked run."""

import pickle

import numpy as np
import pytest

import rodmol
from rodmol import ParameterError
from rodmol.calibrate.variants import apply, current, spec_of
from rodmol.discretise.sampling import Sampled


def base():
    return spec_of(rodmol.paper_arm(10, tensions={11: [(0.0, 0.0), (1.0, 2.0)]}), 1.0, output_dt=0.1)


def test_material_medium_switches_and_solver():
    spec = apply(base(), {"material.E": 90e3, "material.mu": 0.0, "medium.Cy,Cz": 3.0,
                          "medium.drag": False, "discretization.n_elements": 12, "solver.t_end": 2.0,
                          "solver.rtol": 1e-7})
    m = spec.model
    assert m.rod.material.E == 90e3 and m.rod.material.nu == 0.5 and m.rod.material.G == 30e3
    assert np.all(Sampled(m).vl == 0.0)
    assert (m.medium.Cy, m.medium.Cz, m.medium.By) == (3.0, 3.0, 1.5)
    assert not m.drag and np.all(Sampled(m).drag_coefficient == 0.0)
    assert m.n_elements == 12 and spec.t_end == 2.0 and spec.solver["rtol"] == 1e-7
    assert spec.solver["output_dt"] == 0.1
    assert [mk.name for mk in m.markers] == ["L1", "L2", "L3", "L"]
    assert current(spec, "material.E") == 90e3 and current(spec, "medium.Cy,Cz") == 3.0


def test_tension_scale_and_offset_by_cable_number():
    spec = apply(base(), {"tension.11.scale": 1.5, "tension.cable 11.offset": -0.5})
    assert spec.model.tensions(1.0)[10] == pytest.approx(1.5 * 2.0 - 0.5)
    assert spec.model.tensions(0.1)[10] == 0.0  # clipped at zero
    again = apply(spec, {"tension.11.scale": 2.0})  # scales the original input
    assert again.model.tensions(1.0)[10] == pytest.approx(4.0)
    assert current(spec, "tension.11.scale") == 1.5
    pickle.loads(pickle.dumps(spec))


@pytest.mark.parametrize("overrides, message", [
    ({"material.Q": 1.0}, "unknown override 'material.Q'"),
    ({"material.E": -1.0}, r"override 'material.E': `E` must be > 0 Pa, got -1.0"),
    ({"medium.drag": 1}, "must be true or false"),
    ({"tension.13": 1.0}, "no cable named '13'"),
    ({"discretization.n_elements": 1}, "must be >= 2"),
])
def test_bad_overrides_name_the_key(overrides, message):
    with pytest.raises(ParameterError, match=message):
        apply(base(), overrides)
