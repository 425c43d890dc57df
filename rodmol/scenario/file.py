"""Scenario files: one TOML file describes one run (arm, loads, solver, outputs).

:func:`load_scenario` reads a file, checks all of it and returns a
:class:`rodmol.run_spec.RunSpec` (the model plus the solver and output settings). Every problem
in the file is reported at once, each with its line number and table, in one
:class:`ScenarioError`. The schema is documented in
``docs/scenario-reference.md``; relative paths are relative to the file.

The work is shared by
:mod:`~rodmol.scenario.tables` (the tables, their keys derived from the
constructors' signatures, units, TOML conversions),
:mod:`~rodmol.scenario.problems` (collecting problems with their lines),
:mod:`~rodmol.scenario.arm` (rod, material, medium, cables, markers, base),
:mod:`~rodmol.scenario.loads` (``[[load]]``),
:mod:`~rodmol.scenario.build` (solver, output, the Model); what a checked
file gives is a :class:`rodmol.run_spec.RunSpec`, with the outputs'
:class:`rodmol.output.options.OutputOptions`.
"""

import re
from pathlib import Path

try:
    import tomllib
except ModuleNotFoundError:  # Python 3.10
    import tomli as tomllib

from .build import build
from .problems import Context, Override, Problem, ScenarioError
from .toml_lines import KeyLines, deepest_line

__all__ = ["Override", "Problem", "ScenarioError", "load_scenario", "parse_scenario"]


def load_scenario(path, overrides=None):
    """Read and check the scenario file at ``path``; return a :class:`rodmol.run_spec.RunSpec`.

    ``overrides`` maps dotted keys (``"solver.t_end"``) to values that replace
    the file's (the command line's options); their problems name the option
    given as the value of ``overrides.labels`` if present.
    """
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except OSError as exc:
        raise ScenarioError(str(path), [Problem(str(path), None, "", f"cannot read the file: "
                                                f"{exc.strerror}")]) from None
    except UnicodeDecodeError as exc:
        raise ScenarioError(str(path), [Problem(str(path), None, "", f"not UTF-8 text: {exc}")]) from None
    return parse_scenario(text, base_dir=path.parent, source=str(path), overrides=overrides,
                          default_name=path.stem)


def parse_scenario(text, base_dir=".", source="<string>", overrides=None, default_name="scenario"):
    """Check the TOML ``text`` of a scenario; see :func:`load_scenario`.

    ``base_dir`` is where relative paths (CSV tables, output directory) start.
    """
    if not isinstance(text, str):
        raise ScenarioError(source, [Problem(source, None, "", f"the scenario must be text, got "
                                             f"{type(text).__name__}")])
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        match = re.search(r"line (\d+)", str(exc))
        line = int(match.group(1)) if match else None
        raise ScenarioError(source, [Problem(source, line, "", f"not valid TOML: {exc}")]) from None
    except RecursionError:  # tomllib recurses once per level of nested arrays and tables
        raise ScenarioError(source, [Problem(source, deepest_line(text), "", "not a scenario: arrays or "
                                             "inline tables nested too deeply")]) from None
    ctx = Context(source, KeyLines(text), Path(base_dir))
    for dotted, value in (overrides or {}).items():
        ctx.override(dotted, value, data)
    ctx.data = data
    spec = build(data, ctx, default_name)
    if ctx.problems:
        order = sorted(ctx.problems, key=lambda p: p.line if isinstance(p.line, int) else 10**9)
        raise ScenarioError(source, order)
    return spec
