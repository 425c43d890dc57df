"""Time-integration backends, chosen by name from one table.

Each backend integrates ``dy/dt = system(t, y)`` from ``t_out[0]`` and returns
a :class:`RawSolution` holding the states at the output times reached, so a
failed or interrupted run keeps what it computed.
"""

import contextlib
import time
import warnings
from dataclasses import dataclass, field

import numpy as np
from scipy import sparse
from scipy.integrate import RK23

from ..errors import ParameterError
from ..discretise.jacobian import BlockPreconditioner, CompiledJacobian

DEFAULT_RTOL = 1e-6
LINEAR_SOLVERS = ("gmres", "band", "lapackband", "sparse", "dense")
#: How the direct linear solvers get the Jacobian (see :func:`cvode`).
JACOBIANS = ("compiled", "sundials")
#: Failed right-hand-side evaluations after which CVODE gives up: it has
#: then crept up to where the inputs fail and can go no further.
MAX_RHS_FAILURES = 50
#: From this many elements on, linsolver="auto" picks the preconditioned GMRES.
GMRES_MIN_ELEMENTS = 50


@dataclass
class RawSolution:
    t: np.ndarray
    y: np.ndarray
    success: bool
    message: str
    stats: dict = field(default_factory=dict)


class _Outputs:
    """Collects states at the output times (in one preallocated array) and reports progress."""

    def __init__(self, t_out, y0, progress):
        self.t_out, self.progress = t_out, progress
        self.start = time.perf_counter()
        self.ys = np.empty((len(t_out), len(y0)))
        self.ys[0] = y0
        self.next_index = 1

    @property
    def done(self):
        return self.next_index == len(self.t_out)

    def add(self, y):
        k = self.next_index
        self.ys[k] = y
        self.next_index = k + 1
        if self.progress is not None:
            self.progress(self.t_out[k], self.t_out[-1])

    def solution(self, success, message, **stats):
        stats["wall_time_s"] = time.perf_counter() - self.start
        n = self.next_index
        return RawSolution(self.t_out[:n].copy(), self.ys[:n], success, message, stats)


