"""A run of a :class:`rodmol.System` (rods and rigid bodies), reached through
:func:`rodmol.simulate`: from rest, its static equilibrium or a given state, with CVODE or the single rod's
``"galpha"`` and ``"rk23"`` backends (through
:class:`rodmol.solve.system_stepping.SteppedSystem`); with ``out=DIR`` its
frames are streamed in chunks while it goes, through the single rod's
chunked run (:func:`rodmol.solve.chunked.run_chunked`) into the sink
:func:`rodmol.run_sinks.system_writer` makes
(:class:`rodmol.output.system_stream.SystemRunWriter`), and ``resume=True``
continues a killed run from its last restart point.

A resumed run takes the settings it recorded (:mod:`rodmol._settings`,
:func:`~rodmol._settings.record_system`: the fingerprints of the system's
parts, the scheme, tolerances and backend options) wherever the call gives
none, and refuses other values, or a changed system, naming each, unless
``resume="force"``. ``progress`` is reported at the output times only.
"""

import warnings

import numpy as np

from . import _checks, _settings, run_sinks
from .discretise.assembly import Assembly
from .discretise.schemes import DEFAULT_SCHEME, get_scheme
from .errors import ParameterError
from .solve import options
from .solve.backends import get_backend
from .solve.chunked import run_chunked
from .solve.equilibrium import equilibrium
from .solve.galpha import generalized_alpha
from .solve.outputs import RawSolution
from .solve.system_cvode import cvode_system
from .solve.system_stepping import SteppedSystem, auto_dt
from .system_result import SystemResult

OUTPUT_DT = 0.01


def simulate_system(system, t_end, *, initial=None, scheme=None, backend=None, rtol=None, atol=None,
                    output_dt=None, output_times=None, t0=None, progress=None, max_wall_time=None,
                    out=None, resume=False, overwrite=False, **backend_options):
    """Integrate ``system`` from rest (``initial="straight"``: every rod
    straight at its base, every body at rest at its pose), from its static
    equilibrium (``"equilibrium"``, free bodies included:
    :func:`rodmol.solve.equilibrium.system_rest_state`), from a state
    vector (``SystemResult.states[k]``) or from the last frame of an earlier
    SystemResult (at its last time unless ``t0`` is given); the other
    arguments as for :func:`rodmol.simulate`. With ``out``, the frames are
    streamed chunk by chunk (:mod:`rodmol.output.system_stream`) and
    ``resume=True`` continues a killed or interrupted run there from its last
    restart point, with its recorded settings where the call gives none;
    other settings or a changed system (any rod's model, body, joint, the
    medium or gravity) are refused naming each, unless ``resume="force"``
    (not another grid or other output times). Returns a
    :class:`rodmol.system_result.SystemResult`."""
    if not (resume is True or resume is False or (isinstance(resume, str) and resume == "force")):
        raise ParameterError(f"`resume` must be False, True or 'force', got {_checks.short(resume)}")
    if out is None and (overwrite is not False or resume):
        raise ParameterError("`overwrite` and `resume=True` need `out`, the run's directory")
    if resume and overwrite:
        raise ParameterError("give either `resume` or `overwrite=True`, not both")
    sink, first, recorded = None, 0, {}
    if resume:  # the run's directory first: its settings fill in what the call leaves out
        sink = _sink(out, True, False)
        recorded = sink.settings or {}
        _check_plan(sink.t_out, recorded, initial, t0, t_end, output_dt, output_times)
        scheme, backend, rtol, atol, backend_options = _settings.resumed(recorded, scheme, backend, rtol, atol,
                                                                         backend_options)
        first, initial = sink.restart[0], sink.restart[1]
        t0 = float(sink.t_out[first])
    asked_atol = atol  # None: the default, rtol times the parts' scales (recorded as None)
    backend = "cvode" if backend is None else backend
    run = cvode_system if backend == "cvode" else get_backend(backend)
    checked = options.backend_options(backend, run, backend_options)
    progress, max_wall_time = options.progress(progress), options.max_wall_time(max_wall_time)
    if isinstance(initial, SystemResult):
        t0 = float(initial.t[-1]) if t0 is None else t0
        initial = initial.states[-1]
    scheme = get_scheme(DEFAULT_SCHEME if scheme is None else scheme)
    rtol = options.rtol(scheme.default_rtol if rtol is None else rtol)
    t0 = 0.0 if t0 is None else _checks.non_negative("t0", t0, " s")
    t_end = _checks.positive("t_end", t_end, " s")
    if t_end <= t0:
        raise ParameterError(f"`t_end` must be after the start t0 = {t0!r} s, got {t_end!r} s")
    output_dt = _checks.positive("output_dt", OUTPUT_DT if output_dt is None else output_dt, " s")
    assembly = Assembly(system, scheme)
    if run is generalized_alpha and checked.get("dt", "auto") == "auto":
        checked["dt"] = auto_dt(assembly)
    if resume:
        getattr(sink, "check", lambda assembly: None)(assembly)
    t_out = options.output_times(t0, t_end, output_dt, output_times, assembly.size) if sink is None \
        else sink.t_out
    if initial is None or (isinstance(initial, str) and initial == "straight"):
        y0 = assembly.initial_state()
    elif isinstance(initial, str) and initial == "equilibrium":
        y0 = equilibrium(assembly, t0)
    elif isinstance(initial, str):
        raise ParameterError(f"unknown `initial` {_checks.short(initial)}; use 'straight', 'equilibrium' "
                             "or a state")
    else:
        y0 = _sized("initial", initial, assembly.size, scalar=False)
    atol = rtol * assembly.atol_scale() if atol is None else _sized("atol", atol, assembly.size)
    if np.any(atol <= 0):
        raise ParameterError("`atol` must be > 0")
    settings = _settings.record_system(assembly, backend=backend, rtol=rtol,
                                       atol=None if asked_atol is None else atol,
                                       backend_options=backend_options,
                                       initial=recorded.get("initial") if resume else
                                       "straight" if initial is None else initial)
    forced = _settings.check(recorded, settings, resume == "force", repr(str(getattr(sink, "directory", sink)))) \
        if recorded else []
    if out is not None and sink is None:  # after every check: with `overwrite`, this clears the earlier run
        sink = _sink(out, False, bool(overwrite))
    if sink is not None:
        getattr(sink, "record_settings", lambda settings, forced: None)(settings, forced)
    owned = progress is True
    if owned:
        from ._progress import Progress

        progress = Progress()
    solver = dict(rtol=rtol, atol=atol, progress=progress, max_wall_time=max_wall_time, **checked)
    try:
        if sink is None:
            raw = _run(_Chunked(assembly, run), y0, t_out, **solver)
            success, message = raw.success, raw.message
            result = SystemResult(assembly, raw.t, raw.y, success, message, raw.stats, raw.error)
        else:  # in chunks into the sink, whose SystemResult it is
            success, message, stats, error = run_chunked(_run, _Chunked(assembly, run), y0, t_out, sink, first,
                                                         **solver)
            result = sink.end(success, message, stats)
            result.error = error
    finally:
        if owned:
            progress.close()
    if not success:
        warnings.warn(message, RuntimeWarning, stacklevel=3)
    return result


