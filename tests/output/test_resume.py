"""Resuming a streamed run: the settings recorded in result.h5 are the ones it
continues with, other ones are refused naming them (unless forced), a chunk
cut short by Ctrl-C is redone so the resumed run is bitwise the uninterrupted
one, and the statistics and the command line's summary tell the resumed part
from the whole run."""

import os
import re
import signal
import subprocess
import sys
import time
from functools import partial

import numpy as np
import pytest
from views import assert_valid_views

import rodmol
from rodmol._fingerprint import model_fingerprint
from rodmol.cli import commands as cli
from rodmol.discretise.layout import StateLayout
from rodmol.output import h5result
from rodmol.output.stream import RunWriter

SERIES = ("t", "states", "positions", "tensions", "markers")
RTOL = 1e-6  # not the default: a resume that forgot it would not repeat the run


@pytest.fixture(scope="module")
def model():
    return rodmol.scenarios.get("fetching").model(10)


@pytest.fixture(scope="module")
def whole(model, tmp_path_factory):
    """The uninterrupted run: 0.5 s, 51 frames in chunks of 8, at rtol = 1e-6."""
    return rodmol.simulate(model, 0.5, rtol=RTOL, out=RunWriter(tmp_path_factory.mktemp("whole"), chunk_frames=8))


def assert_same(a, b):
    for name in SERIES:
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name), err_msg=name)


def cut_run(model, directory, killed, **options):
    """The run of ``whole`` killed after 3 chunks (frames 0-24 kept)."""
    killed(partial(rodmol.simulate, model, 0.5, rtol=RTOL, **options), directory, 3, chunk_frames=8)
    return directory


def test_settings_are_recorded_and_read_back(model, tmp_path):
    rodmol.simulate(model, 0.1, scheme="upwind", rtol=2e-5, atol=1e-7, out=tmp_path, linsolver="sparse")
    settings = h5result.read_index(tmp_path / "result.h5")["info"]["settings"]
    assert settings["scheme"] == "upwind" and settings["backend"] == "cvode" and settings["rtol"] == 2e-5
    assert settings["backend_options"] == {"linsolver": "sparse"} and settings["initial"] == "equilibrium"
    assert settings["n_elements"] == 10 and settings["model"] == model_fingerprint(model)
    assert np.all(np.asarray(settings["atol"]) == 1e-7) and len(settings["atol"]) == StateLayout(10).size


def test_fingerprint_changes_with_every_parameter_and_not_with_the_grid(model):
    seen = {model_fingerprint(model)}
    for changed in (model.replace(gravity=(0.0, -9.8, 0.0)), model.replace(drag=False),
                    model.replace(rod=rodmol.Rod(model.rod.length * (1 + 1e-15), model.rod.radius,
                                                 model.rod.material)),
                    model.replace(cables=model.cables[:-1]), model.replace(medium="air")):
        seen.add(model_fingerprint(changed))
    assert len(seen) == 6  # the last ulp of the length counts
    assert model_fingerprint(model.replace(n_elements=20)) == model_fingerprint(model)  # compared apart


@pytest.mark.subprocess
def test_fingerprint_is_the_same_in_another_process(model):
    code = "import rodmol; from rodmol._fingerprint import model_fingerprint as f; " \
           "print(f(rodmol.scenarios.get('fetching').model(10)))"
    env = dict(os.environ, PYTHONHASHSEED="12345")
    other = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120, env=env)
    assert other.stdout.strip() == model_fingerprint(model), other.stderr


def test_resume_without_rtol_continues_with_the_runs_and_repeats_it(model, whole, tmp_path, killed):
    cut = cut_run(model, tmp_path, killed)
    resumed = rodmol.simulate(model, 0.5, out=cut, resume=True)  # no rtol: the run's 1e-6, not the default
    assert resumed.success
    assert_same(resumed, whole)
    # The work of the chunks kept: the uninterrupted run's steps exactly; each session's apart.
    stats = resumed.stats
    assert stats["steps"] == whole.stats["steps"] and stats["rhs_evals"] == whole.stats["rhs_evals"]
    first, second = stats["sessions"]
    assert stats["resumed_at"] == second["t_start"] == pytest.approx(0.24) and first["t_start"] == 0.0
    assert first["steps"] + second["steps"] == stats["steps"]  # a kill between chunks: nothing redone
    assert stats["wall_time_s"] == pytest.approx(first["wall_time_s"] + second["wall_time_s"])
    assert rodmol.load_result(cut).stats == stats


