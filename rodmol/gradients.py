"""Adjoint gradients of a scalar loss of a run: :func:`gradient`.

A continuous adjoint over the one CVODE stepper: the forward run keeps its steps
(:mod:`rodmol.solve.checkpoints`; every K-th only with ``checkpoint_every=K``), the
loss reads its frames (:mod:`rodmol.losses`), and lambda with the gradient's
quadrature are integrated backwards by CVODE (:mod:`rodmol.solve.adjoint_backward`);
df/dp comes from :mod:`rodmol.parameter_rates` (one difference per cable for any
number of tension knots). See ``docs/gradients.md`` for what is differentiable and
how accurate and costly it is, as measured.
"""

import time

import numpy as np

from . import _checks, named_parameters
from .discretise.schemes import DEFAULT_SCHEME
from .errors import ParameterError
from .losses import Loss
from .parameter_rates import ParameterColumns
from .run_arguments import check_run, fit, prepare_run
from .run_kinds import run_kind
from .solve.adjoint_backward import LINEAR_SOLVERS, AdjointSystem, integrate_backward
from .solve.checkpoints import ForwardRun

#: The backward integration's tolerances relative to the run's: lambda accumulates the
#: jumps of every loss time, and with the run's own the gradient by E was 4.6e-4 off at
#: rtol 1e-6 (the arm of solvers/adjoint_cost.py); a tenth made it 5e-6 for 23 % more time.
BACKWARD_TOLERANCE = 0.1


def gradient(model, t_end, loss, parameters, *, checkpoint_every=None, adjoint_linsolver="auto",
             initial=None, scheme=None, rtol=None, atol=None, t0=None, max_wall_time=None, backend=None,
             stats=None, **backend_options):
    """The loss of a run of ``model`` to ``t_end`` [s] and its gradient by ``parameters``.

    Parameters
    ----------
    model : Model or System
    t_end : float
        End time [s].
    loss : rodmol.losses.Loss
        ``TipTracking``, ``MarkerTracking``, ``TerminalTarget``, ``Effort``,
        ``StateLoss`` or a sum of them.
    parameters : list of str
        Parameter keys (:mod:`rodmol.named_parameters`): ``"material.E"``,
        ``"medium.Cy,Cz"``, ``"tension.11"`` (its knot values), ``"bodies.head.mass"``,
        ``"rods.arm.material.E"`` ...
    checkpoint_every : int, optional
        Keep every K-th forward step only and integrate a segment again when the
        backward integration reaches it: memory of one segment instead of the whole
        run, at the cost of a second forward run. None: keep every step.
    adjoint_linsolver : "auto", "band", "dense" or "sparse"
        The backward integration's linear solver on J^T (``"auto"``: band for a
        rod, dense LU for a system up to 1500 entries, SuperLU beyond).
    initial, scheme, rtol, atol, t0, max_wall_time, **backend_options
        As for :func:`rodmol.simulate` (CVODE only; its options ``linsolver``,
        ``max_order`` ...). The backward integration takes the same ``rtol``.
    stats : dict, optional
        Filled with the run's counts and timings (forward steps, backward
        Jacobians, seconds of each half).

    Returns
    -------
    (float, dict)
        The loss and {key: (m,) array} its derivative by each parameter's values
        [loss unit per parameter unit].
    """
    kind = run_kind(model)
    if backend not in (None, "cvode"):
        raise ParameterError(f"gradient: `backend` must be 'cvode' (the adjoint integrates with CVODE), got {backend!r}")
    if not isinstance(loss, Loss):
        raise ParameterError(f"`loss` must be a rodmol loss (TipTracking, MarkerTracking, TerminalTarget, Effort, "
                             f"StateLoss or their sum), got {_checks.short(loss)}")
    if adjoint_linsolver not in LINEAR_SOLVERS:
        raise ParameterError(f"`adjoint_linsolver` must be one of {LINEAR_SOLVERS}, got {adjoint_linsolver!r}")
    if checkpoint_every is not None:
        checkpoint_every = _checks.integer_at_least("checkpoint_every", checkpoint_every, 2)
    args = check_run(initial=initial, t0=t0, scheme=DEFAULT_SCHEME if scheme is None else scheme, backend="cvode",
                     rtol=rtol, atol=atol, progress=None, max_wall_time=max_wall_time,
                     backend_options=backend_options, kind=kind)
    t_end = _checks.positive("t_end", t_end, " s")
    if t_end <= args.t0:
        raise ParameterError(f"`t_end` must be after the start t0 = {args.t0!r} s, got {t_end!r} s")
    system = kind.discretise(model, args.scheme)
    args = fit(args, system)
    _refuse_global_coupling(system)
    chosen = named_parameters.parameters(model, parameters)
    loss.check(model, args.t0, t_end)
    columns = ParameterColumns(kind, model, system, chosen)
    clock = time.perf_counter()
    y0, _ = prepare_run(system, args, None)
    frames_at = np.asarray(loss.times(args.t0, t_end), dtype=float)
    forward = ForwardRun(system, args.t0, y0, t_end, frames_at, rtol=args.rtol, atol=args.atol,
                         every=checkpoint_every, max_wall_time=args.max_wall_time, **args.backend_options)
    value, jumps = loss.evaluate(kind, system, frames_at, forward.frames, (args.t0, t_end))
    value += loss.direct(model, args.t0, t_end)
    forward_s = time.perf_counter() - clock
    scale = np.asarray(args.atol, dtype=float) / args.rtol
    adjoint = AdjointSystem(system, forward.state, scale)
    size = float(np.max(np.abs(jumps) * scale, initial=0.0))
    rtol_lambda = BACKWARD_TOLERANCE * args.rtol
    atol_lambda = rtol_lambda * (size if size > 0 else 1.0) / scale
    stops = np.concatenate([np.asarray(system.knot_times(), dtype=float), forward.boundaries()])
    lam0, q0, info = integrate_backward(adjoint, args.t0, t_end, list(zip(frames_at, jumps)), stops,
                                        lambda t, lam: columns.weighted(t, forward.state(t), lam), rtol=rtol_lambda,
                                        atol=atol_lambda, linsolver=adjoint_linsolver)
    total = np.zeros(columns.width) if q0 is None else np.array(q0)
    if isinstance(args.initial, str) and args.initial == "equilibrium" and np.any(lam0):
        total += lam0 @ columns.initial_equilibrium(args.t0, y0)
    grads = columns.split(total)
    for p in chosen:
        grads[p.key] += loss.direct_gradient(model, p, args.t0, t_end)
    if stats is not None:
        stats.update(forward_steps=forward.steps, kept_steps=len(forward.kept_t), forward_s=forward_s, backward_s=time.perf_counter() - clock - forward_s,
                     **info)
    return float(value), grads


def _refuse_global_coupling(system):
    """The adjoint's J is the compiled one on the system's pattern, which leaves out feedback
    tensions and cable friction (global couplings): refused rather than silently wrong."""
    rods = getattr(system, "rods", None)
    for name, rod in (rods.items() if rods is not None else [(None, system)]):
        if getattr(rod, "global_coupling", False):
            where = "" if name is None else f" (rod {name!r})"
            raise ParameterError(f"gradient: the model{where} has feedback tensions or cable friction, which couple "
                                 "the whole state; the adjoint's Jacobian leaves them out, so its gradient would "
                                 "be wrong (use simulate(..., sensitivities=[...]) instead)")
