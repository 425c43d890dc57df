"""The one entry point: :func:`simulate`, one path for a rod and for a system of rods and
bodies; what differs between them is :mod:`rodmol.run_kinds`' table."""

import warnings
from dataclasses import replace

import numpy as np

from . import _checks, _settings
from .discretise.schemes import DEFAULT_SCHEME
from .errors import ParameterError
from .run_arguments import check_run, fit, prepare_run
from .run_kinds import run_kind
from .solve import options
from .solve.chunked import run_chunked
from .solve.outputs import keep_before_failure

#: Values of ``resume``: "force" continues even with settings other than the run's.
RESUME = (False, True, "force")
#: Defaults of the settings ``simulate`` leaves as None (a resumed run takes the run's).
OUTPUT_DT, DEFAULT_BACKEND = 0.01, "cvode"
#: What a sink needs to resume a run (:mod:`rodmol.solve.chunked`).
RESUMING = ("resume_point", "check", "record_settings")


def default_atol(model, rtol):
    """Per-variable absolute tolerances: ``rtol`` times the typical size of
    each field (``rodmol.discretise.rod_scales.field_scales``: positions L,
    strains 1, curvatures 1/L, velocities L/T, angular velocities L/(T r_min)
    with T the first bending period), so that every field's error moves the
    rod by about ``rtol`` L: ``rtol`` times the system's own
    :meth:`~rodmol.discretise.system.SemiDiscrete.atol_scale` (a System's: its
    rods' and bodies'), as ``simulate`` takes it."""
    return rtol * run_kind(model).discretise(model).atol_scale()


