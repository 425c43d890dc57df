"""The system of a state and its sensitivities (rodmol.discretise.sensitivity_system): a
Discretised whose rates, products J v and projection are those of the model's own."""

import numpy as np

import rodmol
from rodmol import named_parameters
from rodmol.discretise.protocol import Discretised
from rodmol.discretise.sensitivity_system import SensitivitySystem
from rodmol.discretise.system import SemiDiscrete


def _augmented():
    arm = rodmol.paper_arm(6, tensions={11: 1.0})
    base = SemiDiscrete(arm)
    p = named_parameters.parameter(arm, "material.E")
    up, down, h = p.pair(arm)
    return arm, base, SensitivitySystem(base, [(SemiDiscrete(up), SemiDiscrete(down))], [h])


def _bent(base):
    y = base.undeformed_state()
    y[base.layout.field(np.arange(base.size), "k")[:, 2]] = 2.0
    return y


def test_it_is_a_discretised_system_of_the_state_and_one_sensitivity():
    _, base, system = _augmented()
    assert isinstance(system, Discretised) and system.size == 2 * base.size
    assert system.linear_solvers() == {"gmres": "compiled"}


def test_its_rates_are_the_models_and_the_directional_derivative():
    arm, base, system = _augmented()
    y, s = _bent(base), np.random.default_rng(1).normal(size=base.size) * 1e-6
    rates = system(0.1, np.concatenate([y, s]))
    np.testing.assert_array_equal(rates[:base.size], base(0.1, y))
    # d/de f(y + e s; E + e) at e = 0, by a central difference of the model's own systems.
    e = 10.0  # Pa: 1e-4 of E
    plus = SemiDiscrete(named_parameters.parameter(arm, "material.E").at(arm, arm.rod.material.E + e))
    minus = SemiDiscrete(named_parameters.parameter(arm, "material.E").at(arm, arm.rod.material.E - e))
    expected = (plus(0.1, y + e * s) - minus(0.1, y - e * s)) / (2 * e)
    np.testing.assert_allclose(rates[base.size:], expected, rtol=1e-5, atol=1e-9 * np.abs(expected).max())


def test_its_products_are_the_models_jacobian_on_each_block():
    _, base, system = _augmented()
    y = _bent(base)
    Y, V = np.concatenate([y, np.zeros(base.size)]), np.random.default_rng(2).normal(size=system.size)
    JV = np.empty(system.size)
    system.jacobian_times(np.tile(base.atol_scale(), 2))(0.1, Y, system(0.1, Y), V, JV)
    for k in range(2):
        v = V[k * base.size:(k + 1) * base.size]
        e = 1e-7 / np.max(np.abs(v) / base.atol_scale())
        expected = (base(0.1, y + e * v) - base(0.1, y - e * v)) / (2 * e)
        np.testing.assert_allclose(JV[k * base.size:(k + 1) * base.size], expected,
                                   atol=1e-4 * np.abs(expected).max())


def test_the_projection_keeps_unit_quaternions_and_tangent_sensitivities():
    _, base, system = _augmented()
    y = _bent(base)
    Y = np.concatenate([1.001 * y, np.random.default_rng(3).normal(size=base.size)])[None].repeat(2, axis=0)
    system.project_quaternions(Y)
    q, dq = (base.layout.quaternions(Y[:, k * base.size:(k + 1) * base.size]) for k in range(2))
    np.testing.assert_allclose(np.linalg.norm(q, axis=-1), 1.0, rtol=1e-12)
    np.testing.assert_allclose(np.sum(q * dq, axis=-1), 0.0, atol=1e-8)  # d|Q| = 0 along the sensitivity
