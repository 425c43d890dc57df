"""Signals and files: SIGTERM keeps the frames like Ctrl-C, one run per output
directory, atomic writes with unique temporaries, and clear messages (exit
code 3, no traceback) when outputs cannot be written, with what was written
still valid."""

import errno
import json
import os
import signal
import socket
import subprocess
import sys
import threading

import numpy as np
import pytest
from cli_helpers import EXAMPLES, assert_interrupted_run, assert_valid_series, slow_run
from views import assert_valid_views

import rodmol
from rodmol.cli import commands as cli
from rodmol.output import writers
from rodmol.output.lock import LOCK_NAME, OutputLock

SMALL = ["run", str(EXAMPLES / "uniform_arm_air.toml"), "--n-elements", "6", "--t-end", "0.05", "--quiet"]


def run_cli(capsys, *args):
    code = cli.main([*SMALL, *map(str, args)])
    captured = capsys.readouterr()
    assert "Traceback" not in captured.err
    return code, captured.err


@pytest.mark.subprocess
def test_sigterm_keeps_a_valid_partial_run_and_a_second_run_is_refused(tmp_path):
    out = tmp_path / "busy"
    process = slow_run(out)
    try:
        # A second run into the same directory is refused while the first runs.
        second = subprocess.run([sys.executable, "-m", "rodmol", *SMALL, "--out", str(out)],
                                capture_output=True, text=True, timeout=120)
        assert second.returncode == 2, second.stderr
        assert f"another rodmol run (pid {process.pid}" in second.stderr
        assert "Traceback" not in second.stderr
        process.send_signal(signal.SIGTERM)  # what `timeout`, schedulers and docker stop send
        stdout, stderr = process.communicate(timeout=60)
    finally:
        if process.poll() is None:
            process.kill()
    assert process.returncode == 143, stderr
    assert_interrupted_run(out, stdout)
    assert not (out / LOCK_NAME).exists()


def test_lock_held_by_a_live_process_is_refused(tmp_path, capsys):
    (tmp_path / LOCK_NAME).write_text(json.dumps({"host": socket.gethostname(), "pid": os.getppid()}))
    code, err = run_cli(capsys, "--out", tmp_path)
    assert code == 2 and f"pid {os.getppid()}" in err and "choose another --out" in err
    assert not (tmp_path / "result.npz").exists() and not (tmp_path / "result.h5").exists()


def test_stale_lock_of_a_dead_process_is_taken_over(tmp_path, capsys):
    dead = subprocess.Popen([sys.executable, "-c", "pass"])
    dead.wait()
    (tmp_path / LOCK_NAME).write_text(json.dumps({"host": socket.gethostname(), "pid": dead.pid}))
    code, err = run_cli(capsys, "--out", tmp_path)
    assert code == 0, err
    assert rodmol.load_result(tmp_path).success
    assert not (tmp_path / LOCK_NAME).exists()


def test_lock_is_exclusive_and_released(tmp_path):
    with OutputLock(tmp_path) as lock:
        assert json.loads(lock.path.read_text())["pid"] == os.getpid()
        with pytest.raises(rodmol.ParameterError, match="another rodmol run"):
            OutputLock(tmp_path).acquire()
    assert not (tmp_path / LOCK_NAME).exists()


@pytest.mark.parametrize("fmt, name", [("vtp", "result.npz"), ("xdmf", "result.h5"), ("xdmf", "rod.xdmf"),
                                       ("vtp", "result.h5")])
def test_a_directory_where_the_result_file_goes_is_refused_before_the_run(tmp_path, capsys, fmt, name):
    (tmp_path / name).mkdir()
    code, err = run_cli(capsys, "--out", tmp_path, "--format", fmt)
    assert code == cli.EXIT_USAGE
    assert f"{str(tmp_path / name)!r} is a directory" in err
    assert sorted(p.name for p in tmp_path.iterdir()) == [name]  # nothing run, nothing written


def test_out_being_a_file(tmp_path, capsys):
    (tmp_path / "file").write_text("not a directory")
    code, err = run_cli(capsys, "--out", tmp_path / "file")
    assert code == cli.EXIT_USAGE and "cannot create the output directory" in err


def test_vtk_being_a_file_is_refused_before_the_run(tmp_path, capsys):
    (tmp_path / "vtk").write_text("not a directory")
    code, err = run_cli(capsys, "--out", tmp_path, "--format", "vtp")
    assert code == cli.EXIT_USAGE and "vtk" in err and "is a file, where rodmol writes a folder" in err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["vtk"]  # nothing written, the file kept
    assert (tmp_path / "vtk").read_text() == "not a directory"


