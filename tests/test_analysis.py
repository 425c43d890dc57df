"""rodmol.analysis helpers against closed forms."""

import numpy as np
import pytest

import rodmol


@pytest.mark.parametrize("samples_per_period", [20, 40, 80])
def test_oscillation_period_of_a_sine_converges_at_second_order(samples_per_period):
    period, phase = 0.1787, 0.3
    t = np.arange(0.0, 10 * period, period / samples_per_period * 1.0137)  # off the period's grid
    x = 0.05 * np.sin(2 * np.pi * t / period + phase) + 0.01  # offset: crossings of the mean
    error = abs(rodmol.oscillation_period(t, x) / period - 1.0)
    # Linear interpolation across a zero of a sine: O((2 pi / samples)^2) per crossing, and the
    # errors at the two ends of the span do not cancel in general.
    assert error < 0.5 * (2 * np.pi / samples_per_period) ** 2 / 10


def test_oscillation_period_needs_two_upward_crossings():
    t = np.linspace(0.0, 1.0, 50)
    with pytest.raises(rodmol.ParameterError, match="crosses its mean upwards 1 time"):
        rodmol.oscillation_period(t, -np.cos(2 * np.pi * 0.9 * t))  # up at 0.28 s only
