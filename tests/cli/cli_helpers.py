"""Helpers of the command-line tests: running ``rodmol`` in a subprocess and checking what it wrote."""

import subprocess
import sys
from pathlib import Path

import pytest
from views import assert_valid_views

import rodmol
from rodmol.output.writers import read_pvd

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
#: The shipped single-rod scenario files, and the system files (with [[rod]]).
SCENARIOS = sorted(p for p in EXAMPLES.glob("*.toml") if "[[rod]]" not in p.read_text(encoding="utf-8"))
SYSTEM_SCENARIOS = sorted(p for p in EXAMPLES.glob("*.toml") if "[[rod]]" in p.read_text(encoding="utf-8"))


def rodmol_cli(*args, timeout=120):
    return subprocess.run([sys.executable, "-m", "rodmol", *map(str, args)], capture_output=True,
                          text=True, timeout=timeout)


def assert_valid_series(directory):
    """Every .pvd lists only files that exist and load; returns the rod's times."""
    pv = pytest.importorskip("pyvista")
    times = None
    for pvd in directory.glob("*.pvd"):
        entries = read_pvd(pvd)
        for _, path in entries:
            assert path.is_file(), path
            assert pv.read(path).n_points > 0, path
        if pvd.name == "rod.pvd":
            times = [t for t, _ in entries]
    assert times is not None, "no rod.pvd"
    return times


def assert_interrupted_run(out, stdout):
    """An interrupted run of the fetching example: said so, and its directory valid up to where it got."""
    assert "STOPPED" in stdout and "interrupted" in stdout
    result = rodmol.load_result(out)
    assert not result.success and "interrupted" in result.message
    assert 2 <= len(result.t) < 801
    assert assert_valid_views(out) == pytest.approx(list(result.t))


def slow_run(out, frames_written=False):
    """``rodmol run`` of the fetching example on the explicit backend and a fine
    grid (minutes: a signal lands in the solver), started and its first
    progress line read (with ``frames_written``: the first past 0%)."""
    command = [sys.executable, "-u", "-m", "rodmol", "run", "--example", "fetching",
               "--backend", "rk23", "--n-elements", "60", "--out", str(out)]
    process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    line = ""
    while "integrating:" not in line or (frames_written and "  0%" in line):
        line = process.stdout.readline()
        if not line and process.poll() is not None:
            raise AssertionError(process.stderr.read())
    return process
