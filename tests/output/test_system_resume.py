"""A system's streamed run: frames chunk by chunk into system.h5 and each rod's
run directory; a run killed (or interrupted) part way reads back up to its
last listed chunk and, resumed, ends bitwise where the uninterrupted run does,
with the settings recorded in system.h5."""

from functools import partial

import numpy as np
import pytest

import rodmol
from rodmol.discretise.assembly import Assembly
from rodmol.errors import ParameterError
from rodmol.output.system_stream import SystemRunWriter

RTOL = 2e-5  # not the default: a resume that forgot it would not repeat the run
T_END, DT, CHUNK = 0.1, 0.01, 4  # 11 frames; restart points at frames 0, 4, 8
BODY = ("position", "quaternion", "velocity", "angular_velocity")


def run(system, **options):
    return rodmol.simulate(system, T_END, output_dt=DT, rtol=RTOL, linsolver="sparse", **options)


@pytest.fixture(scope="module")
def whole(two_arms, tmp_path_factory):
    """The uninterrupted run, in chunks of 4 frames."""
    return run(two_arms(), out=SystemRunWriter(tmp_path_factory.mktemp("whole"), chunk_frames=CHUNK))


def assert_same(a, b):
    assert np.array_equal(a.t, b.t) and np.array_equal(a.states, b.states)
    for field in BODY:
        assert np.array_equal(getattr(a["head"], field), getattr(b["head"], field)), field
    for name in a.rods:
        assert np.array_equal(a[name].positions, b[name].positions), name
        assert np.array_equal(a[name].tensions, b[name].tensions), name


def test_one_chunk_is_the_run_in_memory_and_reads_back(two_arms, tmp_path):
    streamed = rodmol.simulate(two_arms(), 0.04, output_dt=DT, out=tmp_path)  # no restart: one chunk
    assert_same(streamed, rodmol.simulate(two_arms(), 0.04, output_dt=DT))
    back = rodmol.load_result(tmp_path)
    assert back.success and np.array_equal(back.states, streamed.states)
    assert np.array_equal(back["right"].t, streamed.t)


@pytest.mark.parametrize("rods_ahead", [False, True])
def test_a_killed_run_resumes_to_the_uninterrupted_one(two_arms, whole, tmp_path, rods_ahead, killed_system):
    killed_system(partial(run, two_arms()), tmp_path, 1, rods_ahead, chunk_frames=CHUNK)
    kept = rodmol.load_result(tmp_path)  # the first chunk, frames 0-4
    assert not kept.success and "resume" in kept.message
    assert np.array_equal(kept.states, whole.states[:5])
    assert len(kept["right"].t) == (9 if rods_ahead else 5)  # a rod's files may hold one chunk more
    with pytest.raises(ParameterError, match="resume=True"):
        run(two_arms(), out=tmp_path)
    resumed = rodmol.simulate(two_arms(), T_END, out=tmp_path, resume=True)  # rtol, linsolver: recorded
    assert resumed.success
    assert_same(resumed, whole)
    assert_same(rodmol.load_result(tmp_path), whole)
    assert resumed.stats["rhs_evals"] < whole.stats["rhs_evals"]  # frames 4-10 only


def test_an_interrupted_run_keeps_its_frames_and_resumes(two_arms, whole, tmp_path, monkeypatch):
    rates = Assembly.__call__

    def ctrl_c(self, t, y, out=None):  # Ctrl-C inside CVODE's step, in the second chunk
        if t > 0.065:
            raise KeyboardInterrupt
        return rates(self, t, y, out)

    monkeypatch.setattr(Assembly, "__call__", ctrl_c)
    with pytest.warns(RuntimeWarning, match="interrupted"):
        cut = run(two_arms(), out=SystemRunWriter(tmp_path, chunk_frames=CHUNK))
    monkeypatch.undo()
    assert not cut.success and 5 <= len(cut.t) <= 7 and np.array_equal(cut.states, whole.states[:len(cut.t)])
    kept = rodmol.load_result(tmp_path)  # every frame it reached, the cut chunk too
    assert not kept.success and np.array_equal(kept.states, cut.states)
    assert_same(rodmol.simulate(two_arms(), T_END, out=tmp_path, resume=True), whole)


def test_resume_refuses_what_it_cannot_continue(two_arms, tmp_path, killed_system):
    with pytest.raises(ParameterError, match="nothing to resume"):
        rodmol.simulate(two_arms(), T_END, out=tmp_path, resume=True)
    killed_system(partial(run, two_arms()), tmp_path, 1, chunk_frames=CHUNK)
    with pytest.raises(ParameterError, match="ends at 0.1 s"):
        rodmol.simulate(two_arms(), 0.2, out=tmp_path, resume=True)
    with pytest.raises(ParameterError, match="not the run's"):
        rodmol.simulate(two_arms(), T_END, out=tmp_path, resume=True, initial="equilibrium")
    with pytest.raises(ParameterError, match="output times"):
        rodmol.simulate(two_arms(), T_END, out=tmp_path, resume=True, output_dt=0.02)
    with pytest.raises(ParameterError, match="rods"):  # another system
        rodmol.simulate(rodmol.System(rods={"right": two_arms().rods["right"]}), T_END, out=tmp_path, resume=True)
    with pytest.raises(ParameterError, match="`resume` or `overwrite=True`"):
        rodmol.simulate(two_arms(), T_END, out=tmp_path, resume=True, overwrite=True)
