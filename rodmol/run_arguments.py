"""The checked arguments of a run (:class:`RunArguments`) that :func:`rodmol.simulate`
shares with the stepping simulator, inverse statics' and the gradient's runs: what
needs no system (:func:`check_run`), what is sized by its state (:func:`fit`), the
states a user gives (:func:`check_state`), and the preparation before the first step
(:func:`prepare_run`: the compiled kernels, the initial state)."""

import time
from contextlib import contextmanager, nullcontext
from dataclasses import dataclass, replace

import numpy as np

from . import _checks
from .discretise.schemes import get_scheme
from .errors import ParameterError
from .run_kinds import KINDS
from .solve import kernels, options
from .solve.backends import get_backend
from .solve.equilibrium import equilibrium

#: The states a run can start from by name.
INITIAL = ("equilibrium", "straight")
#: What an ``initial`` result may be: a run's of any kind (each kind takes its own).
RESULTS = tuple(kind.results for kind in KINDS)


@dataclass(frozen=True)
class RunArguments:
    """The checked arguments a run of :func:`simulate` shares with the stepping
    simulator (:class:`rodmol.control.Simulator`): :func:`check_run` checks what
    needs no system, :func:`fit` sizes ``initial`` and ``atol`` by the system's state."""

    initial: object  # "equilibrium", "straight", a result or a state vector (checked by fit)
    t0: float
    scheme: object
    rtol: float
    atol: object  # as given (None: the default); an array of the state's size after fit
    progress: object  # None, True or a callable
    max_wall_time: float | None
    backend: str
    run: object
    backend_options: dict
    kind: object  # the model's RunKind (rodmol.run_kinds)
    asked_atol: object = None  # after fit: the checked array the call gave, or None for the default


def check_run(*, initial, t0, scheme, backend, rtol, atol, progress, max_wall_time, backend_options,
              kind=KINDS[0]):
    """Check the arguments that a run of a ``kind`` of model (default: one rod) takes (see
    :func:`simulate`) and that need no system, before any work; ``initial`` None is the
    kind's default, an ``initial`` result gives, unless ``t0`` is given, its last time. The
    state-sized ones (``initial``, ``atol``) are checked by :func:`fit` against the system."""
    initial = kind.default_initial if initial is None else initial
    if isinstance(initial, RESULTS):
        t0 = float(initial.t[-1]) if t0 is None else t0
    else:
        check_word("initial", initial)
    t0 = 0.0 if t0 is None else _checks.non_negative("t0", t0, " s")
    scheme = get_scheme(scheme)
    rtol = options.rtol(scheme.default_rtol if rtol is None else rtol)
    progress = options.progress(progress)
    max_wall_time = options.max_wall_time(max_wall_time)
    run = get_backend(backend)
    backend_options = options.backend_options(backend, run, backend_options)
    return RunArguments(initial, t0, scheme, rtol, atol, progress, max_wall_time, backend, run,
                        backend_options, kind)


def fit(args, system):
    """``args`` with ``initial`` and ``atol`` checked against the state of ``system``: an
    ``initial`` result gives its last state, ``atol=None`` the system's ``atol_scale()``
    (:meth:`~rodmol.discretise.system.SemiDiscrete.atol_scale`) times ``rtol``; a backend
    option the system does not offer (a linear solver) is refused."""
    initial = args.initial
    if isinstance(initial, RESULTS):
        initial = _last_state(initial, args.kind, system)
    if not isinstance(initial, str):  # before any sink is made (`overwrite` then clears the earlier run)
        initial = check_state("initial", initial, system, args.t0)
    atol = None if args.atol is None else _state_sized("atol", args.atol, system, positive=True)
    options.offered_by(system, args.backend_options)
    return replace(args, initial=initial, asked_atol=atol,
                   atol=args.rtol * system.atol_scale() if atol is None else atol)


def check_word(name, value):
    """``value``; a string must be one of :data:`INITIAL` (the states a run can start from
    by name), else a ParameterError names the parameter ``name``, the value and the words."""
    if isinstance(value, str) and value not in INITIAL:
        raise ParameterError(f"unknown `{name}` {_checks.short(value)}{_checks.did_you_mean(value, INITIAL)}"
                             "; use 'equilibrium', 'straight' or a state")
    return value


