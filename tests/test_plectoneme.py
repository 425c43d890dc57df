"""examples/plectoneme.py, short: a rod held at both ends turned 2.4 times
coils up until it lies on itself; with self-contact the link (twist +
writhe, rodmol.analysis.link) stays the turns applied and no part passes
through another; without it the rod passes through itself, and the link
drops by 2 (a crossing changes it by 2), which the measure sees."""

import numpy as np
import pytest
from example_modules import load_example

import rodmol

TURNS, T_TWIST = 2.4, 20.0  # the rod first touches itself at t = 14-15 s (2.1 turns)


@pytest.fixture(scope="module")
def plectoneme():
    return load_example("plectoneme.py")


def run(module, contact, t_end, n=40):
    system = module.plectoneme(n, TURNS, t_twist=T_TWIST)
    if not contact:
        system = system.replace(contacts=[])
    result = rodmol.simulate(system, t_end, output_dt=0.5)
    assert result.success
    lk, tw, wr = rodmol.analysis.result_link(result["rod"])
    return result, lk, wr, module.turned(result.t, TURNS, T_TWIST)


def test_a_rod_turned_onto_itself_keeps_its_link_and_does_not_pass_through(plectoneme):
    result, lk, wr, applied = run(plectoneme, True, 17.0)
    gap = result.rod_contacts()[1]
    assert np.min(gap) < 0.0 and wr[-1] > 0.7  # it lies on itself, coiled (0.89 measured)
    assert np.max(np.abs(lk - applied)) < 1e-2 * TURNS  # 1.5e-4 turns measured
    assert np.min(gap) > -0.15 * plectoneme.R  # the crossing's depth under the law (0.095 r measured)


def test_without_self_contact_it_passes_through_itself_and_the_link_drops_by_two(plectoneme):
    result, lk, wr, applied = run(plectoneme, False, 17.0)
    assert abs(lk[0] - applied[0]) < 1e-3
    assert lk[-1] - applied[-1] == pytest.approx(-2.0, abs=1e-2)
