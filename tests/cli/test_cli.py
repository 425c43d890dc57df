"""The command line end to end, in subprocesses: every shipped example, errors, Ctrl-C."""

import os
import re
import signal
import time

import numpy as np
import pytest
import tomllib
from cli_helpers import (
    EXAMPLES,
    SCENARIOS,
    SYSTEM_SCENARIOS,
    assert_interrupted_run,
    assert_valid_series,
    rodmol_cli,
    slow_run,
)
from views import assert_valid_views

import rodmol
from rodmol.solve.interrupts import DeferredSignals


@pytest.mark.subprocess
def test_run_a_system_file_writes_every_part(tmp_path):
    scenario = next(p for p in SYSTEM_SCENARIOS if p.stem == "two_arms")
    out = tmp_path / "out"
    run = rodmol_cli("run", scenario, "--out", out, "--t-end", 0.05, "--quiet")
    assert run.returncode == 0 and run.stdout == "", (run.stdout, run.stderr)  # --quiet: nothing but errors
    result = rodmol.load_result(out)
    assert result.success and result.names == ["right", "left", "head"] and result.t[-1] == pytest.approx(0.05)
    for rod in result.rods:
        assert assert_valid_views(out / rod) == pytest.approx(list(result.t))
    again = rodmol_cli("run", scenario, "--out", out, "--t-end", 0.05, "--quiet")
    assert again.returncode == 2 and "--overwrite" in again.stderr  # the earlier run is kept
    resumed = rodmol_cli("run", scenario, "--out", out, "--t-end", 0.05, "--resume", "--quiet")
    assert resumed.returncode == 2 and "finished" in resumed.stderr  # streamed, but nothing left to do
    plot = rodmol_cli("plot", out)
    assert plot.returncode == 0 and (out / "tip_path.png").stat().st_size > 10_000


def test_version():
    proc = rodmol_cli("--version")
    assert proc.returncode == 0 and proc.stdout.strip() == f"rodmol {rodmol.__version__}"


def test_examples_are_shipped():
    assert {p.stem for p in SCENARIOS} >= {"bending", "reaching", "fetching", "uniform_arm_air"}


@pytest.mark.subprocess
@pytest.mark.parametrize("scenario", SCENARIOS, ids=lambda p: p.stem)
def test_run_each_example_coarse(scenario, tmp_path):
    out = tmp_path / "out"
    run = rodmol_cli("run", scenario, "--out", out, "--n-elements", 8, "--t-end", 0.3)
    assert run.returncode == 0, run.stderr
    result = rodmol.load_result(out)
    assert result.success and result.t[-1] == pytest.approx(0.3) and len(result.s) == 9
    assert assert_valid_views(out) == pytest.approx(list(result.t))
    assert str(out / "rod.xdmf") in run.stdout and "Jacobian evaluations" in run.stdout
    assert "x real time" in run.stdout and "tip" in run.stdout
    promised = set(re.findall(r"[\w.-]+\.(?:xdmf|h5|pvd|vtp|npz)\b", "\n".join(
        line.partition("#")[2] for line in scenario.read_text().splitlines())))
    assert all((out / name).is_file() for name in promised), (promised, sorted(p.name for p in out.iterdir()))


def test_examples_keep_the_views_frame_cap():
    """``every`` lifts the cap of 6000 frames shown; the examples leave it to the user."""
    for scenario in SCENARIOS:
        assert "every" not in tomllib.loads(scenario.read_text()).get("output", {}), scenario.name


@pytest.mark.subprocess
def test_builtin_example_quiet(tmp_path):
    out = tmp_path / "fetch"
    run = rodmol_cli("example", "fetching", "--out", out, "--n-elements", 6, "--t-end", 0.05, "--quiet")
    assert run.returncode == 0, run.stderr
    assert run.stdout == ""
    assert rodmol.load_result(out / "result.h5").meta["name"] == "fetching"


@pytest.mark.subprocess
def test_vtp_format_writes_the_series_and_result_npz(tmp_path):
    out = tmp_path / "vtp"
    streamed = rodmol_cli("run", EXAMPLES / "bending.toml", "--out", out, "--n-elements", 6, "--t-end", 0.05,
                          "--quiet")
    assert streamed.returncode == 0 and (out / "result.h5").is_file()
    run = rodmol_cli("run", EXAMPLES / "bending.toml", "--out", out, "--n-elements", 6, "--t-end", 0.05,
                     "--format", "vtp", "--overwrite")
    assert run.returncode == 0, run.stderr
    assert not (out / "result.h5").exists()  # the streamed run's files are not left to be read instead
    result = rodmol.load_result(out)
    assert assert_valid_series(out) == pytest.approx(list(result.t))
    assert str(out / "rod.pvd") in run.stdout and str(out / "result.npz") in run.stdout


