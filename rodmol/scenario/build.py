"""From the tables of a parsed scenario file to a :class:`RunSpec`: the top
level, ``[discretization]``, ``[solver]``, ``[output]``, and the Model built
from the arm's tables (:mod:`rodmol.scenario.arm`) and the loads
(:mod:`rodmol.scenario.loads`). Values are checked by the constructors and by
:func:`rodmol.simulate`'s own checks (:func:`rodmol.run_arguments.check_run`)."""

import re

from .. import _checks, scenarios
from ..arm import LENGTH as PAPER_LENGTH
from ..arm import paper_arm
from ..discretise.schemes import DEFAULT_SCHEME, get_scheme
from ..discretise.system import SemiDiscrete
from ..errors import ParameterError
from ..model import Model
from ..output.options import OutputOptions
from ..run_arguments import INITIAL, check_run, fit
from ..run_spec import RunSpec
from ..simulate import DEFAULT_BACKEND, OUTPUT_DT
from ..solve import options as run_options
from . import arm as arm_tables
from . import system as system_file
from . import tables
from .loads import loads as load_tables
from .problems import FAILED, failed

#: The Model's keys a file sets (in the top level, [discretization] and [medium]).
MODEL_KEYS = ("n_elements", "gravity") + tables.MODEL_SWITCHES


def build(data, ctx, default_name):
    """The RunSpec of the parsed file ``data``, or None if ``ctx`` recorded problems."""
    ctx.table(data, (), tables.TOP)
    name = ctx.read(data, (), "name", lambda v: _string("name", v), default_name)
    description = ctx.read(data, (), "description", lambda v: _string("description", v), "")
    if system_file.is_system(data):
        return _build_system(data, ctx, name, description)
    arm = ctx.read(data, (), "arm", lambda v: _checks.choice("arm", v, tables.ARMS))
    scenario = ctx.read(data, (), "scenario", lambda v: _checks.choice("scenario", v, tuple(scenarios.SCENARIOS)))
    if scenario not in (None, FAILED) and arm is None:
        ctx.add(("scenario",), f"`scenario = {scenario!r}` drives the paper's cables: add `arm = \"paper\"`")
    n_elements, scheme = _discretization(data, ctx)
    medium, switches = arm_tables.medium(data, ctx, default="water" if arm == "paper" else "air")
    base = arm_tables.base(data, ctx)
    t_end_default = scenarios.get(scenario).t_end if scenario not in (None, FAILED) else scenario
    solver, t_end = _solver(data, ctx, t_end_default)
    solver["scheme"] = scheme
    checked = _check_solver(ctx, solver, t_end, n_elements)
    output = _output(data, ctx)
    loads = load_tables(data, ctx)
    gravity = arm_tables.values(tables.TOP, ctx, (), data, keys=("gravity",))

    if arm is FAILED:
        return None  # which arm is meant is unknown: its tables cannot be checked
    if arm == "paper":
        for key in ("rod", "material", "marker"):
            if key in data:
                ctx.add((key,), f"`{key}` cannot be changed with `arm = \"paper\"` (the paper's arm "
                                "is fixed); write the arm out in full instead (see examples/bending.toml)")
        tensions = arm_tables.paper_cables(data, ctx, scenario)
        parts = (medium, base, tensions, loads)
        if not failed(loads):
            arm_tables.check_lengths(ctx, PAPER_LENGTH, [], [], loads)
        build_model = lambda **kw: paper_arm(medium=medium, tensions=tensions,  # noqa: E731
                                             base=base, loads=loads, **kw)
    else:
        rod = arm_tables.rod(data, ctx)
        cables = arm_tables.cables(data, ctx)
        markers = arm_tables.markers(data, ctx)
        parts = (medium, base, rod, cables, markers, loads)
        if not failed(rod, cables, markers, loads):
            arm_tables.check_lengths(ctx, rod.length, cables, markers, loads)
        build_model = lambda n_elements, **kw: Model(rod, n_elements, medium=medium,  # noqa: E731
                                                     cables=cables, base=base, markers=markers,
                                                     loads=loads, **kw)
    if failed(gravity, switches):
        return None
    if ctx.problems or failed(*parts):
        build_model = paper_arm  # a stand-in arm: the Model's own keys are still checked
    given = {"n_elements": n_elements, **gravity, **switches}
    model = ctx.construct((), build_model, given, keys=MODEL_KEYS,
                          where=lambda key, message: _model_problem(data, key, message))
    if ctx.problems or failed(model, checked):
        return None
    return RunSpec(name, description, ctx.source, model, t_end, solver, output)


def _build_system(data, ctx, name, description):
    """The RunSpec of a system file (:mod:`rodmol.scenario.system`): its [solver]
    starts from rest by default (``initial = "straight"``)."""
    n_elements, scheme = _discretization(data, ctx)
    solver, t_end = _solver(data, ctx, None, initial="straight")
    solver["scheme"] = scheme
    checked = _check_solver(ctx, solver, t_end, n_elements)
    output = _output(data, ctx)
    system = system_file.system(data, ctx, n_elements)
    if ctx.problems or failed(system, checked):
        return None
    return RunSpec(name, description, ctx.source, system, t_end, solver, output)


