"""Scenario files: one TOML file describes one run (arm, loads, solver, outputs).

:func:`load_scenario` reads a file, checks all of it and returns a
:class:`RunSpec` (the model plus the solver and output settings). Every problem
in the file is reported at once, each with its line number and table, in one
:class:`ScenarioError`. The schema is documented in
``docs/scenario-reference.md``; relative paths are relative to the file.
"""

import difflib
import math
import os
import re
from dataclasses import dataclass, field
from functools import partial
from pathlib import Path

import numpy as np

try:
    import tomllib
except ModuleNotFoundError:  # Python 3.10
    import tomli as tomllib

from .. import scenarios
from ..arm import CABLE_OFFSETS, paper_arm
from ..solve.backends import BACKENDS, DEFAULT_RTOL
from ..base_motion import BaseMotion
from ..cables import Cable, as_tension, read_tension_csv
from ..errors import ParameterError
from ..markers import Marker
from ..model import Model
from ..parameters import MEDIA, Material, Medium
from ..rod import Rod
from .toml_lines import KeyLines


class ScenarioError(ParameterError):
    """A scenario file has problems; ``problems`` lists them all (:class:`Problem`)."""

    def __init__(self, source, problems):
        self.source, self.problems = source, list(problems)
        count = f"{len(self.problems)} problem" + ("s" if len(self.problems) != 1 else "")
        lines = [f"{source}: {count}:"] + [f"  {p}" for p in self.problems]
        super().__init__("\n".join(lines))


@dataclass(frozen=True)
class Problem:
    """One problem: where (file, line, table) and what."""

    source: str
    line: object  # int, None, or a command-line option name
    table: str
    message: str

    def __str__(self):
        where = (f"{self.source}:{self.line}" if isinstance(self.line, int)
                 else f"command line {self.line}" if self.line else self.source)
        return f"{where}: {self.table} {self.message}" if self.table else f"{where}: {self.message}"


@dataclass(frozen=True)
class OutputOptions:
    """What a run writes: ``directory`` (None: chosen by the caller), the VTK
    series (every ``every``-th output frame, and the last), and ``result.npz``."""

    directory: object = None
    vtk: bool = True
    npz: bool = True
    every: int = 1


@dataclass(frozen=True)
class RunSpec:
    """A checked scenario: the model, ``t_end`` [s], the options of
    :func:`rodmol.simulate` (``solver``) and the outputs."""

    name: str
    description: str
    source: str
    model: Model
    t_end: float
    solver: dict = field(default_factory=dict)
    output: OutputOptions = OutputOptions()

    def simulate(self, progress=None):
        """Run it: :func:`rodmol.simulate` with this scenario's settings."""
        from ..simulate import simulate

        return simulate(self.model, self.t_end, progress=progress, **self.solver)


# --------------------------------------------------------------------------- schema

TOP = ("name", "description", "arm", "scenario", "gravity", "rod", "material", "medium",
       "cable", "marker", "base", "discretization", "solver", "output")
ROD = ("length", "radius")
MATERIAL = ("E", "nu", "mu", "rho")
COEFFICIENTS = ("rho", "Cx", "Cy", "Cz", "By", "Bz")
SWITCHES = ("drag", "added_mass", "munk_moment")
MEDIUM = ("preset",) + COEFFICIENTS + SWITCHES
CABLE = ("name", "offset", "anchor", "tension")
PAPER_CABLE = ("number", "tension")
MARKER = ("name", "s", "offset")
BASE = ("fixed", "position", "rotation", "velocity", "angular_velocity")
DISCRETIZATION = ("n_elements",)
SOLVER = ("backend", "rtol", "atol", "t_end", "output_dt", "initial")
OUTPUT = ("directory", "vtk", "npz", "every")
ARMS = ("paper",)
INITIAL = ("equilibrium", "straight")
UNITS = {"length": "m", "radius": "m", "E": "Pa", "mu": "Pa s", "rho": "kg/m^3", "anchor": "m",
         "s": "m", "t_end": "s", "output_dt": "s", "offset": "m", "tension": "N"}