@pytest.mark.parametrize("change, named", [
    (dict(rtol=1e-5), "rtol: the run 1e-06, this call 1e-05"),
    (dict(scheme="upwind"), "scheme: the run 'centred', this call 'upwind'"),
    (dict(backend="rk23"), "backend: the run 'cvode', this call 'rk23'"),
    (dict(linsolver="sparse"), "backend options: the run none, this call linsolver='sparse'"),
    (dict(initial="straight"), "initial state: the run 'equilibrium', this call 'straight'"),
    (dict(atol=1e-9), "atol: the run default"),
    (dict(model=dict(gravity=(0.0, -9.0, 0.0))), "model (fingerprint of its parameters): the run "),
    (dict(model=dict(n_elements=12)), "number of elements N (the grid): the run 10, this call 12"),
    (dict(output_dt=0.02), "output times are 51 from 0.0 to 0.5 s, this call asks for 26"),
])
def test_resume_with_other_settings_is_refused_naming_them(model, tmp_path, killed, change, named):
    cut = cut_run(model, tmp_path, killed)
    before = (cut / "result.h5").read_bytes()
    change = dict(change)
    asked = model.replace(**change.pop("model", {}))
    with pytest.raises(rodmol.ParameterError) as refused:
        rodmol.simulate(asked, 0.5, out=cut, resume=True, **change)
    assert named in str(refused.value) and str(cut) in str(refused.value)
    assert (cut / "result.h5").read_bytes() == before  # refused before anything was touched


def test_forced_resume_takes_the_new_settings_but_not_another_grid(model, whole, tmp_path, killed):
    cut = cut_run(model, tmp_path, killed)
    with pytest.raises(rodmol.ParameterError, match="number of elements"):
        rodmol.simulate(model.replace(n_elements=12), 0.5, out=cut, resume="force")
    resumed = rodmol.simulate(model, 0.5, rtol=1e-5, out=cut, resume="force")
    assert resumed.success and len(resumed.t) == len(whole.t)
    assert h5result.read_index(cut / "result.h5")["info"]["settings"]["rtol"] == 1e-5
    assert "rtol: the run 1e-06, this call 1e-05" in resumed.stats["sessions"][-1]["forced"][0]
    np.testing.assert_array_equal(resumed.states[:25], whole.states[:25])  # the frames kept
    assert not np.array_equal(resumed.states[-1], whole.states[-1])  # went on at the looser rtol


class Interrupt:
    """A progress callable standing for Ctrl-C: KeyboardInterrupt once the solver passed ``at`` [s]."""

    def __init__(self, at):
        self.at = at

    def __call__(self, t, t_end):
        if t > self.at:
            raise KeyboardInterrupt


def test_resume_after_ctrl_c_redoes_the_chunk_cut_short(model, whole, tmp_path):
    with pytest.warns(RuntimeWarning, match="interrupted"):
        stopped = rodmol.simulate(model, 0.5, rtol=RTOL, out=RunWriter(tmp_path, chunk_frames=8),
                                  progress=Interrupt(0.3))
    assert not stopped.success and "interrupted" in stopped.message
    assert 25 < len(stopped.t) < 33  # Ctrl-C keeps the frames of the chunk it cut short
    resumed = rodmol.simulate(model, 0.5, out=tmp_path, resume=True)
    assert resumed.success and resumed.stats["resumed_at"] == pytest.approx(0.24)  # its last complete chunk
    assert_same(resumed, whole)
    assert resumed.stats["steps"] == whole.stats["steps"]
    first, second = resumed.stats["sessions"]
    assert first["steps"] + second["steps"] > resumed.stats["steps"]  # the chunk cut short was redone


