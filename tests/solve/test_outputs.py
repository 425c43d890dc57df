"""A function of the user's that fails at t_fail ends the run with every frame
before t_fail and none after it (``rodmol.solve.outputs.keep_before_failure``),
on every backend, in memory and streamed; the message names the function, the
time and the exception or the bad value."""

import re
import warnings

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import rodmol
from rodmol.discretise.schemes import DEFAULT_SCHEME, get_scheme
from rodmol.output.stream import RunWriter

T_END, DT = 0.2, 0.01  # s: the run and its output interval
LENGTH = 0.3  # m
#: Where the failing function sits, and the words that name it in the message.
NAMED = {
    "tension": ("cable 'pull'", "tension"),
    "feedback": ("cable 'pull': the feedback law T(t, state)",),
    "base": ("the base motion's `velocity` function",),
    "point load": ("`force` of `tip push`",),
    "distributed load": ("side wind: the force(s, t) function",),
}
#: How the function fails, and the words for it in the message.
KINDS = {"raise": "raised RuntimeError: sensor lost", "nan": "returned", "inf": "returned",
         "negative": "returned"}
#: generalized-alpha's fixed step [s]: short, so its own error stays below the tolerances here.
GALPHA_DT = 1e-3


def tension_ramp(t):
    return 0.6 * min(t / T_END, 1.0)


def model(where, fail=None):
    """A 0.3 m rod in water, N = 6, pulled by cable 'pull'; the function at
    ``where`` fails from ``fail`` = (t_fail, kind) on (never if None)."""
    def failing(good, t):
        if fail is None or t < fail[0]:
            return good
        kind = fail[1]
        if kind == "raise":
            raise RuntimeError("sensor lost")
        return {"nan": np.nan, "inf": np.inf, "negative": -1.0}[kind] * np.ones_like(good)

    tension = tension_ramp
    if where == "tension":
        tension = lambda t: failing(np.float64(tension_ramp(t)), t)  # noqa: E731
    elif where == "feedback":
        tension = lambda t, state: failing(np.float64(tension_ramp(t) + 0.0 * state.tip[0]), t)  # noqa: E731
    cable = rodmol.Cable((0.004, 0.0), LENGTH, tension=tension, name="pull")
    base = None
    if where == "base":
        base = rodmol.BaseMotion(velocity=lambda t: failing(np.array([0.0, 0.02 * t, 0.0]), t))
    loads = []
    if where == "point load":
        loads = [rodmol.PointForce(LENGTH, lambda t: failing(np.array([0.0, 0.0, 0.01 * t]), t),
                                   name="tip push")]
    elif where == "distributed load":
        loads = [rodmol.DistributedForce(lambda s, t: failing(np.outer(s, [0.0, 0.0, 0.05 * t]), t),
                                         name="side wind")]
    rod = rodmol.Rod(LENGTH, 0.008, rodmol.Material(E=110e3, nu=0.5, mu=300.0, rho=1080.0))
    return rodmol.Model(rod, 6, medium="water", cables=[cable], base=base, loads=loads)


def simulate(model, backend, **options):
    if backend == "galpha":
        options["dt"] = GALPHA_DT
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        return rodmol.simulate(model, T_END, backend=backend, output_dt=DT, **options)


_references = {}


def reference(where, backend):
    """The run with the same inputs that never fail."""
    if (where, backend) not in _references:
        _references[where, backend] = simulate(model(where), backend)
    return _references[where, backend]