def load_scenario(path, overrides=None):
    """Read and check the scenario file at ``path``; return a :class:`RunSpec`.

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
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        match = re.search(r"line (\d+)", str(exc))
        line = int(match.group(1)) if match else None
        raise ScenarioError(source, [Problem(source, line, "", f"not valid TOML: {exc}")]) from None
    ctx = _Context(source, KeyLines(text), Path(base_dir))
    for dotted, value in (overrides or {}).items():
        ctx.override(dotted, value, data)
    ctx.data = data
    spec = _build(data, ctx, default_name)
    if ctx.problems:
        order = sorted(ctx.problems, key=lambda p: p.line if isinstance(p.line, int) else 10**9)
        raise ScenarioError(source, order)
    return spec


# --------------------------------------------------------------------------- checking

class _Bad(Exception):
    """A value problem found by a field reader (message without location)."""


def _table_label(path):
    if not path:
        return ""
    if len(path) >= 2 and isinstance(path[1], int):
        return f"[[{path[0]}]] #{path[1] + 1}"
    return "[" + ".".join(map(str, path)) + "]"


class _Context:
    """Collects problems, each with its line and table."""

    def __init__(self, source, lines, base_dir):
        self.source, self.lines, self.base_dir = source, lines, base_dir
        self.problems, self.overridden, self.data = [], {}, {}

    def override(self, dotted, value, data):
        label = getattr(value, "label", None)
        value = getattr(value, "value", value)
        *tables, key = dotted.split(".")
        target = data
        for name in tables:
            target = target.setdefault(name, {})
            if not isinstance(target, dict):
                return  # the file's own problem, reported when its table is read
        target[key] = value
        self.overridden[tuple(dotted.split("."))] = label or f"({dotted})"

    def add(self, path, message, table=None):
        """Record a problem at ``path`` (a key or a table); ``table`` defaults to the
        innermost table on the path."""
        path = tuple(path)
        if table is None:
            node, table = self.data, ()
            for i, part in enumerate(path):
                try:
                    node = node[part]
                except (KeyError, IndexError, TypeError):
                    break
                if isinstance(node, dict):
                    table = path[:i + 1]
        line = self.overridden.get(path) or self.lines.find(path)
        self.problems.append(Problem(self.source, line, _table_label(table), message))

    def table(self, data, path, allowed, required=(), hint=""):
        """Check a table's keys; return it (an empty dict if it is not a table)."""
        if not isinstance(data, dict):
            self.add(path, f"`{path[-1]}` must be a table, got {data!r}")
            return {}
        for key in data:
            if key not in allowed:
                close = difflib.get_close_matches(key, allowed, n=1, cutoff=0.6)
                tip = f"; did you mean `{close[0]}`?" if close else f"; valid keys: {', '.join(allowed)}"
                self.add(path + (key,), f"unknown key `{key}`{tip}{hint}", table=path)
        for key in required:
            if key not in data:
                unit = f" [{UNITS[key]}]" if key in UNITS else ""
                self.add(path, f"missing required key `{key}`{unit}")
        return data

    def read(self, table, path, key, reader, default=None):
        """``reader(value)`` of ``table[key]`` (``default`` if absent); on a problem, record it."""
        if key not in table:
            return default
        try:
            return reader(table[key])
        except _Bad as exc:
            self.add(path + (key,), f"`{key}` {exc}")
        except ParameterError as exc:
            self.add(path + (key,), str(exc))
        return _FAILED

    def construct(self, path, table, build):
        """Call a rodmol constructor; a ParameterError is recorded at the key it names."""
        try:
            return build()
        except ParameterError as exc:
            message = str(exc)
            named = [w for quoted in re.findall(r"`([^`]+)`", message)
                     for w in re.findall(r"[A-Za-z_]+", quoted) if w in table]
            self.add(path + ((named[0],) if named else ()), message)
            return _FAILED


_FAILED = object()  # a value that could not be read; its problem is already recorded


def _failed(*values):
    return any(v is _FAILED for v in values)


def _number(condition=None, unit=""):
    def read(value):
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
            raise _Bad(f"must be a number{f' [{unit}]' if unit else ''}, got {value!r}")
        if condition == "positive" and value <= 0:
            raise _Bad(f"must be > 0{f' {unit}' if unit else ''}, got {value!r}")
        if condition == "non-negative" and value < 0:
            raise _Bad(f"must be >= 0{f' {unit}' if unit else ''}, got {value!r}")
        return float(value)
    return read