def simulate(model, t_end, *, initial=None, scheme=None, backend=None, rtol=None, atol=None,
             output_dt=None, output_times=None, t0=None, progress=None, max_wall_time=None, out=None,
             resume=False, overwrite=False, sensitivities=None, **backend_options):
    """Integrate the model from t = 0 to ``t_end``.

    Parameters
    ----------
    model : Model or System
        One rod, or a System of rods and rigid bodies (``docs/systems.md``),
        whose run differs only where :mod:`rodmol.run_kinds` says: it starts
        from rest by default and returns a ``SystemResult``.
    t_end : float
        End time [s], absolute (> ``t0``).
    initial : "equilibrium", "straight", Result or array
        Initial state: the static equilibrium under the loads at ``t0`` (the
        paper's choice, a rod's default; a System's free bodies included), the
        unloaded rod at rest in its rest shape (straight unless the rod has
        rest strains: ``undeformed_state``; a System's default, its bodies at
        rest at their poses), an earlier :class:`Result` or ``SystemResult``
        (the run continues from its last state, at its last time unless ``t0``
        is given), or a state vector (``Result.states``).
    scheme : str
        The spatial scheme, a name from ``rodmol.SCHEMES``: ``"centred"``
        (second order in ds, the default) or ``"upwind"`` (the paper's, first
        order); see ``docs/model.md``.
    backend : str
        A name from ``rodmol.BACKENDS``: ``"cvode"`` (implicit BDF, the default),
        ``"galpha"`` (fixed-step generalized-alpha for stiff, lightly damped
        rods; options ``dt``, ``rho_inf``) or ``"rk23"`` (explicit, cross-check).
    rtol, atol : float, float or array
        Tolerances shared by all backends; ``rtol=None`` is the scheme's
        ``default_rtol`` (the time error about a tenth of the spatial error
        at N = 100), ``atol=None`` uses :func:`default_atol`.
    output_dt : float
        Interval between output frames [s], from ``t0`` (default 0.01 s);
        ``t_end`` is always an output.
    output_times : sequence of float, optional
        Output times [s] instead of a uniform ``output_dt`` (e.g. a camera's
        time stamps): increasing, within [t0, t_end]; ``t0`` and ``t_end``
        are always outputs.
    t0 : float, optional
        Start time [s] (default 0, or the last time of an ``initial``
        Result). Time-dependent inputs are read at absolute time.
    progress : bool or callable, optional
        True shows rodmol's progress display on standard error: the
        preparation of the compiled kernels (first run of a process) and the
        initial equilibrium, each with its duration, then a bar over the
        simulated time whose ETA counts integration only. A callable
        ``progress(t, t_end)`` is called at each output time, and between
        them every half second of wall time (``rodmol.solve.watch``); if it
        has a ``stage(text)`` context manager (as ``rodmol._progress.Progress``),
        the stages are announced through it too.
    max_wall_time : float, optional
        Wall-time budget [s]: the run stops there with ``success=False``.
    out : path or sink, optional
        Stream the frames while the run goes into this directory
        (:class:`rodmol.output.stream.RunWriter`: ``result.h5`` and ParaView's
        ``rod.xdmf``, see ``docs/paraview.md``; a System's:
        :class:`rodmol.output.system_stream.SystemRunWriter`, ``system.h5``
        and a folder per rod) or into a sink object with the same protocol
        (:mod:`rodmol.solve.chunked`); memory then stays bounded by one
        chunk, the solver restarts at every chunk boundary, and the result
        returned reads its arrays from the files. ``result.h5`` records the
        run's settings (``scheme``, ``backend``, ``rtol``, ``atol``, the
        backend options, the grid, the initial state and a fingerprint of
        the model's parameters, a System's of each of its parts,
        :mod:`rodmol._settings`). A directory holding an earlier run is
        refused unless ``overwrite`` or ``resume``.
    resume : bool or "force"
        With ``out``: continue the unfinished (killed, interrupted or failed)
        run in that directory from the last frame of its last complete chunk,
        on its planned output times, so that it ends exactly as the
        uninterrupted run; ``t_end`` must be the planned end. The state is
        the directory's; the settings left None (``scheme``, ``backend``,
        ``rtol``, ``atol``, ``initial``, the backend options, ``t0``,
        ``output_dt``, ``output_times``) are the run's, and a value that
        differs from the run's (or another model) is refused with a
        ParameterError naming each; ``"force"`` continues with the values given
        instead (not with another grid or other output times).
    overwrite : bool
        With ``out``: replace an earlier run in that directory (every file a
        run writes there, :mod:`rodmol.output.run_files`; other files are kept).
    sensitivities : list of str, optional
        Parameter keys (:mod:`rodmol.named_parameters`: ``"material.E"``,
        ``"medium.Cy,Cz"``, ``"tension.11"`` (its knot values),
        ``"bodies.head.mass"``, ``"rods.arm.material.E"`` ...) whose forward
        sensitivities are integrated with the state
        (:mod:`rodmol.sensitivities`); ``result.sensitivity(key)`` is then the
        derivative of every field of the result by that parameter
        (:class:`rodmol.derivatives.Derivative`, see ``docs/gradients.md``).
        CVODE (with GMRES) and RK23 only, not with ``out``.
    **backend_options
        Passed to the backend (e.g. ``linsolver="sparse"`` for CVODE);
        unknown names and bad values are refused before any work. None given
        with ``resume``: the run's.

    Returns
    -------
    Result or SystemResult
        If the solver fails, blows up, stalls or is interrupted, the result
        holds the frames computed so far, ``success`` is False, ``message``
        says where and why (see ``docs/troubleshooting.md``), ``error`` holds
        the exception that ended it (e.g. a user function's, with its
        traceback) and a warning is issued.
    """
    kind = run_kind(model)
    if not (resume is True or resume is False or (isinstance(resume, str) and resume in RESUME)):
        raise ParameterError(f"`resume` must be False, True or 'force', got {_checks.short(resume)}")
    if sensitivities is not None:
        from . import sensitivities as sensitivity

        sensitivity.check(sensitivities, DEFAULT_BACKEND if backend is None else backend, out, resume)
    sink, first, plan, recorded, kept = None, 0, None, {}, None
    asked_plan, asked_initial = (t0, output_dt, output_times), initial
    if resume:  # the run's directory first: its settings fill in what the call leaves out
        sink = _sink(kind, out, resume, overwrite)
        plan, first, kept = sink.resume_point()
        recorded = getattr(sink, "settings", None) or {}
        t0 = float(plan[first])
        scheme, backend, rtol, atol, backend_options = _settings.resumed(recorded, scheme, backend, rtol, atol,
                                                                         backend_options)
    args = check_run(initial=initial, t0=t0, scheme=DEFAULT_SCHEME if scheme is None else scheme,
                     backend=DEFAULT_BACKEND if backend is None else backend, rtol=rtol, atol=atol,
                     progress=progress, max_wall_time=max_wall_time, backend_options=backend_options, kind=kind)
    t_end = _checks.positive("t_end", t_end, " s")
    if t_end <= args.t0:
        raise ParameterError(f"`t_end` must be after the start t0 = {args.t0!r} s, got {t_end!r} s")
    output_dt = _checks.positive("output_dt", OUTPUT_DT if output_dt is None else output_dt, " s")
    system = kind.discretise(model, args.scheme)  # the one system of this run (no compiling): all below reads it
    if resume:  # before anything is sized by it: the states kept fix the grid
        sink.check(system)
    args = fit(args, system)
    augmented = None
    if sensitivities is not None:  # its keys checked and its systems built before any work
        augmented = sensitivity.Plan(kind, model, system, sensitivities)
        options.offered_by(augmented.system, args.backend_options)
    if resume and np.shape(kept) != (system.size,):
        raise ParameterError(f"cannot resume the run in {_where(sink)}: its state has {np.size(kept)} entries, "
                             f"this model's {system.size}")
    if plan is None:
        t_out = options.output_times(args.t0, t_end, output_dt, output_times, system.size)
    else:  # the run's own output times, from where it stopped
        if t_end != plan[-1]:
            raise ParameterError(f"`t_end` = {t_end!r} s: the run being resumed ends at {float(plan[-1])!r} s")
        _check_plan(plan, asked_plan, t_end, system.size, sink)
        t_out = plan
    if not resume:  # after every check: with `overwrite`, making the sink clears the earlier run
        sink = _sink(kind, out, resume, overwrite)
    # Resuming, the sink refuses other settings than the run's (unless forced) before it touches anything;
    # the initial state it records stays the run's.
    getattr(sink, "record_settings", lambda system, force, **run: None)(
        system, resume == "force", backend=args.backend, rtol=args.rtol, atol=args.asked_atol,
        backend_options=args.backend_options,  # asked_atol None: the default
        initial=(recorded.get("initial") or "unknown") if resume and asked_initial is None else args.initial)
    if resume:
        args = replace(args, initial=kept)
    progress = args.progress
    if progress is True:
        from ._progress import Progress

        progress = Progress()
    try:
        y0, timings = prepare_run(system, args, progress, sink)
        solver = dict(rtol=args.rtol, atol=args.atol, progress=progress, max_wall_time=args.max_wall_time,
                      **args.backend_options)
        integrated, start = system, y0
        if augmented is not None:  # the state and its sensitivities, one system (never into a sink)
            integrated, start = augmented.system, augmented.initial(y0, args.initial, args.t0)
            solver["atol"] = augmented.atol(args.atol)
        if sink is None:
            raw = keep_before_failure(args.run, integrated, start, t_out, **solver)
            success, message, stats, error = raw.success, raw.message, raw.stats, raw.error
        else:  # in chunks into the sink, whose result it is
            success, message, stats, error = run_chunked(args.run, system, y0, t_out, sink, first, **solver)
        stats.update(timings, backend=args.backend)
        result = kind.result(system, raw.t, raw.y[:, :system.size], success, message, stats) if sink is None \
            else sink.end(success, message, stats)
        if augmented is not None:
            result.sensitivities = augmented.derivatives(raw.t, raw.y, success, message, stats)
    finally:
        if args.progress is True:
            progress.close()
    result.error = error
    if not success:
        warnings.warn(message, RuntimeWarning, stacklevel=2)
    return result


