"""CVODE's own counters of a scikit-sundae solver, for the solver studies.

scikit-sundae (1.2.0) reports only the right-hand side and Jacobian counts;
CVODE keeps the rest (steps, error-test failures, nonlinear and linear
iterations, convergence failures, preconditioner setups and solves). They are
read here through ``ctypes`` from the SUNDIALS library scikit-sundae ships,
with the CVODE memory pointer taken from the Cython object (its first field
after the object header and the method table). The pointer's place is
checked on every read: CVODE's right-hand side counts through it (its own
and its linear solver's differences) must add up to the run's count of
calls, else :func:`counters` raises.

Not a part of rodmol: a study's instrument.
"""

import ctypes
import glob
import os

import sksundae
import sksundae.cvode

_LIBS = os.path.join(os.path.dirname(os.path.dirname(sksundae.__file__)), "scikit_sundae.libs")
_MEM_OFFSET = 3 * ctypes.sizeof(ctypes.c_void_p)  # refcount, type, vtable, then ``mem``

#: (CVODE getter, names of its long outputs).
GETTERS = (("CVodeGetNumSteps", ("steps",)),
           ("CVodeGetNumRhsEvals", ("cvode_rhs",)),
           ("CVodeGetNumErrTestFails", ("error_test_fails",)),
           ("CVodeGetNumLinSolvSetups", ("linear_setups",)),
           ("CVodeGetNonlinSolvStats", ("newton_iters", "newton_conv_fails")),
           ("CVodeGetNumLinIters", ("krylov_iters",)),
           ("CVodeGetNumLinConvFails", ("krylov_conv_fails",)),
           ("CVodeGetNumPrecEvals", ("prec_jacobians",)),
           ("CVodeGetNumPrecSolves", ("prec_solves",)),
           ("CVodeGetNumLinRhsEvals", ("linear_solver_rhs",)))

_lib = None


def _cvode():
    global _lib
    if _lib is None:
        _lib = ctypes.CDLL(glob.glob(os.path.join(_LIBS, "libsundials_cvode-*.so*"))[0])
    return _lib


class Recorder:
    """Keeps every ``sksundae.cvode.CVODE`` made while it is entered (``with
    Recorder() as made: ...``; ``made.solvers[-1]`` the last)."""

    def __enter__(self):
        self.solvers, self._init = [], sksundae.cvode.CVODE.__init__
        init, solvers = self._init, self.solvers

        def recording(solver, *args, **kwargs):
            init(solver, *args, **kwargs)
            solvers.append(solver)

        sksundae.cvode.CVODE.__init__ = recording
        return self

    def __exit__(self, *exc):
        sksundae.cvode.CVODE.__init__ = self._init


def counters(solver, rhs_evals):
    """CVODE's counters (:data:`GETTERS`, plus the last step ``h_last`` [s] and order
    ``q_last``) of the scikit-sundae ``solver``; ``rhs_evals``: the run's count of
    right-hand side calls (``result.stats``), the check."""
    inner = solver._CVODE__CVODE
    mem = ctypes.c_void_p(ctypes.c_void_p.from_address(id(inner) + _MEM_OFFSET).value)
    lib, out = _cvode(), {}
    for getter, names in GETTERS:
        values = [ctypes.c_long() for _ in names]
        flag = getattr(lib, getter)(mem, *map(ctypes.byref, values))
        if flag != 0:
            raise RuntimeError(f"{getter} returned {flag}")
        out.update({name: v.value for name, v in zip(names, values)})
    if out["cvode_rhs"] + out["linear_solver_rhs"] != rhs_evals:
        raise RuntimeError(f"CVODE's memory not where expected: {out['cvode_rhs']} + "
                           f"{out['linear_solver_rhs']} right-hand sides, the run counted {rhs_evals}")
    h, q = ctypes.c_double(), ctypes.c_int()
    lib.CVodeGetLastStep(mem, ctypes.byref(h))
    lib.CVodeGetLastOrder(mem, ctypes.byref(q))
    return dict(out, h_last=h.value, q_last=q.value)