def _integer(minimum, maximum=None):
    def read(value):
        if isinstance(value, bool) or not isinstance(value, int):
            raise _Bad(f"must be an integer, got {value!r}")
        if value < minimum:
            raise _Bad(f"must be >= {minimum}, got {value!r}")
        if maximum is not None and value > maximum:
            raise _Bad(f"must be <= {maximum}, got {value!r}")
        return value
    return read


def _boolean(value):
    if not isinstance(value, bool):
        raise _Bad(f"must be true or false, got {value!r}")
    return value


def _string(value):
    if not isinstance(value, str):
        raise _Bad(f"must be a string, got {value!r}")
    return value


def _choice(options):
    def read(value):
        if value not in options:
            close = difflib.get_close_matches(str(value), options, n=1, cutoff=0.6)
            tip = f"did you mean {close[0]!r}? " if close else ""
            raise _Bad(f"is {value!r}: {tip}valid values are {', '.join(map(repr, options))}")
        return value
    return read


def _vector(length, unit):
    def read(value):
        if (not isinstance(value, list) or len(value) != length
                or not all(isinstance(x, (int, float)) and not isinstance(x, bool)
                           and math.isfinite(x) for x in value)):
            raise _Bad(f"must be {length} numbers [{unit}], got {value!r}")
        return tuple(float(x) for x in value)
    return read


def _matrix3(value):
    rows = value if isinstance(value, list) and len(value) == 3 else None
    try:
        return tuple(_vector(3, "-")(row) for row in rows)
    except (_Bad, TypeError):
        raise _Bad(f"must be a 3x3 rotation matrix (three rows of three numbers), got {value!r}") from None


def _pairs(what, unit):
    def read(value):
        ok = isinstance(value, list) and len(value) >= 1 and all(
            isinstance(p, list) and len(p) == 2 and all(
                isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x) for x in p)
            for p in value)
        if not ok:
            raise _Bad(f"must be a list of {what} pairs [{unit}], got {value!r}")
        return [(float(a), float(b)) for a, b in value]
    return read


# --------------------------------------------------------------------------- sections

def _build(data, ctx, default_name):
    ctx.table(data, (), TOP)
    name = ctx.read(data, (), "name", _string, default_name)
    description = ctx.read(data, (), "description", _string, "")
    arm = ctx.read(data, (), "arm", _choice(ARMS))
    scenario = ctx.read(data, (), "scenario", _choice(tuple(scenarios.SCENARIOS)))
    if scenario not in (None, _FAILED) and arm is None:
        ctx.add(("scenario",), f"`scenario = {scenario!r}` drives the paper's cables: add `arm = \"paper\"`")
    gravity = ctx.read(data, (), "gravity", _vector(3, "m/s^2"), (0.0, -9.81, 0.0))
    n_elements = _discretization(data, ctx)
    medium, switches = _medium(data, ctx, default="water" if arm == "paper" else "air")
    base = _base(data, ctx)
    t_end_default = scenarios.get(scenario).t_end if scenario not in (None, _FAILED) else scenario
    solver, t_end = _solver(data, ctx, t_end_default)
    output = _output(data, ctx)

    if arm is _FAILED:
        return None  # which arm is meant is unknown: its tables cannot be checked
    if arm == "paper":
        for key in ("rod", "material", "marker"):
            if key in data:
                ctx.add((key,), f"`{key}` cannot be changed with `arm = \"paper\"` (the paper's arm "
                                "is fixed); write the arm out in full instead (see examples/bending.toml)")
        tensions = _paper_cables(data, ctx, scenario)
        parts = (gravity, n_elements, medium, base, tensions)
        build = lambda: paper_arm(n_elements, medium=medium, tensions=tensions, gravity=gravity,  # noqa: E731
                                  base=base, **switches)
    else:
        rod = _rod(data, ctx)
        cables = _cables(data, ctx)
        markers = _markers(data, ctx)
        parts = (gravity, n_elements, medium, base, rod, cables, markers)
        if not _failed(rod, cables, markers):
            _check_lengths(ctx, rod.length, cables, markers)
        build = lambda: Model(rod, n_elements, gravity=gravity, medium=medium, cables=cables,  # noqa: E731
                              base=base, markers=markers, **switches)
    if ctx.problems or _failed(*parts):
        return None
    try:
        model = build()
    except ParameterError as exc:
        _model_problem(ctx, data, str(exc))
        return None
    return RunSpec(name, description, ctx.source, model, t_end, solver, output)


