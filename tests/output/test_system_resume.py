"""A system's streamed run: frames chunk by chunk into system.h5 and each rod's
run directory; a run killed (or interrupted) part way reads back up to its
last listed chunk and, resumed, ends bitwise where the uninterrupted run does,
with the settings recorded in system.h5; another system or other settings are
refused naming each, unless forced."""

import dataclasses
import json
from functools import partial
from pathlib import Path

import numpy as np
import pytest

import rodmol
from rodmol._fingerprint import system_fingerprints
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
    left = [tmp_path / ".system.h5.x1.part", tmp_path / "frames" / ".chunk_000001.h5.x2.part"]
    for file in left:  # what a kill in the middle of writing a file leaves beside it
        file.write_bytes(b"\x89HDF half")
    resumed = rodmol.simulate(two_arms(), T_END, out=tmp_path, resume=True)  # rtol, linsolver: recorded
    assert resumed.success and not any(file.exists() for file in left)
    assert_same(resumed, whole)
    assert_same(rodmol.load_result(tmp_path), whole)
    assert resumed.stats["rhs_evals"] < whole.stats["rhs_evals"]  # frames 4-10 only


# In the second chunk, the first, after the first frame.
@pytest.mark.parametrize("at, frames", [(0.065, (5, 7)), (0.015, (2, 3)), (-1.0, (1, 1))])
def test_an_interrupted_run_keeps_its_frames_and_resumes(two_arms, whole, tmp_path, monkeypatch, at, frames):
    """Cut inside the first chunk, the rods' reopening rolled back to frame 0 already, and the
    system's roll-back to it raised an IndexError after emptying system.h5 (found by review);
    cut after its first frame, the chunk holding only that frame was kept, and stored twice."""
    rates = Assembly.__call__

    def ctrl_c(self, t, y, out=None):  # Ctrl-C inside CVODE's step
        if t > at:
            raise KeyboardInterrupt
        return rates(self, t, y, out)

    monkeypatch.setattr(Assembly, "__call__", ctrl_c)
    with pytest.warns(RuntimeWarning, match="interrupted"):
        cut = run(two_arms(), out=SystemRunWriter(tmp_path, chunk_frames=CHUNK))
    monkeypatch.undo()
    assert not cut.success and frames[0] <= len(cut.t) <= frames[1]
    assert np.array_equal(cut.states, whole.states[:len(cut.t)])
    kept = rodmol.load_result(tmp_path)  # every frame it reached, the cut chunk too
    assert not kept.success and np.array_equal(kept.states, cut.states)
    assert_same(rodmol.simulate(two_arms(), T_END, out=tmp_path, resume=True), whole)


def test_resume_refuses_what_it_cannot_continue(two_arms, tmp_path, killed_system):
    with pytest.raises(ParameterError, match="nothing to resume"):
        rodmol.simulate(two_arms(), T_END, out=tmp_path, resume=True)
    killed_system(partial(run, two_arms()), tmp_path, 1, chunk_frames=CHUNK)
    with pytest.raises(ParameterError, match="ends at 0.1 s"):
        rodmol.simulate(two_arms(), 0.2, out=tmp_path, resume=True)
    with pytest.raises(ParameterError, match="initial state: the run 'straight', this call 'equilibrium'"):
        rodmol.simulate(two_arms(), T_END, out=tmp_path, resume=True, initial="equilibrium")
    with pytest.raises(ParameterError, match="output times"):
        rodmol.simulate(two_arms(), T_END, out=tmp_path, resume=True, output_dt=0.02)
    with pytest.raises(ParameterError, match="rods"):  # another system
        rodmol.simulate(rodmol.System(rods={"right": two_arms().rods["right"]}), T_END, out=tmp_path, resume=True)
    with pytest.raises(ParameterError, match="`resume` or `overwrite=True`"):
        rodmol.simulate(two_arms(), T_END, out=tmp_path, resume=True, overwrite=True)


def changed(system, **bodies):
    """``system`` (two_arms') with the head's arguments changed by ``bodies``."""
    head = dataclasses.replace(system.bodies["head"], **bodies)
    return rodmol.System(rods=system.rods, bodies={"head": head}, joints=system.joints, medium=system.medium,
                         gravity=system.gravity)


