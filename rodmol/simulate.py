"""The one entry point: :func:`simulate`."""

import warnings

import numpy as np

from . import _checks
from .discretise import rotations
from .discretise.layout import StateLayout
from .discretise.schemes import DEFAULT_SCHEME
from .discretise.system import SemiDiscrete, field_scales
from .errors import ParameterError
from .model import Model
from .result import from_states
from .solve.backends import get_backend
from .solve.equilibrium import equilibrium


def default_atol(model, rtol):
    """Per-variable absolute tolerances: ``rtol`` times the typical size of
    each field (``rodmol.discretise.system.field_scales``: positions L,
    strains 1, curvatures 1/L, velocities L/T, angular velocities L/(T r_min)
    with T the first bending period), so that every field's error moves the
    rod by about ``rtol`` L."""
    return rtol * StateLayout(model.n_elements).scales(field_scales(model))


def straight_state(model):
    """The undeformed rod at rest along the base's x axis."""
    base = model.base
    return StateLayout(model.n_elements).straight(
        model.s_nodes, np.asarray(base.position, dtype=float), np.asarray(base.rotation, dtype=float),
        rotations.from_matrix(base.rotation))


def simulate(model, t_end, *, initial="equilibrium", scheme=DEFAULT_SCHEME, backend="cvode",
             rtol=None, atol=None, output_dt=0.01, progress=None, **backend_options):
    """Integrate the model from t = 0 to ``t_end``.

    Parameters
    ----------
    model : Model
    t_end : float
        End time [s] (> 0).
    initial : "equilibrium", "straight" or array
        Initial state: the static equilibrium under the loads at t = 0 (the
        paper's choice), the undeformed straight rod at rest, or a state
        vector (e.g. the last state of an earlier run).
    scheme : str
        The spatial scheme, a name from ``rodmol.SCHEMES``: ``"centred"``
        (second order in ds, default) or ``"upwind"`` (the paper's, first
        order); see ``docs/model.md``.
    backend : str
        A name from ``rodmol.BACKENDS``: ``"cvode"`` (implicit BDF, default)
        or ``"rk23"`` (explicit, cross-check).
    rtol, atol : float, float or array
        Tolerances shared by all backends; ``rtol=None`` is the scheme's
        ``default_rtol`` (the time error about a tenth of the spatial error
        at N = 100), ``atol=None`` uses :func:`default_atol`.
    output_dt : float
        Interval between output frames [s]; ``t_end`` is always an output.
    progress : callable, optional
        ``progress(t, t_end)`` is called at each output time.
    **backend_options
        Passed to the backend (e.g. ``linsolver="sparse"`` for CVODE).

    Returns
    -------
    Result
        If the solver fails or is interrupted, the result holds the frames
        computed so far, ``success`` is False, ``message`` says where and why,
        and a warning is issued.
    """
    if not isinstance(model, Model):
        raise ParameterError(f"`model` must be a rodmol.Model, got {model!r}")
    t_end = _checks.positive("t_end", t_end, " s")
    output_dt = _checks.positive("output_dt", output_dt, " s")
    run = get_backend(backend)
    system = SemiDiscrete(model, scheme)  # the one system of this run
    rtol = _checks.positive("rtol", system.scheme.default_rtol if rtol is None else rtol)
    y0 = _initial_state(system, initial)
    if atol is None:
        atol = default_atol(model, rtol)
    else:
        atol = _state_sized("atol", atol, system.size, positive=True, layout=system.layout)

    n_out = int(np.floor(t_end / output_dt + 1e-9))
    t_out = np.unique(np.append(np.arange(n_out + 1) * output_dt, t_end))
    raw = run(system, y0, t_out, rtol=rtol, atol=atol, progress=progress, **backend_options)
    raw.stats["backend"] = backend
    result = from_states(system, raw.t, raw.y, raw.success, raw.message, raw.stats)
    if not raw.success:
        warnings.warn(raw.message, RuntimeWarning, stacklevel=2)
    return result


def _initial_state(system, initial):
    if isinstance(initial, str):
        if initial == "equilibrium":
            return equilibrium(system.model, 0.0, system=system)
        if initial == "straight":
            return straight_state(system.model)
        raise ParameterError(f"unknown `initial` {initial!r}; use 'equilibrium', 'straight' or a state")
    return _state_sized("initial", initial, system.size, layout=system.layout)


def _state_sized(name, value, size, positive=False, layout=None):
    """A finite float array of length ``size`` (a scalar is broadcast if ``positive``);
    the error names the first bad entry, which numpy's summarised repr would hide."""
    try:
        arr = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise ParameterError(f"`{name}` must be numbers, got {value!r}") from None
    if positive and arr.ndim == 0:
        if not (np.isfinite(arr) and arr > 0):
            raise ParameterError(f"`{name}` must be finite and > 0, got {float(arr)!r}")
        arr = np.full(size, float(arr))
    if arr.shape != (size,):
        raise ParameterError(f"`{name}` must have length {size} (the state size), got shape {arr.shape}")
    bad = ~np.isfinite(arr) | ((arr <= 0) if positive else False)
    if np.any(bad):
        i = int(np.flatnonzero(bad)[0])
        need = "finite and > 0" if positive else "finite"
        where = f" ({layout.entry_name(i)})" if layout is not None else ""
        raise ParameterError(f"`{name}` entries must be {need}, got {float(arr[i])!r} at entry {i}{where}")
    return arr.copy()