def _check_lengths(ctx, length, cables, markers):
    """Anchors and markers beyond the tip, all of them (Model would stop at the first)."""
    for kind, items, key, value in (("cable", cables, "anchor", lambda c: c.anchor),
                                    ("marker", markers, "s", lambda m: m.s)):
        for i, item in enumerate(items):
            if value(item) > length * (1 + 1e-12):
                ctx.add((kind, i, key), f"`{key}` must lie within the rod, <= L = {length!r} m, "
                                        f"got {value(item)!r}")


def _model_problem(ctx, data, message):
    """Place a Model error (it names a cable or a marker) at that entry's table."""
    for kind in ("cable", "marker"):
        match = re.match(rf"{kind} '([^']*)'", message)
        entries = data.get(kind) if isinstance(data.get(kind), list) else []
        for i, entry in enumerate(entries):
            if match and isinstance(entry, dict) and _entry_name(kind, i, entry) == match.group(1):
                key = re.search(r"`(\w+)`", message)
                where = (kind, i) + ((key.group(1),) if key and key.group(1) in entry else ())
                return ctx.add(where, message)
    ctx.add(("rod",) if "rod" in data else (), message)


def _entry_name(kind, index, entry):
    name = entry.get("name")
    return name if isinstance(name, str) else f"{kind} {index + 1}"


def _missing(data, ctx, key):
    """True (and a problem recorded) if the required table ``key`` is absent."""
    if key in data:
        return False
    ctx.add((), f"missing table `[{key}]` (or use the paper's arm: `arm = \"paper\"`)")
    return True


_PLACEHOLDER = {"E": 1.0, "nu": 0.0, "mu": 0.0, "rho": 1.0}


def _material(data, ctx):
    if _missing(data, ctx, "material"):
        return _FAILED
    path = ("material",)
    table = ctx.table(data["material"], path, MATERIAL, required=MATERIAL)
    values = {k: ctx.read(table, path, k, _number()) for k in MATERIAL if k in table}
    if len(values) < len(MATERIAL) or _failed(*values.values()):
        # Check each given value alone (the others set to the paper's) to report them all.
        for key, value in values.items():
            if value is not _FAILED:
                ctx.construct(path, {key: value}, partial(Material, **{**_PLACEHOLDER, key: value}))
        return _FAILED
    return ctx.construct(path, table, lambda: Material(**values))


def _rod(data, ctx):
    material = _material(data, ctx)
    path = ("rod",)
    if _missing(data, ctx, "rod"):
        return _FAILED
    table = ctx.table(data["rod"], path, ROD, required=ROD)
    length = ctx.read(table, path, "length", _number("positive", "m"))
    radius = ctx.read(table, path, "radius", _radius(length))
    if _failed(material, length, radius) or length is None or radius is None:
        return _FAILED
    return ctx.construct(path, table, lambda: Rod(length, radius, material))


@dataclass(frozen=True)
class RadiusProfile:
    """A radius r(s) [m] interpolated linearly between ``(s, r)`` points [m]."""

    s: tuple
    r: tuple

    def __call__(self, s):
        return np.interp(s, self.s, self.r)