def _full_disk(*args, **kwargs):
    raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))


def test_full_disk_while_writing_frames(tmp_path, capsys, monkeypatch):
    original = writers.save_vtp
    calls = []

    def save_vtp(mesh, path):
        calls.append(path)
        if len(calls) > 7:  # two frames of (rod, cables, markers) fit, then the disk is full
            _full_disk()
        original(mesh, path)

    monkeypatch.setattr(writers, "save_vtp", save_vtp)
    code, err = run_cli(capsys, "--out", tmp_path, "--format", "vtp")
    assert code == cli.EXIT_OUTPUT
    assert "No space left on device" in err and "outputs written before it are valid" in err
    assert assert_valid_series(tmp_path) == pytest.approx([0.0, 0.02])
    assert rodmol.load_result(tmp_path / "result.npz").success


def test_full_disk_while_streaming_keeps_the_chunks_before(tmp_path, capsys, monkeypatch):
    from rodmol.output import h5result

    original, calls = h5result.write_chunk, []

    def write_chunk(*args, **kwargs):
        calls.append(args)
        if len(calls) > 1:
            _full_disk()
        return original(*args, **kwargs)

    monkeypatch.setattr(h5result, "write_chunk", write_chunk)
    text = (EXAMPLES / "uniform_arm_air.toml").read_text()
    (tmp_path / "s.toml").write_text(text.replace("[output]", "[output]\nchunk_frames = 2", 1))
    (tmp_path / "tension_ramp.csv").write_text((EXAMPLES / "tension_ramp.csv").read_text())
    code = cli.main(["run", str(tmp_path / "s.toml"), "--n-elements", "6", "--t-end", "0.05", "--quiet",
                     "--out", str(tmp_path / "out")])
    err = capsys.readouterr().err
    assert code == cli.EXIT_OUTPUT and "Traceback" not in err
    assert "No space left on device" in err and "outputs written before it are valid" in err
    result = rodmol.load_result(tmp_path / "out")
    assert list(result.t) == pytest.approx([0.0, 0.02, 0.04]) and not result.success
    assert assert_valid_views(tmp_path / "out") == pytest.approx([0.0, 0.02, 0.04])


def test_full_disk_while_saving_keeps_the_previous_result(tmp_path, monkeypatch):
    first = rodmol.simulate(rodmol.paper_arm(6, tensions={11: 0.5}), 0.02, initial="straight")
    first.save(tmp_path / "result.npz")

    def savez_half(handle, **arrays):
        handle.write(b"PK\x03\x04 half a zip file")
        _full_disk()

    monkeypatch.setattr(np, "savez_compressed", savez_half)
    with pytest.raises(OSError, match="No space left"):
        first.save(tmp_path / "result.npz", overwrite=True)
    monkeypatch.undo()
    back = rodmol.load_result(tmp_path / "result.npz")
    assert np.array_equal(back.positions, first.positions)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["result.npz"]  # no temporary left


def test_concurrent_saves_never_share_a_temporary(tmp_path):
    results = [rodmol.simulate(rodmol.paper_arm(6, tensions={11: tension}), 0.02, initial="straight")
               for tension in (0.2, 0.8)]
    target = tmp_path / "result.npz"
    errors = []

    def save(result):
        try:
            for _ in range(5):
                result.save(target, overwrite=True)
        except Exception as exc:  # noqa: BLE001 (reported below)
            errors.append(exc)

    threads = [threading.Thread(target=save, args=(r,)) for r in results]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    assert not errors
    back = rodmol.load_result(target)
    assert any(np.array_equal(back.tensions, r.tensions) for r in results)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["result.npz"]
    assert oct(target.stat().st_mode & 0o777) == oct(0o666 & ~_umask())


def _umask():
    mask = os.umask(0)
    os.umask(mask)
    return mask


def test_unwritable_output_directory(tmp_path, capsys):
    (tmp_path / "file").write_text("x")
    code, err = run_cli(capsys, "--out", tmp_path / "file" / "below")
    assert code == 2 and "cannot create the output directory" in err


def test_max_wall_time_option(tmp_path, capsys):
    code, err = run_cli(capsys, "--out", tmp_path, "--max-wall-time", "1e-9")
    assert code == cli.EXIT_FAILED and "wall-time budget" in err
    result = rodmol.load_result(tmp_path)
    assert not result.success and "max_wall_time = 1e-09 s" in result.message
