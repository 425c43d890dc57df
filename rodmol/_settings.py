"""How a run was made, as :func:`rodmol.simulate` records it for a streamed run
(``result.h5``'s ``info["settings"]``), and the check of a resumed run against it.

A resumed run continues with the recorded settings wherever the call gives
none, and is refused (:func:`check`) when the call or the scenario asks for
another value, unless it forces the resume (``resume="force"``, the command
line's ``--resume-anyway``). The grid and the output times cannot be
forced: the frames kept fix them (the grid is :func:`check_grid`'s, checked
once, before anything is sized by it). Each takes what the run's system owns.
A :class:`rodmol.System`'s run records the same settings
(:func:`record_system`), its model as the fingerprints of its parts, so that a
refusal names the parts that changed.
"""

import json

import numpy as np

from ._fingerprint import fingerprint, model_fingerprint, system_fingerprints
from .errors import ParameterError

#: The recorded settings, in the order messages name them, with how a message names each.
NAMES = {"n_elements": "number of elements N (the grid)", "model": "model (fingerprint of its parameters)",
         "system": "system (fingerprints of its parts)",
         "scheme": "scheme", "backend": "backend", "rtol": "rtol", "atol": "atol",
         "backend_options": "backend options", "initial": "initial state"}


def record(system, *, backend, rtol, atol, backend_options, initial):
    """The settings of a run of ``system`` (a ``SemiDiscrete``: its grid, model and scheme),
    as JSON values: ``atol`` None for :func:`rodmol.simulate.default_atol` or the per-entry
    array, ``initial`` a name or the state vector (recorded as its fingerprint)."""
    return dict(n_elements=int(system.layout.n_blocks), model=model_fingerprint(system.model),
                **_solver(system.scheme, backend, rtol, atol, backend_options, initial))


def record_system(assembly, *, backend, rtol, atol, backend_options, initial):
    """The settings of a run of a :class:`rodmol.System` (its ``Assembly``): as :func:`record`'s,
    with the fingerprints of the system's parts (:func:`rodmol._fingerprint.system_fingerprints`)
    for the model's; the rods' grids fix the state's layout, which the run's index compares."""
    return dict(system=system_fingerprints(assembly.system),
                **_solver(assembly.scheme, backend, rtol, atol, backend_options, initial))


def _solver(scheme, backend, rtol, atol, backend_options, initial):
    return dict(scheme=str(scheme.name), backend=str(backend), rtol=float(rtol),
                atol=None if atol is None else np.asarray(atol, dtype=float).tolist(),
                backend_options=json.loads(json.dumps(dict(backend_options), default=repr)),
                initial=described_initial(initial))


def described_initial(initial):
    """How the settings record an initial state: its name, or a state vector's fingerprint."""
    if isinstance(initial, str):
        return initial
    return f"a state vector (fingerprint {fingerprint(np.asarray(initial, dtype=float))[:16]})"


def resumed(recorded, scheme, backend, rtol, atol, backend_options):
    """(scheme, backend, rtol, atol, backend_options) of a resumed run: each the call leaves
    None taken from the run's ``recorded`` settings, and its backend options too when the call
    gives none for the recorded backend (another backend keeps its own)."""
    scheme = recorded.get("scheme") if scheme is None else scheme
    backend = recorded.get("backend") if backend is None else backend
    rtol = recorded.get("rtol") if rtol is None else rtol
    atol = recorded.get("atol") if atol is None else atol
    if not backend_options and backend == recorded.get("backend"):
        backend_options = recorded.get("backend_options") or {}
    return scheme, backend, rtol, atol, backend_options


def differences(recorded, current):
    """(name, the run's value, this call's value) of each recorded setting that differs."""
    found = []
    for key in NAMES:
        if key not in recorded:  # recorded by an older rodmol
            continue
        run, now = recorded[key], current[key]
        if key == "atol" and run is not None and now is not None:
            same = np.array_equal(np.asarray(run, dtype=float), np.asarray(now, dtype=float))
        else:
            same = run == now
        if not same:
            found.append((key, run, now))
    return found


def check_grid(recorded, system, where):
    """Refuse to resume the run in ``where`` on another grid than its recorded one (the
    grid of ``system``, a ``SemiDiscrete``); before anything is sized by that grid."""
    n_elements = int(system.layout.n_blocks)
    run = recorded.get("n_elements", n_elements)
    if run != n_elements:
        raise ParameterError(f"cannot resume the run in {where}: {NAMES['n_elements']}: the run {run!r}, this "
                             f"call {n_elements!r} (the states kept are on the run's grid: resume with its "
                             "number of elements, or start a new run)")


def settle(recorded, settings, force, where):
    """(settings to record, what a forced resume changed) of a call with ``settings`` that resumes
    the run in ``where`` (``recorded``: its settings; None or empty: a new run): :func:`check`'s
    refusal unless ``force``; the initial state recorded stays the run's (a resumed run goes on
    from its restart point, whatever the call asked)."""
    if not recorded:
        return settings, []
    forced = check(recorded, settings, force, where)
    return dict(settings, initial=recorded.get("initial", settings["initial"])), forced


def check(recorded, current, force, where):
    """Refuse (ParameterError) to resume the run in ``where`` with ``current`` settings other
    than ``recorded``, unless ``force``; returns the differences, described (for the record
    of a forced resume). The grid, which cannot be forced, is :func:`check_grid`'s."""
    found = differences(recorded, current)
    said = [_said(key, run, now) for key, run, now in found]
    if found and not force:
        raise ParameterError(
            f"cannot resume the run in {where} with other settings than it was made with:\n  "
            + "\n  ".join(said) + "\nleave them out of the call (or the scenario) to continue with the run's, "
            "or force it: simulate(..., resume='force'), on the command line `--resume-anyway`")
    return said


def _said(key, run, now):
    """How a refusal names the setting ``key`` that differs: the run's value and this call's
    (for a system, the parts whose fingerprints differ)."""
    if key == "system":
        changed = [part for part in {**run, **now} if run.get(part) != now.get(part)]
        gone = [part for part in changed if part not in now]
        new = [part for part in changed if part not in run]
        kept = [part for part in changed if part in run and part in now]
        text = "; ".join(f"{what} {', '.join(parts)}" for what, parts in
                         (("changed:", kept), ("not in this call's system:", gone), ("new:", new)) if parts)
        return f"{NAMES[key]}: {text}"
    return f"{NAMES[key]}: the run {_show(key, run)}, this call {_show(key, now)}"


def _show(key, value):
    if key == "atol":
        if value is None:
            return "default (rtol times the fields' scales)"
        values = np.asarray(value, dtype=float)
        return f"{values[0]!r}" if np.all(values == values[0]) else f"an array from {values.min()!r} to {values.max()!r}"
    if key == "backend_options":
        return ", ".join(f"{k}={v!r}" for k, v in sorted(value.items())) or "none"
    if key == "model":
        return str(value)[:16]
    return repr(value)
