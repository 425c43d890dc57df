"""Streamed output: the result file and views written while the run goes, read
back as the in-memory run; restart points; a run killed (SIGKILL) and resumed
ends in the same state as the uninterrupted one."""

from functools import partial

import numpy as np
import pytest
from views import assert_valid_views

import rodmol
from rodmol.output import h5result
from rodmol.output.stream import RunWriter

SERIES = ("t", "states", "positions", "rotations", "tensions", "markers", "curvature", "external_force",
          "integrated_positions", "quaternion_norm_error")


@pytest.fixture(scope="module")
def model():
    return rodmol.scenarios.get("fetching").model(10)


def assert_same(a, b, names=SERIES):
    for name in names:
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name), err_msg=name)


def test_one_chunk_is_the_in_memory_run_and_reads_back_from_any_path(model, tmp_path):
    memory = rodmol.simulate(model, 0.3)
    streamed = rodmol.simulate(model, 0.3, out=tmp_path)
    assert streamed.success and streamed.stats["steps"] == memory.stats["steps"]
    assert_same(streamed, memory)
    for path in (tmp_path, tmp_path / "result.h5", tmp_path / "rod.xdmf"):
        assert_same(rodmol.load_result(path), memory)
    assert assert_valid_views(tmp_path) == pytest.approx(memory.t)
    np.testing.assert_array_equal(rodmol.energy(model, streamed)["kinetic"], rodmol.energy(model, memory)["kinetic"])
    # The stresses and loads are stored in single precision: 7 digits.
    for name in h5result.SINGLE:
        np.testing.assert_allclose(getattr(streamed, name), getattr(memory, name), rtol=2e-7, atol=0, err_msg=name)
    assert np.abs(streamed.internal_moment).max() > 0


def _chunk_forces(directory):
    """(stored, view) internal force arrays of the first chunk, and whether they are one dataset."""
    import h5py

    with h5py.File(directory / h5result.chunk_name(0), "r") as handle:
        stored, view = handle["internal_force"], handle[f"{h5result.VIEW_GROUP}/internal_force"]
        return stored[()], view[()], stored == view


def test_views_of_every_frame_link_the_stored_forces_else_copy_the_shown(model, tmp_path):
    rodmol.simulate(model, 0.2, out=tmp_path / "all")
    stored, view, same = _chunk_forces(tmp_path / "all")
    assert same and view.shape == stored.shape  # one dataset, two names: written once
    rodmol.simulate(model, 0.2, out=RunWriter(tmp_path / "some", every=3))
    stored, view, same = _chunk_forces(tmp_path / "some")
    assert not same and len(view) == 8  # frames 0, 3, ..., 18 and the last, 20
    np.testing.assert_array_equal(view, stored[[0, 3, 6, 9, 12, 15, 18, 20]])


def test_views_of_long_runs_show_at_most_max_shown_frames(model, tmp_path, monkeypatch):
    from rodmol.output import parts

    assert [parts.view_step(n) for n in (1, 6000, 6001, 60001)] == [1, 1, 2, 11]
    assert parts.view_step(60001, every=1) == 1
    monkeypatch.setattr(parts, "MAX_SHOWN", 10)
    memory = rodmol.simulate(model, 0.3)  # 31 frames: every 4th, and the last of each chunk
    rodmol.simulate(model, 0.3, out=RunWriter(tmp_path, chunk_frames=12))
    shown = [0, 4, 8, 12, 16, 20, 24, 28, 30]  # chunks: frames 0-12, 13-24, 25-30
    assert assert_valid_views(tmp_path) == pytest.approx(memory.t[shown])
    np.testing.assert_array_equal(rodmol.load_result(tmp_path).t, memory.t)  # the result file keeps all


def test_chunks_restart_the_solver_within_its_tolerance(model, tmp_path):
    memory = rodmol.simulate(model, 0.6)
    chunked = rodmol.simulate(model, 0.6, out=RunWriter(tmp_path, chunk_frames=7))
    assert len(list((tmp_path / "frames").glob("chunk_*.h5"))) == 9  # 61 frames: 8 of 7 + the first
    np.testing.assert_array_equal(chunked.t, memory.t)
    # A restart forgets the step history, not the state: the tip moves by the solver's error only.
    assert np.abs(chunked.tip - memory.tip).max() < 1e-4 * model.rod.length  # measured 2.1e-5 m
    assert assert_valid_views(tmp_path) == pytest.approx(memory.t)


