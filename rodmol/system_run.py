"""A run of a :class:`rodmol.System` (rods and rigid bodies), reached through
:func:`rodmol.simulate`: in memory, from rest, with CVODE; with ``out=DIR``
its files are written once it ended (:mod:`rodmol.output.system_files`,
through :func:`rodmol.run_sinks.system_writer`).

Not yet for systems (each raises :class:`rodmol.errors.NotSupportedYet`):
streaming while the run goes,
``resume`` and the other backends. ``progress`` is reported at the output times only.
"""

import warnings

import numpy as np

from . import _checks, run_sinks
from .discretise.assembly import Assembly
from .discretise.schemes import DEFAULT_SCHEME, get_scheme
from .errors import NotSupportedYet, ParameterError
from .solve import options
from .solve.equilibrium import equilibrium
from .solve.system_cvode import cvode_system
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
    arguments as for :func:`rodmol.simulate`. Returns a
    :class:`rodmol.system_result.SystemResult`."""
    if resume is not False:
        raise NotSupportedYet("`resume` is not supported yet for systems (their files are written after the run)")
    if out is None and overwrite is not False:
        raise ParameterError("`overwrite` needs `out`")
    if backend not in (None, "cvode"):
        raise NotSupportedYet(f"`backend` {backend!r} is not supported yet for systems: use 'cvode'")
    checked = options.backend_options("cvode", cvode_system, backend_options)
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
    t_out = options.output_times(t0, t_end, output_dt, output_times, assembly.size)
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
    writer = None if out is None else run_sinks.system_writer(out, overwrite=bool(overwrite))
    owned = progress is True
    if owned:
        from ._progress import Progress

        progress = Progress()
    try:
        t, y, success, message, stats, error = cvode_system(assembly, y0, t_out, rtol=rtol, atol=atol,
                                                            progress=progress, max_wall_time=max_wall_time,
                                                            **checked)
    finally:
        if owned:
            progress.close()
    if not success:
        warnings.warn(message, RuntimeWarning, stacklevel=3)
    result = SystemResult(assembly, t, y, success, message, stats, error)
    if writer is not None:
        writer(result)
    return result


def _sized(name, value, size, scalar=True):
    arr = _checks.floats(value)
    if scalar and arr is not None and arr.shape == ():
        arr = np.full(size, float(arr))
    if arr is None or arr.shape != (size,) or not np.all(np.isfinite(arr)):
        raise ParameterError(f"`{name}` must be a number or {size} finite numbers (the system's state), "
                             f"got {_checks.short(value)}")
    return arr