def test_resuming_a_changed_system_or_other_settings_is_refused_naming_each(two_arms, tmp_path, killed_system):
    killed_system(partial(run, two_arms()), tmp_path, 1, chunk_frames=CHUNK)
    index = (tmp_path / "system.h5").read_bytes()
    heavier = changed(two_arms(), mass=0.35)
    sideways = rodmol.System(rods={n: m.replace(gravity=(0.0, 0.0, 0.0)) for n, m in two_arms().rods.items()},
                             bodies=two_arms().bodies, joints=two_arms().joints, medium="water",
                             gravity=(0.0, -1.0, -9.81))
    pulled = two_arms()
    cable = dataclasses.replace(pulled.rods["right"].cables[0], tension=lambda t: 0.4 * min(t / 0.1, 1.0))
    pulled.rods["right"] = pulled.rods["right"].replace(cables=[cable])
    for system, options, named in [
        (heavier, {}, "system (fingerprints of its parts): changed: body 'head'"),
        (sideways, {}, "gravity"),
        (pulled, {}, "changed: rod 'right'\n"),  # that rod only
        (two_arms(), dict(rtol=1e-5), "rtol: the run 2e-05, this call 1e-05"),
        (two_arms(), dict(linsolver="gmres"), "backend options: the run linsolver='sparse', this call "
                                              "linsolver='gmres'"),
    ]:
        with pytest.raises(ParameterError) as refused:
            rodmol.simulate(system, T_END, out=tmp_path, resume=True, **options)
        assert named in str(refused.value) + "\n" and "resume='force'" in str(refused.value)
    assert (tmp_path / "system.h5").read_bytes() == index  # refused before anything was touched
    finer = rodmol.System(rods={n: m.replace(n_elements=7) for n, m in two_arms().rods.items()},
                          bodies=two_arms().bodies, joints=two_arms().joints, medium="water",
                          gravity=two_arms().gravity)
    with pytest.raises(ParameterError, match="grids"):  # the states kept fix the layout: not even forced
        rodmol.simulate(finer, T_END, out=tmp_path, resume="force")


def test_a_forced_resume_goes_on_with_the_changed_system(two_arms, whole, tmp_path, killed_system):
    import h5py

    killed_system(partial(run, two_arms()), tmp_path, 1, chunk_frames=CHUNK)
    heavier = changed(two_arms(), mass=0.35)
    resumed = rodmol.simulate(heavier, T_END, out=tmp_path, resume="force")
    assert resumed.success and np.array_equal(resumed.t, whole.t)
    assert np.array_equal(resumed.states[:5], whole.states[:5])  # the frames kept
    again = rodmol.simulate(heavier, T_END, out=SystemRunWriter(tmp_path / "again", chunk_frames=CHUNK),
                            initial=whole.states[4], t0=whole.t[4], output_times=whole.t[4:], rtol=RTOL,
                            linsolver="sparse")
    assert np.array_equal(resumed.states[5:], again.states[1:])  # then the heavier head's run from frame 4
    assert not np.array_equal(resumed.states[-1], whole.states[-1])
    with h5py.File(tmp_path / "system.h5") as handle:
        info = json.loads(handle.attrs["info"])
    assert info["settings"]["system"] == system_fingerprints(heavier)  # a further resume compares with it
    (forced,) = info["forced"]
    assert forced["t_start"] == pytest.approx(0.04) and "body 'head'" in forced["changed"][0]


def test_the_command_line_resumes_a_system_anyway(tmp_path, killed_system, capsys):
    import h5py

    from rodmol.cli.commands import main

    scenario = Path(__file__).parents[2] / "examples" / "two_arms.toml"
    assert main(["run", str(scenario), "--out", str(tmp_path), "--chunk-frames", "4", "--t-end", "0.3",
                 "--quiet"]) == 0
    with h5py.File(tmp_path / "system.h5") as index:  # the option's chunks: frames 0-4, 5-6
        assert list(index["chunk_frames"][()]) == [5, 2]
    spec = rodmol.load_scenario(scenario)
    killed_system(spec.simulate, tmp_path, 1, chunk_frames=4, overwrite=True)  # 11 frames: frames 0-4 kept
    assert main(["run", str(scenario), "--out", str(tmp_path), "--resume", "--scheme", "upwind", "--quiet"]) == 2
    assert "scheme: the run 'centred', this call 'upwind'" in capsys.readouterr().err
    assert main(["run", str(scenario), "--out", str(tmp_path), "--resume-anyway", "--scheme", "upwind",
                 "--quiet"]) == 0
    result = rodmol.load_result(tmp_path)
    assert result.success and len(result.t) == 11


def test_an_overwrite_that_cannot_start_keeps_the_earlier_run(tmp_path, capsys):
    """`--overwrite` replaces the earlier run when the new one begins, after its checks and its
    initial state: here the equilibrium start fails (the head is held by nothing), and the
    earlier run stays whole (the writer cleared it on construction, before the equilibrium)."""
    from rodmol.cli.commands import main

    scenario = Path(__file__).parents[2] / "examples" / "two_arms.toml"
    out = tmp_path / "run"
    assert main(["run", str(scenario), "--out", str(out), "--t-end", "0.05", "--quiet"]) == 0
    before = rodmol.load_result(out)
    failing = tmp_path / "equilibrium.toml"
    failing.write_text(scenario.read_text().replace("t_end = 0.5", 't_end = 0.05\ninitial = "equilibrium"'))
    assert main(["run", str(failing), "--out", str(out), "--overwrite", "--quiet"]) == 1
    assert "rodmol: error:" in capsys.readouterr().err  # a message, not a traceback
    after = rodmol.load_result(out)
    assert after.success and np.array_equal(after.states, before.states)
