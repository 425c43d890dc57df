"""The helper process that compiles kernels on a second core during a run's first compilation."""

import os
import shutil
import subprocess
import sys
import time
import types

import numpy as np
import pytest

from rodmol.discretise import compile_ahead, compiling, kernel_cache
from rodmol.solve import kernels


def _dispatcher(cache_path):
    return types.SimpleNamespace(_cache=types.SimpleNamespace(_cache_path=str(cache_path)))


def test_the_helper_starts_only_where_it_helps(tmp_path, monkeypatch):
    missing = _dispatcher(tmp_path)
    monkeypatch.setattr(compile_ahead, "cached", lambda d: False)
    monkeypatch.setattr(compile_ahead, "cores", lambda: 2)
    monkeypatch.setattr(compile_ahead.os, "getloadavg", lambda: (1.0, 1.0, 1.0))  # this run alone
    monkeypatch.delenv(compile_ahead.SWITCH, raising=False)
    assert compile_ahead.wanted([missing])
    monkeypatch.setattr(compile_ahead.os, "getloadavg", lambda: (4.0, 4.0, 4.0))  # other jobs on both cores
    assert not compile_ahead.wanted([missing])
    monkeypatch.setenv(compile_ahead.SWITCH, "1")
    assert compile_ahead.wanted([missing])  # asked for
    monkeypatch.delenv(compile_ahead.SWITCH)
    monkeypatch.setattr(compile_ahead.os, "getloadavg", lambda: (1.0, 1.0, 1.0))
    monkeypatch.setattr(compile_ahead, "cores", lambda: 1)
    assert not compile_ahead.wanted([missing])  # one core: nothing to gain
    monkeypatch.setattr(compile_ahead, "cores", lambda: 2)
    assert not compile_ahead.wanted([_dispatcher(tmp_path / "absent")])  # a cache it cannot write
    monkeypatch.setenv(compile_ahead.SWITCH, "0")
    compile_ahead.start([missing])
    assert not compile_ahead.wanted([missing]) and not compile_ahead.running()
    monkeypatch.delenv(compile_ahead.SWITCH)
    monkeypatch.setattr(compile_ahead, "cached", lambda d: True)
    assert not compile_ahead.wanted([missing])  # all in the cache already


def test_a_helper_past_its_time_is_stopped_and_the_run_goes_on(monkeypatch):
    helper = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(60)"])
    monkeypatch.setattr(compile_ahead, "_helper", helper)
    started = time.perf_counter()
    compile_ahead.finish(timeout=0.2)
    assert time.perf_counter() - started < 10.0 and helper.returncode is not None
    assert not compile_ahead.running()
    compile_ahead.finish()  # no helper: nothing to do


def test_an_interrupted_compilation_stops_the_helper_without_waiting(monkeypatch):
    helper = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(60)"])
    monkeypatch.setattr(compile_ahead, "start", lambda dispatchers: setattr(compile_ahead, "_helper", helper))

    def interrupted(dispatcher, signature, ahead):
        raise KeyboardInterrupt

    monkeypatch.setattr(compiling, "_compile", interrupted)
    monkeypatch.setattr(compiling, "_UNCOMPILED", [(None, None, False)])
    started = time.perf_counter()
    with pytest.raises(KeyboardInterrupt):
        compiling.compile_signatures()
    assert time.perf_counter() - started < 10.0 and helper.returncode is not None
    assert not compile_ahead.running()


def test_the_progress_line_says_when_a_helper_compiles_too(monkeypatch):
    monkeypatch.setattr(kernels, "cached", lambda dispatcher: False)
    monkeypatch.setattr(compiling, "helper_wanted", lambda: True)
    assert "once on 2 cores" in kernels.stage_text()
    monkeypatch.setattr(compiling, "helper_wanted", lambda: False)
    assert "once:" in kernels.stage_text() and "cores" not in kernels.stage_text()


_RUN = """
import sys
from numba.core import event
compiled = []
class Recorder(event.Listener):
    def on_start(self, ev):
        compiled.append(ev.data["dispatcher"].py_func.__name__)
    def on_end(self, ev):
        pass
event.register("numba:compile", Recorder())
import numpy as np
import rodmol
result = rodmol.simulate(rodmol.scenarios.get("bending").model(6), 0.05)
np.save(sys.argv[1], result.tip)
print(" ".join(sorted(set(compiled))))
"""


@pytest.mark.slow
@pytest.mark.subprocess
def test_a_fresh_cache_is_compiled_on_two_cores_and_a_killed_helper_leaves_it_sound(tmp_path):
    """In a fresh copy of the package: a helper killed while it compiles, then a run whose own
    helper compiles the preconditioner's and post-processing kernels (the run loads them and
    compiles only the rest) with the same tip as this tree's run."""
    tree = tmp_path / "tree"
    shutil.copytree(kernel_cache.PACKAGE, tree / "rodmol", ignore=shutil.ignore_patterns("__pycache__"))
    env = dict(os.environ, PYTHONPATH=str(tree))
    env[compile_ahead.SWITCH] = "1"  # however busy the machine running the tests
    killed = subprocess.Popen([sys.executable, "-c", compile_ahead._CODE.format(parent=str(tree))], env=env,
                              cwd=tmp_path)
    time.sleep(3.0)  # importing rodmol, then compiling
    killed.kill()
    killed.wait()
    run = subprocess.run([sys.executable, "-c", _RUN, str(tmp_path / "tip.npy")], env=env, cwd=tmp_path,
                         capture_output=True, text=True, timeout=600, check=False)  # cwd: not this tree's rodmol
    assert run.returncode == 0, run.stderr
    compiled_here = set(run.stdout.split())
    assert "rhs" in compiled_here
    if compile_ahead.cores() >= 2:
        assert not {"block_setup", "_chords", "_rotate", "_normalise"} & compiled_here
    import rodmol

    expected = rodmol.simulate(rodmol.scenarios.get("bending").model(6), 0.05).tip
    assert np.array_equal(np.load(tmp_path / "tip.npy"), expected)
