"""Checks of :func:`rodmol.simulate`'s arguments, all made before any work is done.

Backend options are checked against the backend's own keyword arguments
(unknown or misspelled names get a did-you-mean), and their values against
:data:`VALUES`; output sizes are bounded before anything is allocated.
"""

import inspect
import math

import numpy as np

from .. import _checks
from ..errors import ParameterError, RodmolError

#: Relative tolerances accepted (outside: round-off, or no accuracy at all).
RTOL_RANGE = (1e-14, 0.1)
#: Most output frames a run may ask for, and most memory [bytes] its states may take.
MAX_OUTPUT_FRAMES = 1_000_000
MAX_STATE_BYTES = 2 * 1024**3
#: Arguments every backend takes from simulate itself (not backend options).
COMMON = ("rtol", "atol", "progress", "max_wall_time")
#: simulate's own keywords, offered as suggestions for misspelled options.
SIMULATE_KEYWORDS = ("initial", "scheme", "backend", "rtol", "atol", "output_dt", "output_times",
                     "t0", "progress", "max_wall_time", "out", "resume", "overwrite")


def _integer_in(low, high):
    def check(name, value):
        value = _checks.integer_at_least(name, value, low)
        if value > high:
            raise ParameterError(f"`{name}` must be an integer in [{low}, {high}], got {value!r}")
        return value
    return check


def _auto_or(check):
    def either(name, value):
        return value if isinstance(value, str) and value == "auto" else check(name, value)
    return either


def _max_step(name, value):
    if value == math.inf:
        return value
    return _checks.non_negative(name, value, " s (0: no limit)")


def _unit_interval(name, value):
    value = _checks.finite(name, value)
    if not 0.0 <= value <= 1.0:
        raise ParameterError(f"`{name}` must lie in [0, 1], got {value!r}")
    return value


def _choice(options):
    def check(name, value):
        return _checks.choice(name, value, options)
    return check


def _values():
    from .stepping import JACOBIANS, LINEAR_SOLVERS

    return {
        "max_order": _auto_or(_integer_in(1, 5)),
        "max_nonlin_iters": _integer_in(1, 100),
        "max_step": _max_step,
        "linsolver": _choice(("auto", *LINEAR_SOLVERS)),
        "jacobian": _choice(("auto", *JACOBIANS)),
        "dt": _auto_or(lambda name, value: _checks.positive(name, value, " s")),
        "rho_inf": _unit_interval,
        "python_loop": _checks.flag,
    }


def backend_options(backend, run, options):
    """The checked ``options`` of backend function ``run`` (named ``backend``)."""
    accepted = [name for name, p in inspect.signature(run).parameters.items()
                if p.kind is inspect.Parameter.KEYWORD_ONLY and name not in COMMON]
    values = _values()
    checked = {}
    for key, value in options.items():
        if key not in accepted:
            tip = _checks.did_you_mean(key, accepted + list(SIMULATE_KEYWORDS))
            valid = ", ".join(accepted) if accepted else "none"
            raise ParameterError(f"unknown option `{key}` for backend {backend!r}{tip} "
                                 f"(its options: {valid})")
        checked[key] = values[key](key, value) if key in values else value
    return checked


def offered_by(system, options):
    """Refuse, before any work, the checked backend ``options`` that ``system`` does not
    offer: a CVODE ``linsolver`` outside its ``linear_solvers()``
    (:func:`rodmol.solve.stepping.linear_solver`, the one rule)."""
    if "linsolver" in options:
        from .stepping import linear_solver

        linear_solver(system, options["linsolver"])


def rtol(value):
    value = _checks.positive("rtol", value)
    low, high = RTOL_RANGE
    if not low <= value <= high:
        raise ParameterError(f"`rtol` must lie in [{low:g}, {high:g}], got {value!r}")
    return value


def progress(value):
    """None, True (rodmol's display) or the user's callable, guarded (:class:`GuardedProgress`)."""
    if value is None or value is False:
        return None
    if value is not True and not callable(value):
        raise ParameterError(f"`progress` must be True, False, None or a callable progress(t, t_end), "
                             f"got {_checks.short(value)}")
    return value if value is True else GuardedProgress(value)


class GuardedProgress:
    """The user's ``progress(t, t_end)``: an exception it raises becomes a
    :class:`rodmol.errors.UserFunctionError` naming it and t (the run then ends
    as a failed run that keeps its frames, as for any function of the user's);
    its other attributes (a ``stage`` context manager) are its own."""

    def __init__(self, function):
        self.function = function

    def __call__(self, t, t_end):
        try:
            self.function(t, t_end)
        except RodmolError:
            raise
        except Exception as exc:  # noqa: BLE001 (the user's function: chained, never lost)
            raise _checks.user_error("the `progress` callable", exc, t) from exc

    def __getattr__(self, name):
        if name == "function":  # not set yet (a copy being made): no recursion
            raise AttributeError(name)
        return getattr(self.function, name)


def max_wall_time(value):
    return None if value is None else _checks.positive("max_wall_time", value, " s")


def output_times(t0, t_end, output_dt, times, state_size):
    """The output times [s]: ``times`` (checked: finite, increasing, within
    [t0, t_end]) or every ``output_dt`` from t0; t0 and t_end always."""
    if times is None:
        n_out = output_count(t_end - t0, output_dt, state_size, "t_end - t0" if t0 else "t_end")
        uniform = t0 + np.arange(n_out + 1) * output_dt
        return np.unique(np.append(uniform[uniform < t_end], t_end))
    try:
        times = np.asarray(times, dtype=float).ravel()
    except (TypeError, ValueError, OverflowError):
        raise ParameterError(f"`output_times` must be numbers [s], got {_checks.short(times)}") from None
    if not np.all(np.isfinite(times)) or np.any(np.diff(times) <= 0):
        raise ParameterError(f"`output_times` must be finite and increasing, got {_checks.short(times.tolist())}")
    if times.size and (times[0] < t0 or times[-1] > t_end):
        raise ParameterError(f"`output_times` must lie in [t0, t_end] = [{t0!r}, {t_end!r}] s, got "
                             f"{times[0].item()!r} ... {times[-1].item()!r} s")
    limit = min(MAX_OUTPUT_FRAMES, MAX_STATE_BYTES // (8 * state_size))
    if times.size + 2 > limit:
        raise ParameterError(f"`output_times` asks for {times.size} frames; at most {limit} are allowed")
    return np.unique(np.concatenate([[t0], times, [t_end]]))


def output_count(t_end, output_dt, state_size, name="t_end"):
    """Number of output intervals, refused before anything is allocated if the
    frames would be too many or their states too large."""
    frames = t_end / output_dt + 1.0
    limit = min(MAX_OUTPUT_FRAMES, MAX_STATE_BYTES // (8 * state_size))
    if frames > limit:
        raise ParameterError(
            f"{name} = {t_end!r} s with output_dt = {output_dt!r} s asks for {frames:.3g} output "
            f"frames; at most {limit} are allowed (states of {state_size} numbers each): raise "
            f"`output_dt` to at least {t_end / (limit - 1):.3g} s or shorten the run")
    return int(math.floor(t_end / output_dt + 1e-9))
