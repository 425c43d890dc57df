"""The solver studies under solvers/ run end to end (tiny --smoke sizes) and
write their CSV, Markdown and PNG outputs. Timings are not checked here.
core_speed.py also checks out the pre-refactor commit into a temporary git
worktree (skipped outside a git checkout that has it)."""

import os
import shutil
import subprocess
import sys

import pytest

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SCRIPTS = {
    "scaling.py": ["scaling.csv", "scaling.md", "scaling.png", "scaling_extra.csv", "scaling_long.csv"],
    "temporal.py": ["temporal.csv", "temporal.md", "temporal.png", "temporal_rk23.csv",
                    "temporal_options.csv"],
    "work_precision.py": ["work_precision.csv", "work_precision.md", "work_precision.png"],
    "convergence.py": ["convergence.csv", "convergence.md", "convergence.png"],
    "release.py": ["release.csv", "release.md"],
    "profile_rhs.py": ["profile_rhs.csv", "profile_rhs_calls.csv", "profile_rhs_ladder.csv", "profile_rhs.md",
                       "profile_rhs.png"],
    "core_speed.py": ["core_speed.csv", "core_speed.md"],
    "continuum.py": ["continuum.csv", "continuum.md", "continuum.png"],
    "schemes.py": ["schemes.csv", "schemes.md", "schemes.png"],
    "scheme_targets.py": ["scheme_targets.csv", "scheme_targets.md"],
    "fetching_hold.py": ["fetching_hold.csv", "fetching_hold.md", "fetching_hold.png"],
    "long_output.py": ["long_output.csv", "long_output.md"],
    "stiff_cantilever.py": ["stiff_cantilever.csv", "stiff_cantilever.md"],
    "view_open.py": ["view_open.csv", "view_open.md"],
    "quaternion_norm.py": ["quaternion_norm.csv", "quaternion_norm.md"],
}


@pytest.mark.subprocess
@pytest.mark.parametrize("script", sorted(SCRIPTS))
def test_script_smoke_run(script, tmp_path):
    if script == "core_speed.py" and subprocess.run(
            ["git", "-C", ROOT, "cat-file", "-e", "9fce6d7^{commit}"], capture_output=True).returncode != 0:
        pytest.skip("needs a git checkout holding commit 9fce6d7")
    if script == "view_open.py" and shutil.which("pvpython") is None:
        pytest.skip("needs ParaView's pvpython")
    proc = subprocess.run([sys.executable, os.path.join(ROOT, "solvers", script), "--smoke",
                           "--out", str(tmp_path)], capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stdout[-2000:] + proc.stderr[-4000:]
    for name in SCRIPTS[script]:
        path = tmp_path / name
        assert path.is_file() and path.stat().st_size > 0, name
    markdown = next(name for name in SCRIPTS[script] if name.endswith(".md"))
    with open(tmp_path / markdown) as f:
        text = f.read()
    assert "machine:" in text and "numba" in text  # the header names the machine and versions
