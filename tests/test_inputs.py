"""Bad input is refused with a message that names the parameter and the value;
a failed integration hands back what it computed; results survive a save/load.
"""

import math
import re
import warnings

import numpy as np
import pytest

import rodmol
from rodmol import Material, Model, ParameterError, Rod
from rodmol.discretise.schemes import DEFAULT_SCHEME, get_scheme

NAN, INF = float("nan"), float("inf")
GOOD_MATERIAL = dict(E=110e3, nu=0.5, mu=300.0, rho=1080.0)
L = 0.418


def material(**changes):
    return Material(**{**GOOD_MATERIAL, **changes})


def rod(length=L, radius=(0.015, 0.004)):
    return Rod(length, radius, material())


def small_model():
    return Model(rod(), 5)


def value_pattern(value):
    """Regex for the offending value as the message prints it: ``got <repr>``
    (numbers, also numpy's ``array(-1.)`` form) or the quoted name (strings)."""
    text = re.escape(repr(value))
    if isinstance(value, float):
        short = re.escape(repr(value).rstrip("0")) if math.isfinite(value) else text
        return rf"got (array\()?({text}|{short})(?![0-9])"  # -1.0, or numpy's -1.
    if isinstance(value, (int, tuple)):
        return rf"got {text}(?![0-9])"
    return text


def assert_rejected(call, name, value):
    """``call()`` raises ParameterError (a ValueError) naming ``name`` and ``value``."""
    with pytest.raises(ParameterError) as info:
        call()
    assert isinstance(info.value, ValueError)
    message = str(info.value)
    assert re.search(name, message), f"{name!r} not in {message!r}"
    assert re.search(value_pattern(value), message), f"{value!r} not in {message!r}"


BAD_NUMBERS = [0.0, -1.0, NAN, INF]  # for parameters that must be positive

CASES = (
    # (label, call, name regex, offending value)
    [(f"length={v}", lambda v=v: rod(length=v), "`length`", v) for v in BAD_NUMBERS + [-INF]]
    + [(f"radius={v}", lambda v=v: rod(radius=v), "`radius`", v) for v in BAD_NUMBERS]
    + [(f"radius=({v}, tip)", lambda v=v: rod(radius=(v, 0.004)), r"`radius\[0\]", v)
       for v in BAD_NUMBERS]
    + [(f"radius=(base, {v})", lambda v=v: rod(radius=(0.015, v)), r"`radius\[1\]", v)
       for v in BAD_NUMBERS]
    + [("radius=(a, b, c)", lambda: rod(radius=(0.01, 0.02, 0.03)), "`radius`", (0.01, 0.02, 0.03))]
    + [(f"E={v}", lambda v=v: material(E=v), "`E`", v) for v in BAD_NUMBERS]
    + [(f"rho={v}", lambda v=v: material(rho=v), "`rho`", v) for v in BAD_NUMBERS]
    + [(f"nu={v}", lambda v=v: material(nu=v), "`nu`", v)
       for v in [-1.0, -1.5, 0.5000001, 0.6, 1.0, NAN, INF, -INF]]
    + [(f"mu={v}", lambda v=v: material(mu=v), "`mu`", v) for v in [-1e-3, -300.0, NAN, INF]]
    + [(f"n_elements={v!r}", lambda v=v: Model(rod(), v), "`n_elements`", v)
       for v in [1, 0, -4, 2.5, 10.0, "10", NAN, INF, True, None]]
    + [(f"gravity={v!r}", lambda v=v: Model(rod(), 5, gravity=v), "`gravity`", v)
       for v in [(0.0, NAN, 0.0), (INF, 0.0, 0.0), (0.0, -9.81)]]
    + [("medium='honey'", lambda: Model(rod(), 5, medium="honey"), "`medium`", "honey")]
    + [(f"medium_density={v}", lambda v=v: Model(rod(), 5, medium_density=v),
        "`medium_density`", v) for v in [-1.0, NAN]]
    + [(f"t_end={v}", lambda v=v: rodmol.simulate(small_model(), v), "`t_end`", v)
       for v in BAD_NUMBERS + [-INF]]
    + [(f"output_dt={v}", lambda v=v: rodmol.simulate(small_model(), 0.1, output_dt=v),
        "`output_dt`", v) for v in BAD_NUMBERS]
    + [(f"rtol={v}", lambda v=v: rodmol.simulate(small_model(), 0.1, rtol=v), "`rtol`", v)
       for v in BAD_NUMBERS]
    + [(f"backend={v!r}", lambda v=v: rodmol.simulate(small_model(), 0.1, backend=v),
        "`backend`", v) for v in ["rk45", "CVODE", ""]]
    + [(f"initial={v!r}", lambda v=v: rodmol.simulate(small_model(), 0.1, initial=v),
        "`initial`", v) for v in ["relaxed", "Straight"]]
    + [(f"atol={v}", lambda v=v: rodmol.simulate(small_model(), 0.1, atol=v), "`atol`", v)
       for v in [-1.0, 0.0, NAN, INF]]
)