def test_write_series_leaves_a_directory_load_result_reads(model, tmp_path):
    memory = rodmol.simulate(model, 0.2)
    view = rodmol.write_series(memory, tmp_path / "x", every=3)
    assert view == tmp_path / "x" / "rod.xdmf"
    assert_same(rodmol.load_result(tmp_path / "x"), memory)
    shown = assert_valid_views(tmp_path / "x")
    assert shown == pytest.approx(list(memory.t[::3]) + [memory.t[-1]])  # every 3rd and the last
    pvd = rodmol.write_series(memory, tmp_path / "y", format="vtp")
    assert pvd.name == "rod.pvd"
    np.testing.assert_allclose(rodmol.load_result(tmp_path / "y").positions, memory.positions)


def test_resume_after_a_kill_repeats_the_uninterrupted_run(model, tmp_path, killed):
    whole = rodmol.simulate(model, 0.5, out=RunWriter(tmp_path / "whole", chunk_frames=8))
    killed(partial(rodmol.simulate, model, 0.5), tmp_path / "cut", 3, chunk_frames=8)
    cut = rodmol.load_result(tmp_path / "cut")
    assert not cut.success and "resume" in cut.message and len(cut.t) == 25
    assert assert_valid_views(tmp_path / "cut") == pytest.approx(cut.t)
    # What a kill in the middle of a write leaves: half-written temporaries (and a file not ours).
    left = [tmp_path / "cut" / "frames" / ".chunk_000003.h5.k3x9.part", tmp_path / "cut" / ".result.h5.q1.part"]
    for file in (*left, tmp_path / "cut" / ".notes.part"):
        file.write_bytes(b"half")
    resumed = rodmol.simulate(model, 0.5, out=tmp_path / "cut", resume=True)
    assert resumed.success
    assert_same(resumed, whole)
    assert not any(file.exists() for file in left) and (tmp_path / "cut" / ".notes.part").exists()
    assert assert_valid_views(tmp_path / "cut") == pytest.approx(whole.t)
    with pytest.raises(rodmol.ParameterError, match="nothing to resume.*finished"):
        rodmol.simulate(model, 0.5, out=tmp_path / "cut", resume=True)


def test_resume_refuses_another_end_time_and_an_empty_directory(model, tmp_path, killed):
    killed(partial(rodmol.simulate, model, 0.3), tmp_path, 1, chunk_frames=5)
    with pytest.raises(rodmol.ParameterError, match="resumed ends at 0.3 s"):
        rodmol.simulate(model, 0.4, out=tmp_path, resume=True)
    with pytest.raises(rodmol.ParameterError, match="nothing to resume"):
        rodmol.simulate(model, 0.3, out=tmp_path / "empty", resume=True)




@pytest.mark.parametrize("where", ["_view_batches", "_fragment"])
def test_ctrl_c_while_a_chunk_is_stored_leaves_the_chunks_before(tmp_path, monkeypatch, where):
    # Ctrl-C lands while the third chunk is stored: before it is handed to the writer's thread
    # (its views being made) or after (its XDMF text being made); either way it is dropped.
    calls, original = [], getattr(RunWriter, where)

    def interrupted(self, *args):
        calls.append(1)
        if len(calls) == 3:
            raise KeyboardInterrupt
        return original(self, *args)

    monkeypatch.setattr(RunWriter, where, interrupted)
    model = rodmol.scenarios.get("bending").model(6)
    with pytest.warns(RuntimeWarning, match="interrupted"):
        rodmol.simulate(model, 0.3, out=RunWriter(tmp_path, chunk_frames=5))
    stopped = rodmol.load_result(tmp_path)
    assert not stopped.success and len(stopped.t) == 11  # the first two chunks: frames 0-10
    assert len(stopped.states) == len(stopped.t)
    assert assert_valid_views(tmp_path) == pytest.approx(list(stopped.t))