@pytest.mark.parametrize("at", [0.05, -1.0], ids=["in-the-first-chunk", "after-the-first-frame"])
def test_resume_after_ctrl_c_in_the_first_chunk_starts_from_the_initial_state(model, whole, tmp_path, at):
    """A first chunk cut short after its first frame was kept, and the resumed run stored that frame twice."""
    with pytest.warns(RuntimeWarning, match="interrupted"):
        cut = rodmol.simulate(model, 0.5, rtol=RTOL, out=RunWriter(tmp_path, chunk_frames=20), progress=Interrupt(at))
    assert (len(cut.t) == 1) == (at < 0)
    resumed = rodmol.simulate(model, 0.5, out=tmp_path, resume=True)
    reference = rodmol.simulate(model, 0.5, rtol=RTOL, out=RunWriter(tmp_path / "whole", chunk_frames=20))
    assert resumed.stats["resumed_at"] == 0.0
    assert_same(resumed, reference)


#: A run the signal tests stop mid-way: the explicit backend on N = 30 takes a few seconds for 2 s.
SIGNALLED_RUN = [sys.executable, "-m", "rodmol", "run", "--example", "fetching", "--backend", "rk23",
                 "--n-elements", "30", "--t-end", "2", "--chunk-frames", "10", "--quiet"]


@pytest.fixture(scope="module")
def uninterrupted(tmp_path_factory):
    out = tmp_path_factory.mktemp("whole")
    whole = subprocess.run([*SIGNALLED_RUN, "--out", str(out)], capture_output=True, text=True, timeout=300)
    assert whole.returncode == 0, whole.stderr
    return rodmol.load_result(out)


@pytest.mark.subprocess
@pytest.mark.parametrize("sig, code", [(signal.SIGKILL, -signal.SIGKILL), (signal.SIGINT, 130)],
                         ids=["SIGKILL", "SIGINT"])
def test_signal_then_resume_ends_in_the_uninterrupted_state(uninterrupted, tmp_path, sig, code):
    out = tmp_path / "stopped"
    process = subprocess.Popen([*SIGNALLED_RUN, "--out", str(out)], stderr=subprocess.PIPE, text=True)
    try:
        deadline = time.monotonic() + 120
        while time.monotonic() < deadline and process.poll() is None:
            try:  # the index is only ever replaced whole, so it can be read at any moment
                if len(h5result.read_index(out / "result.h5")["chunks"]) >= 3:
                    break
            except (OSError, KeyError):
                pass
            time.sleep(0.02)
        time.sleep(0.05)  # into the next chunk
        process.send_signal(sig)
        process.wait(timeout=60)
    finally:
        if process.poll() is None:
            process.kill()
    assert process.returncode == code, "the run ended before the signal"
    stopped = rodmol.load_result(out)
    assert not stopped.success and 30 <= len(stopped.t) < 201
    assert sig == signal.SIGKILL or "interrupted" in stopped.message
    if sig == signal.SIGKILL:  # after Ctrl-C the views are checked by tests/cli/test_cli.py
        # A chunk's views are written before the index that lists it: a kill between the two
        # leaves the views one whole chunk ahead of the run (every file they name complete).
        views = assert_valid_views(out)
        assert views[:len(stopped.t)] == pytest.approx(stopped.t)
        assert len(views) - len(stopped.t) <= max(h5result.read_index(out / "result.h5")["chunks"].values())
    resumed = subprocess.run([*SIGNALLED_RUN, "--out", str(out), "--resume"], capture_output=True, text=True,
                             timeout=300)
    assert resumed.returncode == 0, resumed.stderr
    final = rodmol.load_result(out)
    assert final.success
    np.testing.assert_array_equal(final.t, uninterrupted.t)
    np.testing.assert_array_equal(final.states, uninterrupted.states)
    np.testing.assert_array_equal(final.positions, uninterrupted.positions)
    assert final.stats["steps"] == uninterrupted.stats["steps"]


