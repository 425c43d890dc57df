"""Physical parameters out of any meaningful range (finite, but the rates at the
straight rod overflow the solver's error norm) are refused before the run with
a ParameterError naming them; meaningful ones pass the check untouched."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import rodmol
from rodmol.discretise.system import SemiDiscrete
from rodmol.solve import kernels
from rodmol.solve.scales import check_scales

MATERIAL = rodmol.Material(E=110e3, nu=0.5, mu=300.0, rho=1080.0)
ROD = rodmol.Rod(0.3, (0.012, 0.005), MATERIAL)

#: Each absurd input, as the Model arguments that give it and what the message names.
ABSURD = {
    "gravity": (lambda x: dict(gravity=(0.0, -x, 0.0)), r"`gravity` = \(0.0, -[0-9.e+]+, 0.0\) m/s\^2"),
    "buoyancy": (lambda x: dict(medium_density=x), r"the medium's density `rho` = [0-9.e+]+ kg/m\^3"),
    "fluid": (lambda x: dict(medium=rodmol.Medium(x, 0.01, 2.5, 2.5, 1.5, 1.5)),  # its drag overflows
              r"the medium's density `rho` = [0-9.e+]+ kg/m\^3"),
    "tension": (lambda x: dict(cables=[rodmol.Cable((0.004, 0.0), 0.3, x, name="pull")]),
                r"the cables' tensions at t = 0 s \('pull'\)"),
    "force": (lambda x: dict(loads=[rodmol.PointForce(0.3, (0.0, x, 0.0), name="push")]), r"the loads \('push'\)"),
}


@settings(max_examples=12, deadline=None, derandomize=True)
@given(which=st.sampled_from(sorted(ABSURD)), exponent=st.floats(160.0, 308.0))
def test_absurd_inputs_are_refused_before_the_run_naming_them(which, exponent):
    arguments, named = ABSURD[which]
    model = rodmol.Model(ROD, 4, **arguments(10.0**exponent))

    def no_run(*args, **kwargs):
        raise AssertionError("the run started")

    message = r"out of any meaningful range.*it comes from " + named + "$"  # that input alone
    with pytest.MonkeyPatch.context() as patch, pytest.raises(rodmol.ParameterError, match=message):
        patch.setattr(kernels, "prepare", no_run)
        rodmol.simulate(model, 0.1, initial="straight")


def test_two_absurd_inputs_are_both_named():
    model = rodmol.Model(ROD, 4, gravity=(0.0, -1e300, 0.0), medium_density=1e308)
    with pytest.raises(rodmol.ParameterError, match=r"it comes from `gravity` = .*, the medium's density"):
        rodmol.simulate(model, 0.1, initial="straight")


@pytest.mark.parametrize("arguments", [
    dict(), dict(medium="water", gravity=(0.0, -1e4, 0.0)),
    dict(cables=[rodmol.Cable((0.004, 0.0), 0.3, 1e6)], loads=[rodmol.PointForce(0.3, (0.0, 1e6, 0.0))]),
])
def test_meaningful_inputs_pass(arguments):
    system = SemiDiscrete(rodmol.Model(ROD, 4, **arguments))
    check_scales(system, 0.0, rodmol.default_atol(system.model, 1e-14))  # the smallest rtol allowed


def test_a_failing_user_function_is_left_for_the_run_to_report():
    def tension(t):
        raise RuntimeError("sensor lost")

    system = SemiDiscrete(rodmol.Model(ROD, 4, cables=[rodmol.Cable((0.004, 0.0), 0.3, tension)]))
    check_scales(system, 0.0, np.ones(system.size))