def _radius(length):
    def read(value):
        if isinstance(value, list) and value and all(isinstance(p, list) for p in value):
            points = _pairs("(s, r)", "m")(value)
            s, r = np.array(points).T
            if len(s) < 2:
                raise _Bad(f"needs at least two (s, r) points, got {value!r}")
            if np.any(np.diff(s) <= 0):
                raise _Bad(f"points must have increasing s, got s = {s.tolist()}")
            if np.any(r <= 0):
                raise _Bad(f"must be > 0 m, got r = {r.tolist()}")
            if isinstance(length, float) and not (s[0] == 0.0 and abs(s[-1] - length) <= 1e-9 * length):
                raise _Bad(f"points must span s = 0 to the length {length!r} m, got s from "
                           f"{s[0].item()!r} to {s[-1].item()!r} m")
            return RadiusProfile(tuple(s), tuple(r))
        if isinstance(value, list):
            return _vector(2, "m")(value) if len(value) == 2 else _bad_radius(value)
        if isinstance(value, (int, float)) and not isinstance(value, bool):
            return _number("positive", "m")(value)
        return _bad_radius(value)
    return read


def _bad_radius(value):
    raise _Bad("must be a number [m], a [base, tip] pair [m] or a list of [s, r] points [m], "
               f"got {value!r}")


def _medium(data, ctx, default):
    value = data.get("medium", default)
    path = ("medium",)
    if isinstance(value, str):
        return ctx.read({"medium": value}, (), "medium", lambda v: _choice(tuple(MEDIA))(v)), {}
    table = ctx.table(value, path, MEDIUM)
    preset = ctx.read(table, path, "preset", _choice(tuple(MEDIA)), "air")
    coefficients = {k: ctx.read(table, path, k, _number("non-negative")) for k in COEFFICIENTS if k in table}
    switches = {k: ctx.read(table, path, k, _boolean) for k in SWITCHES if k in table}
    if _failed(preset, *coefficients.values(), *switches.values()) or not isinstance(value, dict):
        return _FAILED, {}
    start = {k: getattr(MEDIA[preset], k) for k in COEFFICIENTS}
    medium = ctx.construct(path, table, lambda: Medium(**{**start, **coefficients}))
    return medium, switches


def _tension(ctx, name):
    def read(value):
        if isinstance(value, str):
            path = Path(value)
            return read_tension_csv(path if path.is_absolute() else ctx.base_dir / path)
        if isinstance(value, list):
            return as_tension(_pairs("(t, T)", "s, N")(value), f"{name!r} tension")
        if isinstance(value, (int, float)) and not isinstance(value, bool):
            return _number("non-negative", "N")(value)
        raise _Bad(f"must be a number [N], a list of [t, T] knots [s, N] or a CSV file name, got {value!r}")
    return read


def _cables(data, ctx):
    entries = data.get("cable", [])
    if not isinstance(entries, list):
        ctx.add(("cable",), f"`cable` must be an array of tables `[[cable]]`, got {entries!r}")
        return _FAILED
    cables, names = [], {}
    for i, entry in enumerate(entries):
        path = ("cable", i)
        table = ctx.table(entry, path, CABLE, required=("offset", "anchor"))
        name = ctx.read(table, path, "name", _string, f"cable {i + 1}")
        if name in names:
            ctx.add(path + ("name",), f"`name` {name!r} is already used by [[cable]] #{names[name] + 1}")
        names.setdefault(name, i)
        offset = ctx.read(table, path, "offset", _vector(2, "m"))
        anchor = ctx.read(table, path, "anchor", _number("positive", "m"))
        tension = ctx.read(table, path, "tension", _tension(ctx, name), 0.0)
        if _failed(name, offset, anchor, tension) or offset is None or anchor is None:
            cables.append(_FAILED)
            continue
        cables.append(ctx.construct(path, table, partial(Cable, offset, anchor, tension, name=name)))
    return _FAILED if _failed(*cables) else cables


def _paper_cables(data, ctx, scenario):
    """Tensions by cable number: the scenario's, replaced by the ``[[cable]]`` entries."""
    tensions = dict(scenarios.get(scenario).tensions) if scenario not in (None, _FAILED) else {}
    entries = data.get("cable", [])
    if not isinstance(entries, list):
        ctx.add(("cable",), f"`cable` must be an array of tables `[[cable]]`, got {entries!r}")
        return _FAILED
    hint = " (with `arm = \"paper\"`, a [[cable]] only sets the `tension` of cable `number` 1-12)"
    ok = True
    for i, entry in enumerate(entries):
        path = ("cable", i)
        table = ctx.table(entry, path, PAPER_CABLE, required=PAPER_CABLE, hint=hint)
        number = ctx.read(table, path, "number", _integer(1, maximum=len(CABLE_OFFSETS)))
        tension = ctx.read(table, path, "tension", _tension(ctx, f"cable {number}"))
        if _failed(number, tension) or number is None or tension is None:
            ok = False
        else:
            tensions[number] = tension
    return tensions if ok else _FAILED