def _check_plan(plan, recorded, initial, t0, t_end, output_dt, output_times):
    """Refuse a resumed call asking for another start or other output times than the run's
    ``plan`` (the same as it recorded, as a scenario file gives them again, is fine)."""
    if initial is not None and not (isinstance(initial, str) and initial == recorded.get("initial", initial)):
        raise ParameterError(f"a resumed run starts from its last restart point: `initial` "
                             f"{_checks.short(initial)} is not the run's ({recorded.get('initial')!r})")
    if t0 is not None and t0 != plan[0]:
        raise ParameterError(f"`t0` = {t0!r} s: the run being resumed started at {float(plan[0])!r} s")
    if t_end != plan[-1]:
        raise ParameterError(f"`t_end` = {t_end!r} s: the run being resumed ends at {float(plan[-1])!r} s")
    if output_dt is not None or output_times is not None:
        asked = options.output_times(float(plan[0]), t_end, OUTPUT_DT if output_dt is None else output_dt,
                                     output_times, 1)
        if len(asked) != len(plan) or not np.allclose(asked, plan, rtol=0, atol=1e-12 * max(1.0, t_end)):
            raise ParameterError(f"cannot resume: the run's output times are {len(plan)} from "
                                 f"{float(plan[0]):g} to {float(plan[-1]):g} s, this call asks for {len(asked)}")


class _Chunked:
    """The assembly and its backend ``run`` as :func:`rodmol.solve.chunked.run_chunked`
    sees them. Its frames are not checked again against the rods' inputs
    (``inputs_vary``): a rod's inputs are evaluated when its Result is built, and a
    failing one stops the run there."""

    inputs_vary = False

    def __init__(self, assembly, run):
        self.assembly, self.run = assembly, run


def _run(chunked, y0, t_out, **solver):
    """The backend on the assembly (a RawSolution): CVODE's own system run, or a single
    rod's integrator on the assembly seen as one system (:class:`SteppedSystem`)."""
    if chunked.run is cvode_system:
        return RawSolution(*cvode_system(chunked.assembly, y0, t_out, **solver))
    return chunked.run(SteppedSystem(chunked.assembly), y0, t_out, **solver)


def _sink(out, resume, overwrite):
    """The sink of ``out``: a sink as given (one with ``chunk_frames``), else a directory's."""
    if hasattr(out, "chunk_frames"):
        if resume and not hasattr(out, "restart"):
            raise ParameterError("`resume=True`: this sink cannot resume (no restart point)")
        return out
    return run_sinks.system_writer(out, resume=resume, overwrite=overwrite)


def _sized(name, value, size, scalar=True):
    arr = _checks.floats(value)
    if scalar and arr is not None and arr.shape == ():
        arr = np.full(size, float(arr))
    if arr is None or arr.shape != (size,) or not np.all(np.isfinite(arr)):
        raise ParameterError(f"`{name}` must be a number or {size} finite numbers (the system's state), "
                             f"got {_checks.short(value)}")
    return arr
