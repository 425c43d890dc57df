"""CVODE (BDF) over a system of rods and rigid bodies
(:class:`rodmol.discretise.assembly.Assembly`).

The Newton systems are solved (``linsolver``) by

* ``"gmres"`` (default): GMRES preconditioned by the rods' exact block
  preconditioners, the bodies' own blocks and, for free bodies with
  clamped rods or penalty joints, their Schur complement
  (:mod:`rodmol.discretise.system_preconditioner`), and the blocks of
  penalty joints between two rods' nodes by theirs
  (:mod:`rodmol.discretise.rod_joint_coupling`); about 2-3x faster than
  ``"sparse"`` on the octopus (``solvers/octopus.py``, docs/performance.md),
  as fast or faster on loops, also between rods, where it is 1.1 to 2
  times faster from N = 32 per rod (``solvers/loops.py``, docs/systems.md);
* ``"sparse"``: SuperLU_MT (scikit-sundae)
  on the assembly's Jacobian pattern, the rods' banded patterns on the
  diagonal and the joints' coupling blocks; scikit-sundae fills the
  Jacobian by its own coloured differences over that pattern;
* ``"dense"``: small systems and cross-checks.
"""

import math
import time

import numpy as np

from ..discretise.system_preconditioner import SystemPreconditioner
from ..errors import ParameterError
from .interrupts import stop_reason
from .outputs import RawSolution, cause
from .watch import assembly_state_problem

#: Linear solvers of a system run.
SYSTEM_LINEAR_SOLVERS = ("sparse", "gmres", "dense")
#: GMRES's Krylov dimension with the block preconditioner.
KRYLOV_DIM = 5


#: Non-finite right-hand sides between two output frames after which the run stops: CVODE
#: (scikit-sundae's right-hand side cannot report a recoverable failure) would otherwise retry
#: ever shorter steps without end; a sound run meets none, or a few in wild Newton iterates.
NONFINITE_RATES = 200
#: Right-hand sides between two output frames before their rates are checked: a sound run
#: takes a few to a few hundred, and is not slowed by the check (2 % of the octopus's).
WATCHED_AFTER = 1000


class _OutOfTime(Exception):
    """Raised inside the right-hand side when the wall-time budget is used up."""


class _NonFinite(Exception):
    """Raised inside the right-hand side when its rates were non-finite too often (its message says where)."""


class _Interrupted(Exception):
    """Raised inside the right-hand side, before its work, when a signal asked the run to stop
    (:func:`rodmol.solve.interrupts.stop_reason`, its message): CVODE's step is left there."""


