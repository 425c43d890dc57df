"""Ctrl-C and SIGTERM on ``rodmol run``, a rod's run and a system's alike: the run stops at
its next step with its files whole, exits 130 (143), says how to resume it, and ``--resume``
ends it exactly where the uninterrupted run ends. A signal that lands inside a chunk's
write, or anywhere at random in a system's run, is never lost (it used to be swallowed by
a weakref callback now and then) and never cuts a file short."""

import random
import signal
import subprocess
import sys
import time

import numpy as np
import pytest
from cli_helpers import EXAMPLES
from views import assert_valid_views

import rodmol
from rodmol.cli import commands as cli
from rodmol.output import h5result

ROD = """name = "rod"
arm = "paper"
scenario = "fetching"
[discretization]
n_elements = 20
[solver]
t_end = 1.0
backend = "rk23"
[output]
chunk_frames = 10
"""
#: A second or so of integration: a signal sent once the first chunk is written lands mid-run.
SYSTEM_RUN = {"t_end = 0.5": "t_end = 1.5", "output_dt = 0.05": "output_dt = 0.02"}


def system_text(chunk_frames=5, **replaced):
    text = (EXAMPLES / "two_arms.toml").read_text()
    for old, new in {**SYSTEM_RUN, **replaced}.items():
        assert old in text, old
        text = text.replace(old, new)
    return text + f"\n[output]\nchunk_frames = {chunk_frames}\n"


@pytest.fixture(scope="module")
def scenarios(tmp_path_factory):
    """The rod's and the system's scenario files, and their uninterrupted runs."""
    folder = tmp_path_factory.mktemp("scenarios")
    found = {}
    for kind, text in (("rod", ROD), ("system", system_text())):
        scenario = folder / f"{kind}.toml"
        scenario.write_text(text)
        whole = folder / f"{kind}-whole"
        assert cli.main(["run", str(scenario), "--out", str(whole), "--quiet"]) == 0
        found[kind] = scenario, rodmol.load_result(whole)
    return found


def assert_same(a, b):
    """Bitwise the same frames (every rod's and body's state)."""
    np.testing.assert_array_equal(a.t, b.t)
    np.testing.assert_array_equal(a.states, b.states)


def assert_stopped_and_resumable(out, sig, stderr, whole):
    """What a signal left in ``out``: said so, whole and valid files with the uninterrupted
    run's first frames, a run that resumes to the uninterrupted one."""
    assert "Traceback" not in stderr and "Exception ignored" not in stderr, stderr
    assert "can be resumed" in stderr and "`--resume`" in stderr, stderr
    stopped = rodmol.load_result(out)
    assert not stopped.success and f"interrupted by {sig.name}" in stopped.message
    assert 1 <= len(stopped.t) < len(whole.t)
    np.testing.assert_array_equal(stopped.states, whole.states[:len(stopped.t)])
    rods = getattr(stopped, "rods", ())  # a system's: each in a folder of its own (one chunk more, maybe)
    assert assert_valid_views(out, "bodies.xdmf" if rods else "rod.xdmf") == pytest.approx(stopped.t)
    for name in rods:
        assert len(assert_valid_views(out / name)) >= len(stopped.t)


def resume(scenario, out, whole):
    assert cli.main(["run", str(scenario), "--out", str(out), "--resume", "--quiet"]) == 0
    final = rodmol.load_result(out)
    assert final.success
    assert_same(final, whole)


def signalled(scenario, out, sig, after=None):
    """``rodmol run scenario --out out`` in a subprocess, sent ``sig`` once its first chunk file
    is written (``after``: that many seconds after it says it began); returns (exit code, stderr)."""
    command = [sys.executable, "-u", "-m", "rodmol", "run", str(scenario), "--out", str(out)]
    process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        if after is None:
            first, deadline = out / h5result.chunk_name(0), time.monotonic() + 120
            while not first.exists() and process.poll() is None and time.monotonic() < deadline:
                time.sleep(0.005)
        else:
            process.stdout.readline()  # its first line: the run began (the signals are its own)
            time.sleep(after)
        process.send_signal(sig)
        _, stderr = process.communicate(timeout=120)
    finally:
        if process.poll() is None:
            process.kill()
    return process.returncode, stderr


@pytest.mark.subprocess
@pytest.mark.parametrize("kind, sig", [("rod", signal.SIGINT), ("system", signal.SIGINT),
                                       ("system", signal.SIGTERM)])
def test_a_signal_stops_the_run_resumably_and_resume_ends_as_the_uninterrupted_run(scenarios, tmp_path, kind,
                                                                                     sig):
    scenario, whole = scenarios[kind]
    out = tmp_path / "out"
    code, stderr = signalled(scenario, out, sig)
    assert code == cli.EXIT_SIGNAL[sig], stderr
    assert_stopped_and_resumable(out, sig, stderr, whole)
    resume(scenario, out, whole)


@pytest.mark.parametrize("kind", ["rod", "system"])
def test_a_signal_inside_a_chunk_write_lets_it_finish_and_stops_after(scenarios, tmp_path, monkeypatch,
                                                                       capsys, kind):
    """Where Python's own handler would raise: the chunk is written whole, the run stops at its next step."""
    scenario, whole = scenarios[kind]
    write_chunk, calls = h5result.write_chunk, []

    def signalled_write(*args, **kwargs):
        calls.append(args[1])
        if len(calls) == 3:
            signal.raise_signal(signal.SIGINT)  # a system's own chunk: in the main thread, the handler's
        return write_chunk(*args, **kwargs)

    monkeypatch.setattr(h5result, "write_chunk", signalled_write)
    out = tmp_path / "out"
    code = cli.main(["run", str(scenario), "--out", str(out), "--quiet"])
    stderr = capsys.readouterr().err
    assert code == cli.EXIT_INTERRUPTED, stderr
    assert_stopped_and_resumable(out, signal.SIGINT, stderr, whole)
    monkeypatch.undo()
    resume(scenario, out, whole)


@pytest.mark.slow
@pytest.mark.subprocess
def test_fifty_signals_at_random_moments_of_a_system_run_each_stop_it_resumably(tmp_path):
    """From its start (kernels, initial state) to well before its end, in the solver, the
    chunk writes and between them; each run stopped is resumed to the uninterrupted one."""
    scenario = tmp_path / "system.toml"
    scenario.write_text(system_text(chunk_frames=3, **{"t_end = 0.5": "t_end = 3.0"}))
    assert cli.main(["run", str(scenario), "--out", str(tmp_path / "whole"), "--quiet"]) == 0
    whole = rodmol.load_result(tmp_path / "whole")
    moments = random.Random(33)
    for k in range(50):
        out = tmp_path / f"run{k}"
        after = moments.uniform(0.0, 1.0)
        code, stderr = signalled(scenario, out, signal.SIGINT, after)
        assert code == cli.EXIT_INTERRUPTED, (k, after, stderr)
        assert_stopped_and_resumable(out, signal.SIGINT, stderr, whole)
        resume(scenario, out, whole)