def _sink(kind, out, resume, overwrite):
    """The sink of ``out``: None, a sink as given, or the ``kind``'s directory sink."""
    if out is None:
        if resume or overwrite:
            raise ParameterError(f"`{'resume' if resume else 'overwrite=True'}` needs `out`, the directory of the run")
        return None
    if resume and overwrite:
        raise ParameterError("give either `resume` or `overwrite=True`, not both")
    if all(hasattr(out, name) for name in ("begin", "frames", "end", "chunk_frames")):
        missing = [name for name in RESUMING if not hasattr(out, name)]
        if resume and missing:
            raise ParameterError(f"`resume=True`: this sink cannot resume (it has no {', '.join(missing)})")
        return out
    return kind.directory_sink(out, resume=bool(resume), overwrite=bool(overwrite))


def _where(sink):
    """The run being resumed, for messages: its directory (quoted), or the sink."""
    return repr(str(getattr(sink, "directory", sink)))


def _check_plan(plan, asked, t_end, size, sink):
    """Refuse a resumed call whose ``asked`` (t0, output_dt, output_times) give other output
    times than the run's ``plan``: the frames kept are on it."""
    t0, output_dt, output_times = asked
    if t0 is None and output_dt is None and output_times is None:
        return
    start = float(plan[0]) if t0 is None else _checks.non_negative("t0", t0, " s")
    dt = _checks.positive("output_dt", OUTPUT_DT if output_dt is None else output_dt, " s")
    wanted = options.output_times(start, t_end, dt, output_times, size) if start < t_end else np.array([start])
    if not np.array_equal(wanted, plan):
        where = _where(sink)

        def show(times):
            return f"{len(times)} from {float(times[0])!r} to {float(times[-1])!r} s"

        raise ParameterError(f"cannot resume the run in {where}: its output times are {show(plan)}, this call "
                             f"asks for {show(wanted)} (leave out `t0`, `output_dt` and `output_times` to "
                             "continue on the run's)")
