"""Every shell and Python block of the README and of docs/ runs as written.

Each page runs in a fresh directory holding a link to ``examples/``, block
after block in the page's order, so a block may use what an earlier one
wrote. Python blocks share one namespace per page (as in one session);
shell blocks run line by line through bash with this environment's scripts
first on the PATH. Three kinds of command are left out, because the suite
itself stands for them: creating the virtual environment and installing
rodmol (``python3 -m venv``, ``pip install``; ``.ci/run`` runs them as
written on a fresh machine), the ``.venv/bin/`` prefix (this environment is
that one), and running the test suite. A plain ``rodmol ...`` command (no
shell syntax) runs through ``rodmol.cli.main`` in this process, the same
code without a fresh interpreter's start (a second or two each), except a
page's first, which runs through the console script as written. A block
after an HTML comment
``<!-- file: NAME -->`` is a file the page asks the reader to save (e.g. a
ParaView script): it is written under that name, not run. ``pvpython`` gets a
virtual display when there is none (``xvfb-run``), and a page that needs it is
skipped where ParaView is not installed.
"""

import builtins
import importlib
import os
import re
import shlex
import shutil
import sys
from pathlib import Path

import pytest
import xserver

ROOT = Path(__file__).resolve().parents[1]
PAGES = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
FENCE = re.compile(r"(?:<!-- file: (?P<file>[\w.-]+) -->\s*\n)?^```(?P<lang>python|bash)\n(?P<code>.*?)^```$",
                   re.M | re.S)
SET_UP = re.compile(r"python3? -m venv|pip install|-m pytest")
SHELL_SYNTAX = re.compile(r"[|&;<>()$`*?~{}'\"\\]")
XVFB = ["xvfb-run", *xserver.XVFB_ARGS]


def blocks(page):
    """(kind, code, line) of each block: kind is "python", "bash" or "file:NAME"."""
    text = page.read_text()
    for match in FENCE.finditer(text):
        kind = f"file:{match['file']}" if match["file"] else match["lang"]
        yield kind, match["code"], text.count("\n", 0, match.start("code")) + 1


def commands(code):
    """The shell block's commands, continuation lines joined, set-up left out."""
    for line in code.replace("\\\n", " ").splitlines():
        line = line.split(" #")[0].strip()
        if not line or line.startswith("#"):
            continue
        kept = [part.strip().removeprefix(".venv/bin/") for part in line.split("&&")
                if not SET_UP.search(part)]
        if kept:
            yield " && ".join(kept)


def rodmol_arguments(command):
    """The arguments of a plain ``rodmol ...`` command (no shell syntax), else None."""
    if not command.startswith("rodmol ") or SHELL_SYNTAX.search(command):
        return None
    return shlex.split(command)[1:]


def run_in_process(arguments):
    """``rodmol.cli.main(arguments)``'s exit code (0 for None, as the console script)."""
    from rodmol.cli.commands import main

    try:
        return main(arguments) or 0
    except SystemExit as exc:  # argparse's --help and errors
        return exc.code or 0


@pytest.mark.subprocess
@pytest.mark.parametrize("page", [p for p in PAGES if any(blocks(p))], ids=lambda p: p.name)
def test_page_runs_as_written(page, tmp_path, monkeypatch):
    needs_paraview = any("pvpython" in code for kind, code, _ in blocks(page) if kind == "bash")
    if needs_paraview and not shutil.which("pvpython"):
        pytest.skip("ParaView (pvpython) is not installed")
    (tmp_path / "examples").symlink_to(ROOT / "examples")
    monkeypatch.chdir(tmp_path)
    env = dict(os.environ, PATH=f"{Path(sys.executable).parent}{os.pathsep}{os.environ['PATH']}",
               MPLBACKEND="Agg")
    namespace = {"__name__": "__main__"}
    console_script_ran = False
    for kind, code, line in blocks(page):
        where = f"{page.relative_to(ROOT)}:{line}"
        if kind.startswith("file:"):
            (tmp_path / kind[5:]).write_text(code)
        elif kind == "python":
            exec(compile(code, where, "exec"), namespace)  # noqa: S102 (the page's own code)
        else:
            for command in commands(code):
                arguments = rodmol_arguments(command)
                if arguments is not None and console_script_ran:
                    exit_code = run_in_process(arguments)
                    assert exit_code == 0, f"{where}: `{command}` exited with {exit_code}"
                    continue
                console_script_ran = console_script_ran or arguments is not None
                argv = ["bash", "-c", command]
                if command.startswith("pvpython") and not os.environ.get("DISPLAY"):
                    argv = XVFB + argv
                if command.startswith("xvfb-run") and not shutil.which("xvfb-run"):
                    pytest.skip("xvfb-run is not installed")
                done = xserver.run(argv, env=env, timeout=600)
                assert done.returncode == 0, f"{where}: `{command}` failed:\n{done.stdout}\n{done.stderr}"


def _resolves(dotted):
    """True if ``a.b.c`` is a module or an attribute reached from one."""
    parts = dotted.split(".")
    found = importlib.import_module(parts[0])
    for i, part in enumerate(parts[1:], start=2):
        if hasattr(found, part):
            found = getattr(found, part)
            continue
        try:
            found = importlib.import_module(".".join(parts[:i]))
        except ImportError:
            return False
    return True


def test_every_dotted_rodmol_name_in_the_docs_exists():
    missing = [(page.name, name) for page in PAGES
               for name in sorted(set(re.findall(r"(?<![\w./])rodmol(?:\.[A-Za-z_]\w*)+", page.read_text())))
               if not _resolves(name)]
    assert not missing


def test_every_name_api_md_gives_unqualified_is_importable_from_rodmol():
    """docs/api.md: "Everything below is importable from `rodmol`": its class names, and the
    functions that open a list item or a table row, unless the page names their module."""
    import rodmol

    text = (ROOT / "docs" / "api.md").read_text()
    assert "Everything below is importable from `rodmol`" in text
    names = {m for m in re.findall(r"`([A-Z]\w*)", text) if any(c.islower() for c in m)}
    names |= set(re.findall(r"^(?:- |\| )`([a-z_]\w*)\(", text, re.M))
    qualified = {m[1]: m[0] for m in re.findall(r"`(rodmol(?:\.\w+)*)\.([A-Za-z_]\w*)", text)}
    missing = [name for name in sorted(names) if not (
        hasattr(rodmol, name) or hasattr(builtins, name)
        or (name in qualified and hasattr(importlib.import_module(qualified[name]), name)))]
    assert not missing, f"docs/api.md names these as importable from rodmol: {missing}"