@pytest.mark.parametrize("call, name, value", [c[1:] for c in CASES], ids=[c[0] for c in CASES])
def test_bad_parameter_is_named_with_its_value(call, name, value):
    assert_rejected(call, name, value)


@pytest.mark.parametrize("radius, where", [
    (lambda s: 0.015 - 0.05 * s, "negative beyond s = 0.3 m"),
    (lambda s: 0.0 * s, "zero everywhere"),
    (lambda s: np.where(s > 0.2, np.nan, 0.01), "NaN beyond s = 0.2 m"),
])
def test_radius_callable_must_stay_positive(radius, where):
    """A radius profile r(s) <= 0 (or NaN) somewhere is refused; the message
    names the arc length and the value r(s) found there."""
    with pytest.raises(ParameterError, match="`radius`") as info:
        Rod(L, radius, material())
    found = re.search(r"r\(([-+0-9.e]+) m\) = (?:np\.float64\()?([-+0-9.e]+|nan)", str(info.value))
    assert found, str(info.value)
    s, r = float(found.group(1)), float(found.group(2))
    assert 0.0 <= s <= L
    assert not r > 0.0  # the reported value is the offending one
    expected = float(radius(np.array(s)))
    assert (math.isnan(r) and math.isnan(expected)) or r == pytest.approx(expected, abs=1e-7)


def test_bad_atol_vector():
    model = small_model()
    size = rodmol.StateLayout(5).size
    # Wrong length: the message names atol and the length it must have.
    with pytest.raises(ParameterError, match=f"`atol`.*length {size}"):
        rodmol.simulate(model, 0.1, atol=np.full(size - 1, 1e-6))
    bad = np.full(size, 1e-6)
    bad[7] = -1e-6
    with pytest.raises(ParameterError, match=r"(?s)`atol`.*-1(\.0*)?e-0?6"):
        rodmol.simulate(model, 0.1, atol=bad)


def test_initial_state_of_wrong_size():
    with pytest.raises(ParameterError, match=r"`initial`.*\(3,\)"):
        rodmol.simulate(small_model(), 0.1, initial=np.zeros(3))


def _nan_initial_state():
    model = Model(rod(), 100)
    y0 = rodmol.straight_state(model)
    y0[20] = NAN
    return lambda: rodmol.simulate(model, 0.1, initial=y0)


def _atol_with_one_bad_entry():
    model = Model(rod(), 100)
    atol = np.full(rodmol.StateLayout(100).size, 1e-6)
    atol[20] = -1e-6
    return lambda: rodmol.simulate(model, 0.1, atol=atol)


@pytest.mark.parametrize("make_call, name, value", [
    (_nan_initial_state, "`initial`", NAN),
    (_atol_with_one_bad_entry, "`atol`", -1e-6),
], ids=["initial with a NaN", "atol with one negative entry"])
def test_bad_entry_of_state_vector_is_named(make_call, name, value):
    with pytest.raises(ParameterError) as info:
        make_call()()
    message = str(info.value)
    assert name in message
    assert re.search("nan" if value != value else r"-1(\.0*)?e-0?6", message), message


# --------------------------------------------------------------------------
# A failed integration returns the partial result
# --------------------------------------------------------------------------

T_FAIL = 0.05  # s


def lost_sensor(t):
    if t > T_FAIL:
        raise RuntimeError("tension sensor lost")
    return 0.5


def negative_after_failure(t):
    return 0.5 if t <= T_FAIL else -1.0


