"""The calibration example and the throughput study run end to end."""

import importlib.util
import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
ROW = re.compile(r"^\| (\S+) \| [0-9.e+]+ \| [0-9.e+]+ \| [0-9.e+-]+ \| [0-9.]+ \| [0-9.e+]+ \| ([+-][0-9.]+) \|$", re.M)


def run(*args):
    return subprocess.run([sys.executable, *map(str, args)], capture_output=True, text=True, timeout=600,
                          check=False, cwd=ROOT)


def fitted_errors(stdout):
    """{parameter: error of the fit [%]} from the identification table."""
    return {name: float(error) for name, error in ROW.findall(stdout)}


def test_example_quick_identifies_e_and_cy(tmp_path, monkeypatch, capsys):
    """The example's ``main`` in this process, with the command line it reads (the full
    workflow, marked slow, runs it as a command)."""
    script = ROOT / "examples" / "identify_from_cameras.py"
    monkeypatch.setattr(sys, "argv", [script.name, "--quick", "--serial", "--figures", str(tmp_path)])
    spec = importlib.util.spec_from_file_location("identify_from_cameras", script)
    example = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(example)
    example.main()
    stdout = capsys.readouterr().out
    errors = fitted_errors(stdout)
    assert set(errors) == {"material.E", "medium.Cy,Cz"}, stdout
    assert all(abs(e) < 2.0 for e in errors.values()), stdout
    assert (tmp_path / "calibration_errors.png").stat().st_size > 10_000


@pytest.mark.slow
@pytest.mark.subprocess
def test_example_full_workflow(tmp_path):
    """The documented workflow (about 90 s): Table V and E, mu, Cy on the LocalCluster."""
    out = run(ROOT / "examples" / "identify_from_cameras.py", "--figures", tmp_path)
    assert out.returncode == 0, out.stderr[-3000:]
    errors = fitted_errors(out.stdout)
    assert abs(errors["material.E"]) < 1.0 and abs(errors["medium.Cy,Cz"]) < 1.0, out.stdout
    assert "| no drag |" in out.stdout and (tmp_path / "calibration_table5.png").is_file()


@pytest.mark.subprocess
def test_throughput_study_smoke(tmp_path):
    out = run(ROOT / "solvers" / "sweep_throughput.py", "--smoke", "--out", tmp_path)
    assert out.returncode == 0, out.stderr[-3000:]
    table = (tmp_path / "sweep_throughput.md").read_text()
    assert table.count("| True |") >= 1 and "False" not in table
    assert (tmp_path / "sweep_throughput_startup.csv").is_file()