def cvode(system, y0, t_out, *, rtol, atol, progress=None, linsolver="auto", max_step=0.0,
          jacobian="auto", max_order=5, max_nonlin_iters=3):
    """SUNDIALS CVODE (BDF) through scikit-sundae.

    ``linsolver`` is how the Newton systems (I - gamma J) x = r are solved:

    * ``"gmres"``: GMRES preconditioned by an exact O(N) solve of the
      structured Newton matrix (:class:`rodmol.jacobian.BlockPreconditioner`),
      so it converges in one or two iterations; needs the numba kernel;
    * ``"band"``: SUNDIALS' band LU of the full system (half-bandwidths 21);
    * ``"lapackband"``, ``"sparse"`` (SuperLU_MT on the structural pattern),
      ``"dense"`` (small systems only);
    * ``"auto"``: "gmres" with the numba kernel from ``GMRES_MIN_ELEMENTS``
      elements on or when a cable tension is a feedback law, else "band" (on the bending test they break even around
      N = 50; "gmres" is 1.3x faster at N = 100 and 1.6x at N = 400, "band"
      1.15x faster at N = 25, where GMRES's fixed cost per iteration weighs
      more; see ``docs/performance.md``).

    ``jacobian`` chooses how the direct solvers get J:

    * ``"sundials"``: SUNDIALS' own finite differences for the band and dense
      solvers (one Python call of the right-hand side per column group, 43
      for the band), scikit-sundae's coloured differences for ``"sparse"``;
    * ``"compiled"``: :class:`rodmol.jacobian.CompiledJacobian`, finite
      differences inside numba with a colouring of the true structure (34
      kernel evaluations whatever N, no Python calls), handed over as
      ``jacfn`` (needs the numba kernel);
    * ``"auto"``: "compiled" for the sparse solver when the kernel is numba
      (scikit-sundae's differences loop in Python), "sundials" otherwise
      (measured fastest with the band solvers, whose ``jacfn`` template is a
      dense (n, n) array; see ``docs/performance.md``).

    "gmres" always uses the compiled Jacobian for its preconditioner.

    ``max_order`` caps the BDF order (1-5) and ``max_nonlin_iters`` the Newton
    iterations per step (SUNDIALS' defaults, 5 and 3: order 4 and 5 Newton
    iterations save ~10% on the paper's tests but double the steps of an
    inviscid oscillation; see ``docs/performance.md``).
    """
    from sksundae.cvode import CVODE, CVODEPrecond

    compiled_kernel = getattr(system, "kernel", None) == "numba"
    if linsolver == "auto":
        # GMRES's Jacobian-vector products are differences of the full right-hand
        # side, so they carry the global coupling of feedback tensions that any
        # banded Jacobian leaves out (20x fewer steps on a P controller, N = 12).
        big = system.model.n_elements >= GMRES_MIN_ELEMENTS
        linsolver = "gmres" if compiled_kernel and (big or system.model.feedback) else "band"
    if linsolver not in LINEAR_SOLVERS:
        raise ParameterError(f"unknown `linsolver` {linsolver!r}; valid: {['auto', *LINEAR_SOLVERS]}")
    if jacobian == "auto":
        jacobian = "compiled" if compiled_kernel and linsolver in ("sparse", "gmres") else "sundials"
    if jacobian not in JACOBIANS:
        raise ParameterError(f"unknown `jacobian` {jacobian!r}; valid: {['auto', *JACOBIANS]}")
    if jacobian == "compiled" and not compiled_kernel:
        raise ParameterError("jacobian='compiled' (and linsolver='gmres') need the numba kernel "
                             "(SemiDiscrete(model, kernel='numba'))")
    if linsolver == "gmres" and jacobian != "compiled":
        raise ParameterError("linsolver='gmres' is preconditioned with the compiled Jacobian; "
                             "use jacobian='auto' or 'compiled'")
    options = dict(method="BDF", rtol=rtol, atol=atol, linsolver=linsolver,
                   max_num_steps=1_000_000, max_step=max_step, max_order=int(max_order),
                   max_nonlin_iters=int(max_nonlin_iters))
    scale = np.broadcast_to(atol, (system.size,)) / rtol
    precond = None
    if linsolver == "gmres":
        precond = BlockPreconditioner(system, scale)
        # Left preconditioning, SUNDIALS' default Krylov dimension (5): the
        # fastest of {left, right} x {1, 5} on the bending test.
        options["precond"] = CVODEPrecond(precond.setup, precond.solve, "left")
        options["krylov_dim"] = 5
    elif linsolver in ("band", "lapackband"):
        options["lband"], options["uband"] = system.layout.bandwidths()
    if jacobian == "compiled" and linsolver != "gmres":
        matrix = "band" if linsolver in ("band", "lapackband") else linsolver
        jac = CompiledJacobian(system, scale, matrix)
        options["jacfn"] = jac
        if matrix == "sparse":
            options["sparsity"] = jac.sparsity
    elif linsolver == "sparse":
        options["sparsity"] = sparse.csc_matrix(system.layout.pattern())

    out = _Outputs(t_out, y0, progress)
    evals = [0]  # counted here: CVODE's own counter leaves out the Jacobian's evaluations

    failures = []  # (t, exception) raised by the right-hand side

    def rhs(t, y, yp):
        evals[0] += 1
        try:
            system(t, y, yp)
        except Exception as exc:
            # scikit-sundae would abort on an exception, throwing away a step that
            # merely reached past the trouble: NaN rates make CVODE reject the
            # trial step and retry shorter ones, so the run gets as close as it can.
            failures.append((t, exc))
            yp[:] = np.nan

    def stats():
        info = dict(steps=len(sizes), rhs_evals=evals[0], linear_solver=linsolver,
                    **_step_size_stats(sizes))
        if precond is not None:
            info.update(jac_evals=precond.jac_evals, prec_setups=precond.setups,
                        prec_solves=precond.solves)
        else:
            info["jac_evals"] = int(r.njev) if r is not None else 0
        return info

    t_end = float(t_out[-1])
    sizes, r, t_last = [], None, float(t_out[0])  # sizes of the steps taken [s]
    try:
        with warnings.catch_warnings():
            # scikit-sundae warns that its own coloured differences are not used
            # when both `sparsity` and `jacfn` are given: that is the point.
            warnings.filterwarnings("ignore", "Custom sparse Jacobian", UserWarning)
            solver = CVODE(rhs, **options)
        with _small_pages():  # the solver's memory is allocated here
            solver.init_step(float(t_out[0]), np.asarray(y0, dtype=float))
        while not out.done:
            r = solver.step(t_end, method="onestep", tstop=t_end)
            if not r.success or len(failures) > MAX_RHS_FAILURES:
                reason = r.message
                if failures:
                    t_bad, exc = failures[-1]
                    reason = f"{type(exc).__name__}: {exc} (at t = {t_bad:.6g} s)"
                reached = out.t_out[out.next_index - 1]
                return out.solution(False, f"CVODE failed after t = {reached:.6g} s (last output; "
                                    f"the solver got to {r.t:.6g} s): {reason}", **stats())
            # After output times were interpolated inside the last step, CVODE's
            # next one-step call hands that step back again: count real steps only.
            if r.t > t_last:
                sizes.append(r.t - t_last)
                t_last = r.t
            while not out.done and out.t_out[out.next_index] <= r.t:
                t_k = out.t_out[out.next_index]
                out.add(r.y if t_k == r.t else solver.step(t_k).y)
    except (Exception, KeyboardInterrupt) as exc:
        reached = out.t_out[out.next_index - 1]
        reason = "interrupted" if isinstance(exc, KeyboardInterrupt) else f"{type(exc).__name__}: {exc}"
        return out.solution(False, f"CVODE stopped after t = {reached:.6g} s: {reason}", **stats())
    return out.solution(True, "The solver reached the end time.", **stats())


