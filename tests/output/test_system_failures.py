"""A system's streamed run that fails fast (a rod turning over, a body's rates non-finite, a
user function raising) ends with success=False, says where and why, and leaves the frames
computed before in its directory, read back by load_result as the run returned them."""

import dataclasses

import numpy as np
import pytest

import rodmol
from rodmol.discretise.assembly import Assembly
from rodmol.output.system_stream import SystemRunWriter

CHUNK = 2  # frames a chunk: the failures land after a few chunks


def run(system, directory, **options):
    """The streamed run to 0.2 s (frames every 10 ms); the budget only guards against a run that never stops."""
    with pytest.warns(RuntimeWarning) as warned:
        result = rodmol.simulate(system, 0.2, output_dt=0.01, max_wall_time=60.0,
                                 out=SystemRunWriter(directory, chunk_frames=CHUNK), **options)
    assert not result.success and str(warned[0].message) == result.message
    return result


def assert_kept(result, directory):
    """The directory holds the frames the run returned, and says why it stopped."""
    back = rodmol.load_result(directory)
    assert not back.success and back.message == result.message
    assert np.array_equal(back.t, result.t) and np.array_equal(back.states, result.states)
    assert np.all(np.isfinite(back.states)) and 1 < len(back.t) < 21
    for name in back.rods:  # each rod's own folder, up to the same frame
        assert np.array_equal(back[name].t, result.t), name
    assert np.array_equal(back["head"].position, result["head"].position)
    return back


def pulled(system, tension):
    """``system`` with the cable of its rod 'left arm' pulled by ``tension`` (a function of t [s])."""
    left = system.rods["left arm"]
    system.rods["left arm"] = left.replace(cables=[dataclasses.replace(left.cables[0], tension=tension)])
    return system


def test_a_rod_turning_over_stops_the_run_naming_it(two_arms, tmp_path):
    result = run(pulled(two_arms(), lambda t: 5.0 * min(t / 0.1, 1.0)), tmp_path)  # 5 N on a 6 mm tip
    assert "rod 'left arm': element" in result.message and "turns by" in result.message
    assert result.t[-1] == pytest.approx(0.04)
    assert_kept(result, tmp_path)


@pytest.mark.parametrize("linsolver", ["gmres", "sparse"])
def test_a_body_whose_rates_turn_non_finite_stops_the_run_naming_it(two_arms, tmp_path, monkeypatch, linsolver):
    """CVODE, whose right-hand side cannot report a failure, retried ever shorter steps without
    end (minutes, until stopped): the run now stops and names the body."""
    rates = Assembly.__call__

    def lost(self, t, y, out=None):  # the head's accelerations turn NaN after 0.055 s
        f = rates(self, t, y, out)
        if t > 0.055:
            f[self.bodies["head"].fields["v"]] = np.nan
        return f

    monkeypatch.setattr(Assembly, "__call__", lost)
    result = run(two_arms(), tmp_path, linsolver=linsolver)
    monkeypatch.undo()
    assert "body 'head' (v" in result.message and "non-finite" in result.message
    assert result.t[-1] == pytest.approx(0.05)  # the last frame before
    assert_kept(result, tmp_path)


def test_a_failing_input_stops_the_run_with_its_error(two_arms, tmp_path):
    def tension(t):
        if t > 0.065:
            raise RuntimeError("sensor lost")
        return 0.1

    result = run(pulled(two_arms(), tension), tmp_path)
    assert isinstance(result.error, rodmol.UserFunctionError) and "sensor lost" in result.message
    assert result.t[-1] == pytest.approx(0.06)
    assert_kept(result, tmp_path)