def cvode_system(assembly, y0, t_out, *, rtol, atol, progress=None, max_wall_time=None, linsolver=None,
                 max_step=0.0, max_order="auto"):
    """Integrate ``assembly`` from ``y0`` at ``t_out[0]`` through the output
    times ``t_out`` [s].

    ``progress(t, t_end)`` is called at each output time; ``max_wall_time``
    [s] is checked at every right-hand side, and ends the run when used up, as
    does a stop asked by a signal (:mod:`rodmol.solve.interrupts`).

    ``max_order`` caps the BDF order; ``"auto"`` is 2 when a rod is lightly
    damped (``SemiDiscrete.lightly_damped``), else 5, as for one rod.

    Returns a :class:`~rodmol.solve.outputs.RawSolution`: the output frames
    reached; on failure (CVODE's, a user function's exception, Ctrl-C)
    ``message`` says after which output time and why, and ``error`` holds
    the exception that stopped it, if any.
    """
    from sksundae.cvode import CVODE, CVODEPrecond

    if linsolver is None:
        linsolver = "gmres"
    if linsolver not in SYSTEM_LINEAR_SOLVERS:
        raise ParameterError(f"unknown `linsolver` {linsolver!r} for a system; valid: {list(SYSTEM_LINEAR_SOLVERS)}")
    if max_order == "auto":
        max_order = 2 if assembly.lightly_damped else 5
    # Right-hand sides; those with non-finite rates since the last output frame; the first count then.
    evals = [0, 0, 0]
    origin = [None]  # the first of those from a finite state: where the rates turned non-finite
    # An exception raised through scikit-sundae's sparse (SuperLU_MT) path crashes the process
    # (a segmentation fault, found by review): there the right-hand side keeps it, returns NaN
    # rates, which fail CVODE's step at once, and the step's caller raises it.
    kept = [None]
    # There a signal's stop waits for the step to the next output: NaN rates would have CVODE
    # retry and print its failure before the step's caller stops.
    stop_inside = linsolver != "sparse"

    def rates(t, y, yp):
        evals[0] += 1
        asked = stop_inside and stop_reason()
        if asked:
            raise _Interrupted(asked)
        if max_wall_time is not None and time.perf_counter() - start > max_wall_time:
            raise _OutOfTime
        assembly(t, y, yp)
        if evals[0] - evals[2] > WATCHED_AFTER and not math.isfinite(yp.sum()) and not np.all(np.isfinite(yp)):
            evals[1] += 1
            if origin[0] is None and np.isfinite(y.sum()):  # where they turned so from a finite state
                origin[0] = _nonfinite(assembly, t, yp)
            if evals[1] >= NONFINITE_RATES:
                raise _NonFinite(origin[0] or _nonfinite(assembly, t, yp))

    def kept_rates(t, y, yp):
        if kept[0] is None:
            try:
                return rates(t, y, yp)
            except BaseException as exc:  # noqa: BLE001 (raised again by the step's caller)
                kept[0] = exc
        yp[:] = np.nan

    def step(t_k):
        r = solver.step(t_k)
        if kept[0] is not None:
            raise kept[0]
        return r

    options = dict(method="BDF", rtol=rtol, atol=atol, linsolver=linsolver, max_num_steps=1_000_000,
                   max_step=max_step, max_order=int(max_order))
    precond = None
    if linsolver == "sparse":
        options["sparsity"] = assembly.pattern()
    elif linsolver == "gmres":
        precond = SystemPreconditioner(assembly, np.broadcast_to(atol, (assembly.size,)) / rtol)
        options.update(precond=CVODEPrecond(precond.setup, precond.solve, "left"), krylov_dim=KRYLOV_DIM)
    t_out = np.asarray(t_out, dtype=float)
    start = time.perf_counter()
    if progress is not None:
        progress(float(t_out[0]), float(t_out[-1]))
    frames, message, error, jac_evals = [np.array(y0, dtype=float)], "", None, 0
    asked = stop_reason()  # before the run: no solver made (a sparse one freed unstepped crashes)
    if asked:
        message = f"CVODE stopped after t = {float(t_out[0]):.6g} s: {asked}"
    else:
        solver = CVODE(kept_rates if linsolver == "sparse" else rates, **options)
        solver.init_step(float(t_out[0]), frames[0])
    for t_k in [] if asked else t_out[1:]:
        reached = float(t_out[len(frames) - 1])
        try:
            r = step(float(t_k))
        except KeyboardInterrupt:
            message = f"CVODE interrupted after t = {reached:.6g} s"
            break
        except _OutOfTime:
            message = f"CVODE stopped after t = {reached:.6g} s: the wall-time budget max_wall_time = {max_wall_time:g} s is used up"
            break
        except (_NonFinite, _Interrupted) as exc:
            message = f"CVODE stopped after t = {reached:.6g} s: {exc}"
            break
        except Exception as exc:  # noqa: BLE001 (a user function's: reported with the frames before)
            message, error = f"CVODE stopped after t = {reached:.6g} s: {cause(exc)}", exc
            break
        if not r.success:
            message = f"CVODE stopped after t = {reached:.6g} s: {r.message}"
            break
        broken = assembly_state_problem(assembly, float(t_k), r.y)
        if broken:  # as a single rod's run: the frames before, and where and why
            message = f"CVODE stopped after t = {reached:.6g} s: {broken}"
            break
        frames.append(np.array(r.y))
        evals[1:], origin[0] = [0, evals[0]], None
        jac_evals = int(r.njev)
        if progress is not None:
            try:
                progress(float(t_k), float(t_out[-1]))
            except Exception as exc:  # noqa: BLE001 (the user's callable, guarded: a UserFunctionError)
                message, error = f"CVODE stopped at t = {float(t_k):.6g} s: {cause(exc)}", exc
                break
        asked = stop_reason()
        if asked and len(frames) < len(t_out):  # between two steps (inside one: `rates`)
            message = f"CVODE stopped after t = {float(t_k):.6g} s: {asked}"
            break
    t, y = t_out[:len(frames)], np.array(frames)
    assembly.project_quaternions(y)
    success = len(t) == len(t_out)
    stats = dict(rhs_evals=evals[0], jac_evals=jac_evals, linear_solver=linsolver,
                 wall_time_s=time.perf_counter() - start)
    if precond is not None:
        stats.update(jac_evals=precond.jac_evals, prec_setups=precond.setups, prec_solves=precond.solves)
    return RawSolution(t, y, success, message, stats, error)


def _nonfinite(assembly, t, rates):
    """Where the ``rates`` at ``t`` [s] are non-finite: each part (a rod or a body) and its first such entry."""
    where = [assembly.entry_name(part.start + int(bad[0])) for part in assembly.parts.values()
             for bad in [np.flatnonzero(~np.isfinite(rates[part]))] if len(bad)]
    return (f"the rates of {', '.join(where)} were non-finite at t = {t:.6g} s (from a finite state; "
            f"{NONFINITE_RATES} non-finite right-hand sides among the {WATCHED_AFTER + NONFINITE_RATES} or more "
            "since the last output frame): no step can be taken "
            "(the model gives no finite motion there: a load, an input or a body's property out of range?)")
