"""SUNDIALS CVODE (BDF) through scikit-sundae."""

import contextlib
import warnings

import numpy as np
from scipy import sparse

from ..discretise.preconditioner import check_structure
from ..errors import ParameterError
from ..inputs import knot_times
from .outputs import Outputs, run_steps, step_size_stats
from .watch import Watch

LINEAR_SOLVERS = ("gmres", "band", "lapackband", "sparse", "dense")
#: How the direct linear solvers get the Jacobian (see :func:`cvode`).
JACOBIANS = ("compiled", "sundials")
#: From this many elements on, linsolver="auto" picks the preconditioned GMRES.
GMRES_MIN_ELEMENTS = 50


def cvode(system, y0, t_out, *, rtol, atol, progress=None, max_wall_time=None, linsolver="auto",
          max_step=0.0, jacobian="auto", max_order="auto", max_nonlin_iters=3):
    """SUNDIALS CVODE (BDF) through scikit-sundae.

    ``linsolver`` is how the Newton systems (I - gamma J) x = r are solved:

    * ``"gmres"``: GMRES preconditioned by an exact O(N) solve of the
      structured Newton matrix (``system.preconditioner``), so it converges
      in one or two iterations;
    * ``"band"``: SUNDIALS' band LU of the full system (the half-bandwidths
      come from ``system.bandwidths()``);
    * ``"lapackband"``, ``"sparse"`` (SuperLU_MT on ``system.pattern()``),
      ``"dense"`` (small systems only);
    * ``"auto"``: "gmres" from ``GMRES_MIN_ELEMENTS`` elements on or when the
      system has a global coupling (feedback tensions), if the preconditioner
      can solve its structure; else "band" (see ``docs/performance.md``).

    ``jacobian`` chooses how the direct solvers get J:

    * ``"sundials"``: SUNDIALS' own finite differences for the band and dense
      solvers, scikit-sundae's coloured differences for ``"sparse"``;
    * ``"compiled"``: ``system.jacobian``, finite differences inside numba
      with the colouring derived from the system's dependencies, handed over
      as ``jacfn``;
    * ``"auto"``: "compiled" for "sparse" and "gmres", "sundials" otherwise
      (measured fastest with the band solvers, whose ``jacfn`` template is a
      dense (n, n) array; see ``docs/performance.md``).

    ``max_order`` caps the BDF order (1-5); ``"auto"`` is 5, or 2 when every
    mode of the grid oscillates (``system.lightly_damped``): BDF 3-5 are not
    stable near the imaginary axis, and there they either take many short
    steps or let the energy grow, while BDF2 is A-stable (see
    ``docs/model.md``). ``max_nonlin_iters`` caps the Newton iterations
    per step (SUNDIALS' default 3: order 4 and 5 Newton iterations save ~10%
    on the paper's tests but double the steps of an inviscid oscillation).

    Every internal step is checked by :class:`rodmol.solve.watch.Watch`
    (blow-ups, degenerate elements, stalls, the wall-time budget
    ``max_wall_time`` [s]), which also reports ``progress`` between outputs.
    """
    from sksundae.cvode import CVODE

    options, linsolver, precond = solver_options(system, rtol, atol, linsolver, max_step, jacobian,
                                                 max_order, max_nonlin_iters)

    watch = Watch(system, t_out, max_wall_time, progress)
    out = Outputs(t_out, y0, progress, system.layout, "CVODE", watch)
    evals = [0]  # counted here: CVODE's own counter leaves out the Jacobian's evaluations

    failed_at = []  # times [s] of right-hand sides that raised

    def rhs(t, y, yp):
        evals[0] += 1
        try:
            system(t, y, yp)
        except Exception:
            # Only the inputs raise (a function of the user's): shorter steps would
            # not help, so the exception stops CVODE at once (scikit-sundae hands
            # it on); the frames of a step that reached past the failure are
            # integrated again by keep_before_failure.
            failed_at.append(t)
            raise

    def stats():
        info = dict(steps=len(sizes), rhs_evals=evals[0], linear_solver=linsolver,
                    **step_size_stats(sizes))
        if precond is not None:
            info.update(jac_evals=precond.jac_evals, prec_setups=precond.setups,
                        prec_solves=precond.solves)
        else:
            info["jac_evals"] = int(r.njev) if r is not None else 0
        return info

    def stop(reason, error=None):
        return out.stopped(reason, error, **stats())

    t_end = float(t_out[-1])
    sizes, r, t_last = [], None, float(t_out[0])  # sizes of the steps taken [s]

    def steps():
        nonlocal r, t_last
        with warnings.catch_warnings():
            # scikit-sundae warns that its own coloured differences are not used
            # when both `sparsity` and `jacfn` are given: that is the point.
            warnings.filterwarnings("ignore", "Custom sparse Jacobian", UserWarning)
            solver = CVODE(rhs, **options)
        with _small_pages():  # the solver's memory is allocated here
            solver.init_step(float(t_out[0]), np.asarray(y0, dtype=float))
        # Steps stop at the inputs' knots: a rod at rest takes long steps and
        # would stride over a short ramp that starts between two of them.
        kinks = [t for t in knot_times(system.model) if t_out[0] < t < t_end][::-1]
        while not out.done:
            while kinks and kinks[-1] <= t_last:
                kinks.pop()
            r = solver.step(t_end, method="onestep", tstop=kinks[-1] if kinks else t_end)
            if not r.success:
                return stop(r.message)
            # After output times were interpolated inside the last step, CVODE's
            # next one-step call hands that step back again: count real steps only.
            if r.t > t_last:
                sizes.append(r.t - t_last)
                t_last = r.t
                broken = watch.state(r.t, sizes[-1], r.y)
                if broken:  # the frames inside this step are not kept either
                    return stop(broken)
            while not out.done and out.t_out[out.next_index] <= r.t:
                t_k = out.t_out[out.next_index]
                out.add(r.y if t_k == r.t else solver.step(t_k).y)
            slow = watch.pace(r.t, r.y)
            if slow and not out.done:
                return stop(slow)
    return run_steps(steps, stop, out, stats, now=lambda: failed_at[-1] if failed_at else t_last)