# --------------------------------------------------------------------------- the command line

SCENARIO = """name = "short"
arm = "paper"
scenario = "fetching"
[discretization]
n_elements = 10
[solver]
t_end = 0.5
rtol = 1e-6
[output]
chunk_frames = 8
"""


def run_cli(capsys, *args):
    code = cli.main([*map(str, args)])
    captured = capsys.readouterr()
    assert "Traceback" not in captured.err
    return code, captured.out, captured.err


def test_cli_resume_says_so_and_sums_up_the_part_and_the_whole(tmp_path, capsys, killed, whole):
    scenario = tmp_path / "short.toml"
    scenario.write_text(SCENARIO)
    out = tmp_path / "out"
    killed(rodmol.load_scenario(scenario).simulate, out, 3, chunk_frames=8)
    code, text, _ = run_cli(capsys, "run", scenario, "--out", out, "--resume")
    assert code == 0
    result = rodmol.load_result(out)
    assert_same(result, whole)
    part, st = result.stats["sessions"][-1], result.stats
    assert f"resuming the run in {out} at t = 0.24 s (frame 24 of 50" in text
    assert "done (resumed at t = 0.24 s)" in text
    assert f"{st['steps']} steps, {st['rhs_evals']} RHS evaluations" in text and st["steps"] == whole.stats["steps"]
    this = re.search(r"this part +[\d.]+ s run \(([\d.]+) s integrating 0.24 to 0.5 s in (\d+) steps, "
                     r"([\d.]+) x real time", text)
    assert this, text
    assert float(this[1]) == pytest.approx(part["wall_time_s"], abs=0.006) and int(this[2]) == part["steps"]
    assert float(this[3]) == pytest.approx(0.26 / part["wall_time_s"], rel=1e-2)
    every = re.search(r"whole run +([\d.]+) s integrating 0.5 s of simulated time in 2 sessions, ([\d.]+) x", text)
    assert every, text
    assert float(every[1]) == pytest.approx(st["wall_time_s"], abs=0.006)
    assert float(every[2]) == pytest.approx(0.5 / st["wall_time_s"], rel=1e-2)


def test_cli_resume_of_an_edited_scenario_is_refused_unless_forced(tmp_path, capsys, killed):
    scenario = tmp_path / "short.toml"
    scenario.write_text(SCENARIO)
    out = tmp_path / "out"
    killed(rodmol.load_scenario(scenario).simulate, out, 3, chunk_frames=8)
    scenario.write_text(SCENARIO.replace("rtol = 1e-6", "rtol = 1e-5").replace("t_end", "initial = 'straight'\nt_end"))
    code, _, err = run_cli(capsys, "run", scenario, "--out", out, "--resume")
    assert code == 2
    assert "rtol: the run 1e-06, this call 1e-05" in err and "initial state: the run 'equilibrium'" in err
    assert "--resume-anyway" in err
    code, _, err = run_cli(capsys, "run", scenario, "--out", out, "--resume-anyway", "--quiet")
    assert code == 0, err
    assert rodmol.load_result(out).success
    # It went on from its restart point: the initial state recorded stays the run's.
    assert h5result.read_index(out / "result.h5")["info"]["settings"]["initial"] == "equilibrium"


@pytest.mark.parametrize("damage", ["index", "chunk"])
def test_cli_resume_of_a_damaged_run_names_the_file(tmp_path, capsys, killed, model, damage):
    scenario = tmp_path / "short.toml"
    scenario.write_text(SCENARIO)
    out = tmp_path / "out"
    killed(rodmol.load_scenario(scenario).simulate, out, 3, chunk_frames=8)
    broken = out / ("result.h5" if damage == "index" else h5result.chunk_name(2))
    broken.write_bytes(broken.read_bytes()[:300])  # truncated
    code, _, err = run_cli(capsys, "run", scenario, "--out", out, "--resume")
    assert code == 2
    assert f"cannot resume from {str(broken)!r}: the file is damaged, truncated" in err
