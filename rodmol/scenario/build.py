"""From the tables of a parsed scenario file to a :class:`RunSpec`: the top
level, ``[discretization]``, ``[solver]``, ``[output]``, and the Model built
from the arm's tables (:mod:`rodmol.scenario.arm`) and the loads
(:mod:`rodmol.scenario.loads`)."""

import os
import re
from pathlib import Path

from .. import scenarios
from ..arm import LENGTH as PAPER_LENGTH
from ..arm import paper_arm
from ..discretise.layout import StateLayout
from ..discretise.schemes import DEFAULT_SCHEME, SCHEMES
from ..errors import ParameterError
from ..model import MAX_ELEMENTS, Model
from ..output.formats import DEFAULT, FORMATS
from ..output.options import OutputOptions
from ..output.stream import CHUNK_FRAMES
from ..run_spec import RunSpec
from ..solve import options as run_options
from ..solve.backends import BACKENDS
from . import arm as arm_tables
from . import readers as read
from .loads import loads as load_tables
from .problems import FAILED, failed
from .schema import ARMS, DISCRETIZATION, INITIAL, OUTPUT, SOLVER, TOP


def build(data, ctx, default_name):
    """The RunSpec of the parsed file ``data``, or None if ``ctx`` recorded problems."""
    ctx.table(data, (), TOP)
    name = ctx.read(data, (), "name", read.string, default_name)
    description = ctx.read(data, (), "description", read.string, "")
    arm = ctx.read(data, (), "arm", read.choice(ARMS))
    scenario = ctx.read(data, (), "scenario", read.choice(tuple(scenarios.SCENARIOS)))
    if scenario not in (None, FAILED) and arm is None:
        ctx.add(("scenario",), f"`scenario = {scenario!r}` drives the paper's cables: add `arm = \"paper\"`")
    gravity = ctx.read(data, (), "gravity", read.vector(3, "m/s^2"), (0.0, -9.81, 0.0))
    n_elements, scheme = _discretization(data, ctx)
    medium, switches = arm_tables.medium(data, ctx, default="water" if arm == "paper" else "air")
    base = arm_tables.base(data, ctx)
    t_end_default = scenarios.get(scenario).t_end if scenario not in (None, FAILED) else scenario
    solver, t_end = _solver(data, ctx, t_end_default, n_elements)
    solver["scheme"] = scheme
    output = _output(data, ctx)
    loads = load_tables(data, ctx)

    if arm is FAILED:
        return None  # which arm is meant is unknown: its tables cannot be checked
    if arm == "paper":
        for key in ("rod", "material", "marker"):
            if key in data:
                ctx.add((key,), f"`{key}` cannot be changed with `arm = \"paper\"` (the paper's arm "
                                "is fixed); write the arm out in full instead (see examples/bending.toml)")
        tensions = arm_tables.paper_cables(data, ctx, scenario)
        parts = (gravity, n_elements, scheme, medium, base, tensions, loads)
        if not failed(loads):
            _check_lengths(ctx, PAPER_LENGTH, [], [], loads)
        build_model = lambda: paper_arm(n_elements, medium=medium, tensions=tensions,  # noqa: E731
                                        gravity=gravity, base=base, loads=loads, **switches)
    else:
        rod = arm_tables.rod(data, ctx)
        cables = arm_tables.cables(data, ctx)
        markers = arm_tables.markers(data, ctx)
        parts = (gravity, n_elements, scheme, medium, base, rod, cables, markers, loads)
        if not failed(rod, cables, markers, loads):
            _check_lengths(ctx, rod.length, cables, markers, loads)
        build_model = lambda: Model(rod, n_elements, gravity=gravity, medium=medium,  # noqa: E731
                                    cables=cables, base=base, markers=markers, loads=loads,
                                    **switches)
    if ctx.problems or failed(*parts):
        return None
    try:
        model = build_model()
    except ParameterError as exc:
        _model_problem(ctx, data, str(exc), loads)
        return None
    return RunSpec(name, description, ctx.source, model, t_end, solver, output)