@pytest.mark.parametrize("backend", ["cvode", "rk23", "galpha"])
@pytest.mark.parametrize("tension, reason", [
    (lost_sensor, "RuntimeError: tension sensor lost"),
    (negative_after_failure, "the tension input returned -1.0 at t = "),
])
def test_failed_integration_returns_partial_result(backend, tension, reason):
    # The arm is released from straight so that the solver is busy (small
    # steps) when the input fails at 0.05 s.
    model = rodmol.paper_arm(10, tensions={11: tension})
    with pytest.warns(RuntimeWarning) as record:
        res = rodmol.simulate(model, 0.2, initial="straight", backend=backend, output_dt=0.01)
    assert res.success is False
    assert reason in res.message
    assert any(reason in str(w.message) for w in record)

    # The message names the time reached, and it is the last frame's time.
    reached = float(re.search(r"t = ([-+0-9.e]+) s", res.message).group(1))
    assert reached == pytest.approx(res.t[-1], abs=1e-9)
    # Frames run up to the failure and no further: a solver's trial step that
    # overshot the failure time does not lose the frames before it.
    assert res.t[-1] == pytest.approx(T_FAIL, abs=1e-12)
    assert np.allclose(np.diff(res.t), 0.01)
    for name in ("positions", "rotations", "velocity", "tensions", "quaternion_norm_error",
                 "markers"):
        assert len(getattr(res, name)) == len(res.t), name

    # The frames computed are the true motion: the same as a run with an input
    # that agrees with this one up to the failure, to the integration's accuracy
    # (the frames after the last step before the failure are integrated again
    # from the last frame): rtol L where the step is error-controlled (measured
    # 1.9e-6 L at rtol 3e-5), else generalized-alpha's own error at its fixed
    # step (measured 1.7e-4 m against 5.7e-4 m).
    ok = rodmol.simulate(rodmol.paper_arm(10, tensions={11: 0.5}), 0.2, initial="straight",
                         backend=backend, output_dt=0.01)
    assert ok.success
    n = len(res.t)
    assert np.allclose(ok.t[:n], res.t)
    accuracy = 0.3 * get_scheme(DEFAULT_SCHEME).default_rtol * L
    if backend == "galpha":
        exact = rodmol.simulate(rodmol.paper_arm(10, tensions={11: 0.5}), T_FAIL, initial="straight",
                                rtol=1e-8, output_dt=0.01)
        accuracy = np.max(np.abs(ok.positions[:n] - exact.positions))
    assert np.max(np.abs(ok.positions[:n] - res.positions)) < accuracy


def test_successful_run_does_not_warn():
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        res = rodmol.simulate(rodmol.paper_arm(6, tensions={11: 0.5}), 0.02, output_dt=0.01)
    assert res.success is True


# --------------------------------------------------------------------------
# Result.save / rodmol.load_result
# --------------------------------------------------------------------------

def _assert_same_result(a, b):
    from rodmol.result import ARRAYS

    for name in ARRAYS:
        x, y = getattr(a, name), getattr(b, name)
        assert x.shape == y.shape and x.dtype == y.dtype, name
        assert np.array_equal(x, y), name
    assert b.success == a.success and b.message == a.message
    assert b.stats == a.stats and b.meta == a.meta


def test_save_load_round_trip(tmp_path):
    res = rodmol.simulate(rodmol.paper_arm(6, tensions={11: 0.5}), 0.05, initial="straight",
                          output_dt=0.01)
    path = tmp_path / "run.npz"
    res.save(path)
    back = rodmol.load_result(path)
    _assert_same_result(res, back)
    assert back.tip.shape == (len(res.t), 3)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["run.npz"]  # no temporary left
    # Saving again over the same name is refused unless asked, and then replaces the file.
    with pytest.raises(rodmol.ParameterError, match="run.npz' exists: .*overwrite=True"):
        res.save(path)
    res.save(str(path), overwrite=True)
    _assert_same_result(res, rodmol.load_result(str(path)))


def test_save_load_round_trip_of_failed_run(tmp_path):
    with pytest.warns(RuntimeWarning):
        res = rodmol.simulate(rodmol.paper_arm(6, tensions={11: lost_sensor}), 0.2,
                              initial="straight", backend="rk23", output_dt=0.01)
    assert not res.success
    res.save(tmp_path / "failed.npz")
    _assert_same_result(res, rodmol.load_result(tmp_path / "failed.npz"))