@pytest.mark.subprocess
def test_malformed_scenario_exit_2_names_key_and_line_writes_nothing(tmp_path):
    text = (EXAMPLES / "bending.toml").read_text()
    text = text.replace("nu = 0.5", "nuu = 0.5").replace("rho = 1080.0", 'rho = "heavy"')
    bad = tmp_path / "bad.toml"
    bad.write_text(text)
    lines = text.splitlines()
    nuu = next(i for i, line in enumerate(lines, 1) if line.startswith("nuu"))
    rho = next(i for i, line in enumerate(lines, 1) if line.startswith("rho = \"heavy\""))
    out = tmp_path / "never"
    run = rodmol_cli("run", bad, "--out", out)
    assert run.returncode == 2
    assert f"bad.toml:{nuu}: [material] unknown key `nuu`; did you mean `nu`?" in run.stderr
    assert f"bad.toml:{rho}: [material] `rho` must be a number, got 'heavy'" in run.stderr
    assert not out.exists()


@pytest.mark.subprocess
def test_bad_command_line_value_exit_2(tmp_path):
    run = rodmol_cli("run", EXAMPLES / "bending.toml", "--n-elements", 1, "--out", tmp_path / "x")
    assert run.returncode == 2 and "command line --n-elements" in run.stderr
    assert not (tmp_path / "x").exists()
    assert rodmol_cli("render", tmp_path).returncode == 2


@pytest.mark.subprocess
def test_ctrl_c_keeps_a_valid_partial_run(tmp_path):
    out = tmp_path / "stopped"
    process = slow_run(out, frames_written=True)
    try:
        time.sleep(1.0)
        process.send_signal(signal.SIGINT)
        stdout, stderr = process.communicate(timeout=60)
    finally:
        if process.poll() is None:
            process.kill()
    assert process.returncode == 130, stderr
    assert_interrupted_run(out, stdout)


@pytest.mark.subprocess
@pytest.mark.skipif(os.environ.get("RODMOL_SKIP_RENDER") == "1", reason="RODMOL_SKIP_RENDER=1")
def test_render_and_plot(tmp_path):
    out = tmp_path / "r"
    assert rodmol_cli("run", EXAMPLES / "uniform_arm_air.toml", "--out", out, "--n-elements", 6,
                      "--t-end", 0.1, "--quiet").returncode == 0
    render = rodmol_cli("render", out, "--frames", 3, "--size", "320x240")
    assert render.returncode == 0, render.stderr
    assert "rendering: 100%" in render.stdout  # not silent while it draws
    plot = rodmol_cli("plot", out)
    assert plot.returncode == 0, plot.stderr
    for name in ("last_frame.png", "animation.gif", "tip_path.png", "markers.png", "tensions.png"):
        assert (out / name).stat().st_size > 1000, name
    from PIL import Image, ImageSequence

    frames = [np.asarray(f.convert("RGB")) for f in ImageSequence.Iterator(Image.open(out / "animation.gif"))]
    assert len(frames) >= 3 and all(np.any(a != b) for a, b in zip(frames, frames[1:]))  # each drawn anew


def test_ctrl_c_while_writing_stops_between_frames(tmp_path, monkeypatch):
    from rodmol.cli import commands as cli
    from rodmol.output import writers
    from rodmol.output.options import OutputOptions

    result = rodmol.simulate(rodmol.scenarios.get("bending").model(6), 0.05, output_dt=0.01)
    interrupts = DeferredSignals()
    # one Ctrl-C stopped the solver already
    interrupts.signal, interrupts.count, interrupts.forcing = signal.SIGINT, 1, False
    original = writers.SeriesWriter.write

    def write(self, result, k):
        original(self, result, k)
        if self.frames == 2:
            interrupts(signal.SIGINT, None)  # a second Ctrl-C while writing

    monkeypatch.setattr(writers.SeriesWriter, "write", write)
    written = cli._write_outputs(result, OutputOptions(format="vtp"), tmp_path, interrupts)
    assert written["frames"] == 2 and written["all_frames"] == len(result.t) == 6
    assert assert_valid_series(tmp_path) == pytest.approx(list(result.t[:2]))
    assert len(rodmol.load_result(tmp_path / "result.npz").t) == 6


def test_progress_plain_lines_when_not_a_terminal():
    import io

    from rodmol._progress import Progress

    stream = io.StringIO()
    progress = Progress(stream=stream)
    with progress.stage("preparing"):
        pass
    for t in (0.0, 0.01, 0.02, 0.05, 0.1, 0.15, 0.5, 1.0):
        progress(t, 1.0)
    progress.close()
    lines = stream.getvalue().splitlines()
    assert lines[0] == "rodmol: preparing ..." and lines[1].startswith("rodmol: preparing: ")
    bar = lines[2:]  # every tenth: 0, 10 % (0.1), 50 % (0.5: past 20-40 at once), 100 %
    assert [line.split("%")[0].split()[-1] for line in bar] == ["0", "10", "50", "100"]
    assert all("ETA" in line for line in bar) and "\r" not in stream.getvalue()


def test_progress_eta_counts_integration_only(monkeypatch):
    """A long stage before the first progress call does not enter the rate."""
    import io

    import rodmol._progress as display

    clock = [100.0]
    monkeypatch.setattr(display.time, "perf_counter", lambda: clock[0])
    stream = io.StringIO()
    progress = display.Progress(stream=stream)
    with progress.stage("compiling"):
        clock[0] += 50.0  # a long compilation
    progress(0.0, 10.0)
    clock[0] += 2.0
    progress(1.0, 10.0)  # 10 % in 2 s: 18 s to go
    assert stream.getvalue().splitlines()[-1].endswith("ETA 00:18")
