"""One rule for every state a user gives (run_arguments.check_state, run_arguments.check_word): simulate's
and the Simulator's ``initial`` and linearize's ``state`` refuse the same states with a
ParameterError naming the parameter, before any work; linearize never returns non-finite A, B."""

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import rodmol
from rodmol.errors import ParameterError

SETTINGS = settings(max_examples=40, deadline=None, derandomize=True,
                    suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture])
N = 6
MODEL = rodmol.paper_arm(N)
SYSTEM = rodmol.SemiDiscrete(MODEL)
REST = SYSTEM.undeformed_state()
QUATERNIONS = SYSTEM.layout.field(np.arange(SYSTEM.size), "Q")  # (N, 4) entries

#: Each public entry that takes a state: (its parameter's name, a call with the state given).
ENTRIES = {
    "simulate": ("initial", lambda state: rodmol.simulate(MODEL, 0.01, initial=state)),
    "Simulator": ("initial", lambda state: rodmol.Simulator(MODEL, initial=state)),
    "linearize": ("state", lambda state: rodmol.linearize(MODEL, state)),
}
WORDS = ("equilibrium", "straight")


def refused(entry, state):
    """The message of the ParameterError with which ``entry`` refuses ``state`` (no other error)."""
    name, call = ENTRIES[entry]
    with pytest.raises(ParameterError) as info:
        call(state)
    assert f"`{name}`" in str(info.value)
    return str(info.value)


@pytest.mark.parametrize("entry", ENTRIES)
@SETTINGS
@given(data=st.data())
def test_non_finite_entries_in_a_valid_state_are_always_refused_naming_the_first(entry, data):
    where = data.draw(st.lists(st.integers(0, SYSTEM.size - 1), min_size=1, max_size=5, unique=True))
    values = data.draw(st.lists(st.sampled_from([np.nan, np.inf, -np.inf]), min_size=len(where),
                                max_size=len(where)))
    state = REST.copy()
    state[where] = values
    first = min(where)
    message = refused(entry, state)
    assert f"entry {first} ({SYSTEM.entry_name(first)})" in message


@pytest.mark.parametrize("entry", ENTRIES)
@SETTINGS
@given(node=st.integers(0, N - 1), scale=st.one_of(st.just(0.0), st.floats(0.0, 0.85), st.floats(1.15, 1e6)))
def test_a_quaternion_off_unit_norm_is_refused_by_every_entry(entry, node, scale):
    state = REST.copy()
    state[QUATERNIONS[node]] *= scale
    assert "lost its unit norm" in refused(entry, state)


def test_linearize_refuses_the_degenerate_state_it_used_to_turn_into_nan():
    state = REST.copy()
    state[QUATERNIONS.ravel()] = 0.0  # every orientation degenerate: A had > 1000 NaN entries
    assert "|Q| = 0" in refused("linearize", state)


@SETTINGS
@given(scale=st.floats(0.95, 1.05))
def test_a_quaternion_near_unit_norm_is_taken_as_simulate_takes_it(scale):
    state = REST.copy()
    state[QUATERNIONS[N // 2]] *= scale
    a, b = rodmol.linearize(MODEL, state)
    assert np.all(np.isfinite(a)) and np.all(np.isfinite(b))


@pytest.mark.parametrize("entry", ENTRIES)
@pytest.mark.parametrize("word", ["equilibrum", "rest", "", "Straight"])
def test_an_unknown_word_is_refused_naming_the_parameter_value_and_words(entry, word):
    message = refused(entry, word)
    assert repr(word) in message and all(repr(w) in message for w in WORDS)


def test_linearize_takes_the_same_words_as_simulate():
    straight = rodmol.linearize(MODEL, "straight")
    np.testing.assert_array_equal(straight.state, REST)
    np.testing.assert_array_equal(straight.A, rodmol.linearize(MODEL, REST).A)
    np.testing.assert_allclose(rodmol.linearize(MODEL, "equilibrium").state, rodmol.equilibrium(MODEL))


def test_linearize_refuses_rates_that_are_not_finite_about_a_finite_state():
    state = REST.copy()
    SYSTEM.layout.field(state, "v")[:] = 1e200  # finite, but the drag overflows
    with np.errstate(all="ignore"), pytest.raises(ParameterError, match="A has .* non-finite entries"):
        rodmol.linearize(MODEL, state)


@pytest.mark.parametrize("t", [np.nan, np.inf, "0"])
def test_linearize_refuses_a_bad_time(t):
    with pytest.raises(ParameterError, match="`t`"):
        rodmol.linearize(MODEL, REST, t=t)