def solver_options(system, rtol, atol, linsolver="auto", max_step=0.0, jacobian="auto", max_order="auto",
                   max_nonlin_iters=3):
    """scikit-sundae's ``CVODE`` options for ``system`` (see :func:`cvode` for the
    arguments): returns (options, the linear solver chosen, the block preconditioner
    or None). Shared with the stepping integrator (:mod:`rodmol.solve.stepping`)."""
    from sksundae.cvode import CVODEPrecond

    if linsolver == "auto":
        # GMRES's Jacobian-vector products are differences of the full right-hand
        # side, so they carry the global coupling of feedback tensions that any
        # banded Jacobian leaves out (20x fewer steps on a P controller, N = 12).
        big = system.layout.n_blocks >= GMRES_MIN_ELEMENTS
        linsolver = "gmres" if (big or system.global_coupling) and _block_solvable(system) else "band"
    if linsolver not in LINEAR_SOLVERS:
        raise ParameterError(f"unknown `linsolver` {linsolver!r}; valid: {['auto', *LINEAR_SOLVERS]}")
    if jacobian == "auto":
        jacobian = "compiled" if linsolver in ("sparse", "gmres") else "sundials"
    if jacobian not in JACOBIANS:
        raise ParameterError(f"unknown `jacobian` {jacobian!r}; valid: {['auto', *JACOBIANS]}")
    if linsolver == "gmres" and jacobian != "compiled":
        raise ParameterError("linsolver='gmres' is preconditioned with the compiled Jacobian; "
                             "use jacobian='auto' or 'compiled'")
    if max_order == "auto":
        max_order = 2 if system.lightly_damped else 5
    options = dict(method="BDF", rtol=rtol, atol=atol, linsolver=linsolver,
                   max_num_steps=1_000_000, max_step=max_step, max_order=int(max_order),
                   max_nonlin_iters=int(max_nonlin_iters))
    scale = np.broadcast_to(atol, (system.size,)) / rtol
    precond = None
    if linsolver == "gmres":
        precond = system.preconditioner(scale)
        # Left preconditioning, SUNDIALS' default Krylov dimension (5): the
        # fastest of {left, right} x {1, 5} on the bending test.
        options["precond"] = CVODEPrecond(precond.setup, precond.solve, "left")
        options["krylov_dim"] = 5
    elif linsolver in ("band", "lapackband"):
        options["lband"], options["uband"] = system.bandwidths()
    if jacobian == "compiled" and linsolver != "gmres":
        matrix = "band" if linsolver in ("band", "lapackband") else linsolver
        jac = system.jacobian(scale, matrix)
        options["jacfn"] = jac
        if matrix == "sparse":
            options["sparsity"] = jac.sparsity
    elif linsolver == "sparse":
        options["sparsity"] = sparse.csc_matrix(system.pattern())

    return options, linsolver, precond


@contextlib.contextmanager
def _small_pages():
    """Allocate without numpy's transparent-huge-page advice.

    With a ``jacfn``, scikit-sundae allocates a dense (n, n) template for the
    band solver, of which only the band is ever touched; numpy advises 2 MB
    pages for large arrays, so writing the band made the kernel clear every
    2 MB page of it (the whole n^2 array, 460 MB at N = 400, 0.2 s per
    solver start). With 4 kB pages only the band's own pages are cleared.
    """
    core = getattr(np, "_core", None) or getattr(np, "core", None)
    setter = getattr(getattr(core, "multiarray", None), "_set_madvise_hugepage", None)
    if setter is None:  # not a numpy that advises huge pages: nothing to undo
        yield
        return
    previous = setter(False)
    try:
        yield
    finally:
        setter(previous)




def _block_solvable(system):
    """True if the block preconditioner solves this system's structure exactly."""
    try:
        check_structure(system.depends)
    except ValueError:
        return False
    return True