def _markers(data, ctx):
    entries = data.get("marker", [])
    if not isinstance(entries, list):
        ctx.add(("marker",), f"`marker` must be an array of tables `[[marker]]`, got {entries!r}")
        return _FAILED
    markers = []
    for i, entry in enumerate(entries):
        path = ("marker", i)
        table = ctx.table(entry, path, MARKER, required=("s",))
        name = ctx.read(table, path, "name", _string, f"marker {i + 1}")
        s = ctx.read(table, path, "s", _number("non-negative", "m"))
        offset = ctx.read(table, path, "offset", _vector(2, "m"))
        if _failed(name, s, offset) or s is None:
            markers.append(_FAILED)
            continue
        markers.append(ctx.construct(path, table, partial(Marker, s, offset, name)))
    return _FAILED if _failed(*markers) else markers


def _constant(vector):
    return lambda t: vector


def _base(data, ctx):
    path = ("base",)
    table = ctx.table(data.get("base", {}), path, BASE)
    fixed = ctx.read(table, path, "fixed", _boolean, False)
    position = ctx.read(table, path, "position", _vector(3, "m"), (0.0, 0.0, 0.0))
    rotation = ctx.read(table, path, "rotation", _matrix3, tuple(map(tuple, np.eye(3))))
    velocity = ctx.read(table, path, "velocity", _vector(3, "m/s"))
    angular = ctx.read(table, path, "angular_velocity", _vector(3, "rad/s"))
    if fixed is True and (velocity is not None or angular is not None):
        ctx.add(path + ("fixed",), "`fixed = true` cannot be combined with `velocity` or "
                                   "`angular_velocity`")
        return _FAILED
    if _failed(fixed, position, rotation, velocity, angular):
        return _FAILED
    return ctx.construct(path, table, lambda: BaseMotion(
        None if velocity is None else _constant(np.array(velocity)),
        None if angular is None else _constant(np.array(angular)), position, rotation))


def _discretization(data, ctx):
    path = ("discretization",)
    table = ctx.table(data.get("discretization", {}), path, DISCRETIZATION)
    return ctx.read(table, path, "n_elements", _integer(2), 100)


def _solver(data, ctx, t_end_default):
    path = ("solver",)
    table = ctx.table(data.get("solver", {}), path, SOLVER)
    options = dict(
        backend=ctx.read(table, path, "backend", _choice(tuple(BACKENDS)), "cvode"),
        rtol=ctx.read(table, path, "rtol", _number("positive"), DEFAULT_RTOL),
        atol=ctx.read(table, path, "atol", _number("positive")),
        output_dt=ctx.read(table, path, "output_dt", _number("positive", "s"), 0.01),
        initial=ctx.read(table, path, "initial", _choice(INITIAL), "equilibrium"),
    )
    t_end = ctx.read(table, path, "t_end", _number("positive", "s"), t_end_default)
    if t_end is None:  # (_FAILED if the scenario that would give it is wrong)
        ctx.add(path, "missing required key `t_end` [s] (only `scenario = ...` gives a default)")
    return options, t_end


def _output(data, ctx):
    path = ("output",)
    table = ctx.table(data.get("output", {}), path, OUTPUT)
    directory = ctx.read(table, path, "directory", _string)
    values = dict(vtk=ctx.read(table, path, "vtk", _boolean, True),
                  npz=ctx.read(table, path, "npz", _boolean, True),
                  every=ctx.read(table, path, "every", _integer(1), 1))
    if _failed(directory, *values.values()):
        return None
    if directory is not None:
        directory = Path(os.path.normpath(ctx.base_dir / directory))
    return OutputOptions(directory, **values)


@dataclass(frozen=True)
class Override:
    """A value given on the command line, with the option's name for messages."""

    value: object
    label: str