def _string(key, value):
    if not isinstance(value, str):
        raise ParameterError(f"`{key}` must be a string, got {_checks.short(value)}")
    return value


def _model_problem(data, key, message):
    """Where a Model error belongs: the table of the key it names, or the
    [[cable]], [[marker]] or [[load]] entry whose name it quotes or starts with
    (a load's messages begin "name: "; the last one: a name used twice is the
    second's fault), or [rod]."""
    if key is not None:
        return tables.table_of(key) + (key,)
    found = None
    for kind in tables.ARRAYS:
        entries = data.get(kind) if isinstance(data.get(kind), list) else []
        for i, entry in enumerate(entries):
            name = _entry_name(kind, i, entry) if isinstance(entry, dict) else None
            if name is not None and (repr(name) in message or message.startswith(f"{name}: ")):
                named = re.search(r"`(\w+)`", message)
                found = (kind, i) + ((named.group(1),) if named and named.group(1) in entry else ())
    return found or (("rod",) if "rod" in data else ())


def _entry_name(kind, index, entry):
    """The name the built object carries: the table's, else its class's default."""
    name = entry.get("name")
    if isinstance(name, str):
        return name
    table = tables.LOADS.get(entry.get("type")) if kind == "load" else None
    default = table.default("name") if table is not None and "name" in table.parameters() else None
    return default if isinstance(default, str) else f"{kind} {index + 1}"


def _discretization(data, ctx):
    path = ("discretization",)
    table = ctx.table(data.get("discretization", {}), path, tables.DISCRETIZATION)
    scheme = ctx.read(table, path, "scheme", lambda v: get_scheme(v).name, DEFAULT_SCHEME)
    return table.get("n_elements", tables.DISCRETIZATION.default("n_elements")), scheme


def _solver(data, ctx, t_end_default, initial=INITIAL[0]):
    """The [solver] values as simulate takes them (checked with the model, by
    :func:`_check_solver`), and t_end; ``initial``: the default start."""
    path = ("solver",)
    table = ctx.table(data.get("solver", {}), path, tables.SOLVER, required=())  # t_end: below
    defaults = dict(backend=DEFAULT_BACKEND, rtol=None, atol=None, output_dt=OUTPUT_DT, initial=initial)
    options = {key: tables.convert(key, table.get(key, default), ctx.base_dir) for key, default in defaults.items()}
    if "max_wall_time" in table:
        options["max_wall_time"] = table["max_wall_time"]
    t_end = table.get("t_end", t_end_default)
    if t_end is None:  # (FAILED if the scenario that would give it is wrong)
        ctx.add(path, "missing required key `t_end` [s] (only `scenario = ...` gives a default)")
    return options, t_end


def _check_solver(ctx, solver, t_end, n_elements):
    """simulate's own checks of the [solver] values, each problem at its key;
    FAILED if one fails. They need a Model of the file's size (it sizes the
    state): the paper's arm with as many elements stands in (a bad
    ``n_elements`` is the file's Model's to report)."""
    path = ("solver",)
    table = ctx.data.get("solver", {}) if isinstance(ctx.data.get("solver"), dict) else {}
    options = {k: v for k, v in solver.items() if k not in ("output_dt", "scheme")}
    scheme = DEFAULT_SCHEME if failed(solver["scheme"]) else solver["scheme"]  # (recorded)
    try:
        stand_in, sized = paper_arm(n_elements), True
    except ParameterError:
        stand_in, sized = paper_arm(2), False
    system = SemiDiscrete(stand_in, get_scheme(scheme))  # (sizes the state; compiles nothing)
    run = ctx.construct(path, lambda **kw: fit(check_run(t0=None, scheme=scheme, progress=None,
                                                         backend_options={}, **{"max_wall_time": None, **kw}),
                                               system),
                        options, given=table, keys=tuple(options))
    if t_end is None or t_end is FAILED:
        return FAILED  # (recorded)
    t_end = ctx.read({"t_end": t_end}, path, "t_end", lambda v: _checks.positive("t_end", v, " s"))
    output_dt = ctx.read(solver, path, "output_dt", lambda v: _checks.positive("output_dt", v, " s"))
    if failed(run, t_end, output_dt) or not sized:
        return FAILED if failed(run, t_end, output_dt) else run
    try:
        run_options.output_count(t_end, output_dt, system.size)
    except ParameterError as exc:
        # The message opens with t_end: its line, unless only output_dt was written here.
        ctx.add(path + (("output_dt",) if "output_dt" in table and "t_end" not in table else ("t_end",)),
                str(exc))
        return FAILED
    return run


def _output(data, ctx):
    return arm_tables.build_table(data.get("output", {}), ctx, ("output",), tables.OUTPUT, OutputOptions)