def _step_size_stats(sizes):
    """Smallest, median and largest step [s] (0 if none), for the run's stats."""
    if not sizes:
        return dict(h_min=0.0, h_median=0.0, h_max=0.0)
    h = np.asarray(sizes)
    return dict(h_min=float(h.min()), h_median=float(np.median(h)), h_max=float(h.max()))


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


def rk23(system, y0, t_out, *, rtol, atol, progress=None, max_step=np.inf):
    """scipy's explicit Bogacki-Shampine RK23 on the same right-hand side (cross-check).

    Its step is bounded by the explicit stability limits, so it is slow on
    fine grids.
    """
    evals = [0]

    def rhs(t, y):
        evals[0] += 1
        return system(t, y)

    out = _Outputs(t_out, y0, progress)
    sizes = []

    def stats():
        return dict(steps=len(sizes), rhs_evals=evals[0], jac_evals=0, **_step_size_stats(sizes))

    try:
        solver = RK23(rhs, float(t_out[0]), np.array(y0, dtype=float), float(t_out[-1]),
                      rtol=rtol, atol=atol, max_step=max_step or np.inf)
        while not out.done:
            message = solver.step()
            if solver.status == "failed":
                return out.solution(False, f"RK23 failed at t = {solver.t:.6g} s: {message}",
                                    **stats())
            sizes.append(solver.t - solver.t_old)
            if out.t_out[out.next_index] <= solver.t:  # the interpolant only when needed
                dense = solver.dense_output()
                while not out.done and out.t_out[out.next_index] <= solver.t:
                    out.add(dense(out.t_out[out.next_index]))
    except (Exception, KeyboardInterrupt) as exc:
        reached = out.t_out[out.next_index - 1]
        reason = "interrupted" if isinstance(exc, KeyboardInterrupt) else f"{type(exc).__name__}: {exc}"
        return out.solution(False, f"RK23 stopped after t = {reached:.6g} s: {reason}", **stats())
    return out.solution(True, "The solver reached the end time.", **stats())


#: Backends by name.
BACKENDS = {"cvode": cvode, "rk23": rk23}


def get_backend(name):
    try:
        return BACKENDS[name]
    except (KeyError, TypeError):
        raise ParameterError(f"unknown `backend` {name!r}; valid backends are {sorted(BACKENDS)}") from None