def assert_ends_at_the_failure(result, ok, t_fail, where, kind):
    """Every frame before t_fail, equal to the run that does not fail (to the
    tolerance), none after; the message names the function, the time and the
    exception or the bad value."""
    assert not result.success
    before = ok.t[ok.t < t_fail]
    np.testing.assert_allclose(result.t, before, rtol=0, atol=1e-12)
    tolerance = 0.3 * get_scheme(DEFAULT_SCHEME).default_rtol * LENGTH
    assert np.max(np.abs(result.positions - ok.positions[:len(before)])) < tolerance
    message, error = result.message, result.error
    assert isinstance(error, rodmol.UserFunctionError)
    assert all(words in message for words in NAMED[where]) and KINDS[kind] in message, message
    # The time named: where the function failed, at most the first output at or after t_fail.
    assert f"t = {error.t:.6g} s" in message
    assert t_fail <= error.t <= ok.t[ok.t >= t_fail][0] + 1e-12
    if kind == "raise":
        assert isinstance(error.__cause__, RuntimeError)
    else:
        assert {"nan": "nan", "inf": "inf", "negative": "-1.0"}[kind] in message


@settings(max_examples=24, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(t_fail=st.floats(0.015, 0.185), kind=st.sampled_from(sorted(KINDS)),
       where=st.sampled_from(sorted(NAMED)), backend=st.sampled_from(["cvode", "galpha", "rk23"]))
def test_a_function_failing_late_keeps_every_frame_before(t_fail, kind, where, backend):
    if kind == "negative" and where != "tension" and where != "feedback":
        kind = "nan"  # a negative force or velocity is no failure
    result = simulate(model(where, (t_fail, kind)), backend)
    assert_ends_at_the_failure(result, reference(where, backend), t_fail, where, kind)


@pytest.mark.parametrize("backend", ["cvode", "galpha", "rk23"])
def test_a_streamed_run_ends_cleanly_at_the_last_good_frame(backend, tmp_path):
    # Chunks of 4 frames: the failure at 0.123 s comes in the fourth chunk.
    t_fail = 0.123
    result = simulate(model("tension", (t_fail, "raise")), backend,
                      out=RunWriter(tmp_path, chunk_frames=4, views=False))
    ok = reference("tension", backend)
    assert_ends_at_the_failure(result, ok, t_fail, "tension", "raise")
    stored = rodmol.load_result(tmp_path)
    assert not stored.success and "sensor lost" in stored.message
    np.testing.assert_array_equal(stored.t, result.t)
    np.testing.assert_array_equal(stored.positions, result.positions)


def test_cvode_stops_at_once_instead_of_creeping():
    # Before, the failing function answered NaN rates and CVODE retried shorter
    # steps up to 50 times; a failing function is no numerical failure.
    calls = []

    def sensor(t):
        if t >= 0.1:
            calls.append(t)
            raise RuntimeError("sensor lost")
        return tension_ramp(t)

    rod = rodmol.Rod(LENGTH, 0.008, rodmol.Material(E=110e3, nu=0.5, mu=300.0, rho=1080.0))
    failing = rodmol.Model(rod, 6, medium="water", cables=[rodmol.Cable((0.004, 0.0), LENGTH, sensor,
                                                                        name="pull")])
    result = simulate(failing, "cvode")
    assert result.t[-1] == pytest.approx(0.09)
    assert len(calls) <= 3  # the trial step past it, the step ending on it, the frame check


def test_a_raising_progress_callable_ends_the_run_and_keeps_its_frames():
    def progress(t, t_end):
        if t >= 0.05:
            raise RuntimeError("display closed")

    result = simulate(model("tension"), "cvode", progress=progress)
    assert not result.success and result.t[-1] == pytest.approx(0.05)
    assert re.search(r"the `progress` callable raised RuntimeError: display closed \(at t = 0\.05 s\)",
                     result.message), result.message
    assert isinstance(result.error, rodmol.UserFunctionError)
    assert isinstance(result.error.__cause__, RuntimeError)


@pytest.mark.parametrize("where", sorted(NAMED))
def test_a_function_failing_at_the_start_is_raised_before_the_run(where):
    with pytest.raises(rodmol.UserFunctionError) as info:
        rodmol.simulate(model(where, (0.0, "raise")), T_END)
    assert all(words in str(info.value) for words in NAMED[where]) and "(at t = 0 s)" in str(info.value)
    assert isinstance(info.value.__cause__, RuntimeError)