def check_state(name, value, system, t=0.0):
    """``value``, the parameter ``name``, as a state vector of ``system`` (a copy), or a
    ParameterError naming it: the rule for every state a user gives (simulate's and the
    Simulator's ``initial``, linearize's ``state``). Refused: another size, a non-finite
    entry (named) and what the system's ``state_problem`` at ``t`` [s] finds (an element
    inverted or torn, an orientation whose quaternion norm is off 1 by more than
    ``watch.MAX_QUATERNION_DRIFT``, a zero one too); a quaternion within it is taken as it
    is (the rotations are normalised on the fly), as an integration takes its own."""
    state = _state_sized(name, value, system)
    problem = system.state_problem(t, state)
    if problem:
        raise ParameterError(f"`{name}` is not a state of this model: {problem}")
    return state


def prepare_run(system, args, progress, sink=None):
    """The compiled kernels of ``system`` made ready (where its kind prepares them before the
    run: ``RunKind.prepare``) and the initial state, each stage announced through
    ``progress``: returns (y0, timings [s])."""
    timings, prepare = {}, args.kind.prepare
    with _stage(progress, kernels.stage_text(), timings, "prepare_s",
                prepare is None or kernels.ready(args.run, args.backend_options)):
        if prepare is not None:
            prepare(system, args.t0, system.undeformed_state(), args.run, args.rtol, args.atol,
                    args.backend_options)
        getattr(sink, "prepare", lambda system: None)(system)
    initial = args.initial
    with _stage(progress, f"solving the initial equilibrium at t = {args.t0:g} s", timings, "equilibrium_s",
                not (isinstance(initial, str) and initial == "equilibrium")):
        y0 = initial_state(system, initial, args.t0)
    return y0, timings


@contextmanager
def _stage(progress, text, timings, key, silent=False):
    """Time a stage into ``timings[key]`` [s], announced through ``progress.stage``."""
    start = time.perf_counter()
    announce = getattr(progress, "stage", None)
    with nullcontext() if silent or announce is None else announce(text):
        yield
    timings[key] = time.perf_counter() - start


def _last_state(result, kind, system):
    if not isinstance(result, kind.results):
        raise ParameterError(f"`initial`: a {type(result).__name__} cannot start a run of a "
                             f"{kind.model.__name__} (a {kind.results.__name__} can)")
    states = getattr(result, "states", None)
    if states is None or len(states) == 0:
        raise ParameterError("`initial`: this result holds no states (written by an older rodmol?)")
    if len(states[-1]) != system.size:
        n = getattr(result, "meta", {}).get("n_elements")
        raise ParameterError(f"`initial`: the result's states have {len(states[-1])} entries"
                             f"{'' if n is None else f' (N = {n} elements)'}, this model's {system.size}")
    return states[-1]


def initial_state(system, initial, t0):
    """The state ``initial`` names at ``t0`` [s] (a word of :data:`INITIAL`), or the state
    vector given (checked by :func:`check_state`) as a new array."""
    if isinstance(initial, str):
        if initial == "equilibrium":
            return equilibrium(system, t0)
        if initial == "straight":  # the rest shape: straight unless the rod has rest strains
            return system.undeformed_state()
    return np.array(initial, dtype=float)  # checked by fit, or the resumed run's own state


def _state_sized(name, value, system, positive=False):
    """A finite float array of the state's size (``system``'s; a scalar is broadcast if
    ``positive``); the error names the first bad entry, which numpy's summarised repr would hide."""
    size = system.size
    try:
        arr = np.asarray(value, dtype=float)
    except (TypeError, ValueError, OverflowError):
        raise ParameterError(f"`{name}` must be numbers, got {_checks.short(value)}") from None
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
        raise ParameterError(f"`{name}` entries must be {need}, got {float(arr[i])!r} at entry {i} "
                             f"({system.entry_name(i)})")
    return arr.copy()
