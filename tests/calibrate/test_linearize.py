"""Linearisation: A and B against finite differences of the system."""

from dataclasses import replace

import numpy as np
import pytest

import rodmol
from rodmol.calibrate import linearize


@pytest.fixture(scope="module")
def bent():
    """The paper's arm (N = 8) bent by cable 11 at 1.5 N and moving: its
    equilibrium with velocities added (so that drag, added mass and the
    gyroscopic terms are linearised too)."""
    model = rodmol.paper_arm(8, tensions={11: 1.5, 3: 0.0})
    system = rodmol.SemiDiscrete(model)
    y = rodmol.equilibrium(model).copy()
    rng = np.random.default_rng(0)
    system.layout.field(y, "v")[:] = 0.05 * rng.standard_normal((8, 3))
    system.layout.field(y, "w")[:] = 0.5 * rng.standard_normal((8, 3))
    return model, y


def central(f, x, h):
    cols = []
    for j in range(len(x)):
        e = np.zeros(len(x))
        e[j] = h[j]
        cols.append((f(x + e) - f(x - e)) / (2 * h[j]))
    return np.column_stack(cols)


@pytest.mark.parametrize("friction", [0.0, 0.3])
def test_state_jacobian_matches_central_differences(bent, friction):
    """With friction the tension along the cable depends on the sliding
    velocities, a coupling the linearisation must keep."""
    model, y = bent
    if friction:
        model = model.replace(cables=[replace(c, friction=friction, slip_speed=0.05) for c in model.cables])
    a, _ = linearize(model, y, 0.3)
    system = rodmol.SemiDiscrete(model)
    reference = central(lambda x: system(0.3, x), y, 1e-6 * system.atol_scale())
    scale = np.abs(reference).max()
    assert np.max(np.abs(a - reference)) < 1e-5 * scale


def test_input_jacobian_matches_models_with_other_tensions(bent):
    """Column j of B is d f / d T_j, found here from separate models whose cable j
    pulls 0.1 N more and less (cable 3 is slack in the model itself)."""
    model, y = bent
    _, b = linearize(model, y, 0.3)
    assert b.shape == (y.size, 12)
    for j in (2, 10):
        rates = []
        for dt in (0.1, -0.1):
            tensions = {11: 1.5 + (dt if j == 10 else 0.0), 3: 0.0 + (dt if j == 2 else 0.0)}
            if tensions[3] < 0:
                tensions[3] = 0.0
            rates.append(rodmol.SemiDiscrete(rodmol.paper_arm(8, tensions=tensions))(0.3, y))
        step = 0.2 if j == 10 else 0.1  # cable 3 cannot go below 0 N: forward difference
        reference = (rates[0] - rates[1]) / step
        assert np.max(np.abs(b[:, j] - reference)) < 1e-6 * np.abs(reference).max()
    assert np.max(np.abs(b[:, 2])) > 0.0  # a slack cable still has its input column