def _check_lengths(ctx, length, cables, markers, loads):
    """Anchors, markers and point loads beyond the tip, all of them (Model
    would stop at the first)."""
    points = [(i, load) for i, load in enumerate(loads) if hasattr(load, "s")]
    for kind, items, key, value in (("cable", enumerate(cables), "anchor", lambda c: c.anchor),
                                    ("marker", enumerate(markers), "s", lambda m: m.s),
                                    ("load", points, "s", lambda p: p.s)):
        for i, item in items:
            if value(item) > length * (1 + 1e-12):
                ctx.add((kind, i, key), f"`{key}` must lie within the rod, <= L = {length!r} m, "
                                        f"got {value(item)!r}")


def _model_problem(ctx, data, message, loads=()):
    """Place a Model error (it names a cable, a marker or a load) at that entry's table."""
    for i, load in enumerate(loads):  # a load's message starts with its name (a hold off the grid)
        if message.startswith(f"{load.name}: "):
            key = re.search(r"`(\w+)`", message)
            where = ("load", i) + ((key.group(1),) if key and key.group(1) in data["load"][i] else ())
            return ctx.add(where, message)
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


def _discretization(data, ctx):
    path = ("discretization",)
    table = ctx.table(data.get("discretization", {}), path, DISCRETIZATION)
    return (ctx.read(table, path, "n_elements", read.integer(2, MAX_ELEMENTS), 100),
            ctx.read(table, path, "scheme", read.choice(tuple(SCHEMES)), DEFAULT_SCHEME))


def _solver(data, ctx, t_end_default, n_elements):
    """simulate's options and t_end, checked by the same rules as in Python
    (:mod:`rodmol.solve.options`)."""
    path = ("solver",)
    table = ctx.table(data.get("solver", {}), path, SOLVER)
    options = dict(
        backend=ctx.read(table, path, "backend", read.choice(tuple(BACKENDS)), "cvode"),
        rtol=ctx.read(table, path, "rtol", lambda v: run_options.rtol(read.number()(v))),
        atol=ctx.read(table, path, "atol", read.number("positive")),
        output_dt=ctx.read(table, path, "output_dt", read.number("positive", "s"), 0.01),
        initial=ctx.read(table, path, "initial", read.choice(INITIAL), "equilibrium"),
    )
    if "max_wall_time" in table:
        options["max_wall_time"] = ctx.read(table, path, "max_wall_time", read.number("positive", "s"))
    t_end = ctx.read(table, path, "t_end", read.number("positive", "s"), t_end_default)
    if t_end is None:  # (FAILED if the scenario that would give it is wrong)
        ctx.add(path, "missing required key `t_end` [s] (only `scenario = ...` gives a default)")
    elif not failed(t_end, options["output_dt"], n_elements):
        try:
            run_options.output_count(t_end, options["output_dt"], StateLayout(n_elements).size)
        except ParameterError as exc:
            # The message opens with t_end: its line, unless only output_dt was written here.
            ctx.add(path + (("output_dt",) if "output_dt" in table and "t_end" not in table else ("t_end",)),
                    str(exc))
    return options, t_end


def _output(data, ctx):
    path = ("output",)
    table = ctx.table(data.get("output", {}), path, OUTPUT)
    directory = ctx.read(table, path, "directory", read.path)
    values = dict(format=ctx.read(table, path, "format", read.choice(tuple(FORMATS)), DEFAULT),
                  vtk=ctx.read(table, path, "vtk", read.boolean, True),
                  npz=ctx.read(table, path, "npz", read.boolean, True),
                  every=ctx.read(table, path, "every", read.integer(1), None),
                  chunk_frames=ctx.read(table, path, "chunk_frames", read.integer(1), CHUNK_FRAMES))
    if failed(directory, *values.values()):
        return None
    if directory is not None:
        directory = Path(os.path.normpath(ctx.base_dir / directory))
    return OutputOptions(directory, **values)
