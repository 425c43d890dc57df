"""What a compiled driver would buy: CVODE with compiled callbacks on the paper's tests.

A study, not a part of rodmol. scikit-sundae calls every right-hand side,
preconditioner setup and solve through Python; here CVODE (the SUNDIALS
library scikit-sundae ships, through ``ctypes``) calls numba ``cfunc``s
instead: the same compiled right-hand side, Jacobian blocks, block
factorisation and solve as rodmol's GMRES path, the cable's tension knots
interpolated inside the right-hand side. The loop of one-step calls and the
outputs (``CVodeGetDky``) stay in Python, one ``ctypes`` call each. Only the
paper's tests' inputs are handled (cables' tension knots, a fixed base, no
loads that vary), and no step is checked: it measures, it does not replace
``rodmol.simulate``.

The same callbacks also run under rodmol's own driver: :class:`DropIn` offers
scikit-sundae's ``CVODE`` interface (``init_step``, ``step``) to rodmol's
unchanged :class:`~rodmol.solve.stepping.Stepper` (its per-step watch, output
store and stop times), which is how a backend would plug in.

Against rodmol's driver on the same system: the steps and right-hand sides
(the same algorithm, so the same counts), the largest tip difference, the
CPU time of each (medians of --reps, interleaved), and the tip error against
``accuracy_per_cost.py``'s reference.

    python solvers/compiled_driver.py [--quick | --smoke] [--out DIR] [--reps K]
"""

import ctypes
import glob
import os
import textwrap
import time

import _common as C
import numba
from _common import np, rodmol
from accuracy_per_cost import PRIVATE_REFERENCE_S, cached_reference
from numba import types
from numba.extending import intrinsic

from rodmol.discretise.jacobian import jacobian_blocks
from rodmol.discretise.preconditioner import block_setup, block_solve
from rodmol.discretise.stencil import rhs as stencil_rhs

SCRIPT = "compiled_driver.py"
CV_BDF, CV_ONE_STEP, SUN_PREC_LEFT = 2, 2, 1


@intrinsic
def _voidptr(typingctx, address):
    """An integer address as a void pointer (for ``numba.carray``)."""
    def codegen(context, builder, signature, args):
        return builder.inttoptr(args[0], context.get_value_type(types.voidptr))
    return types.voidptr(types.intp), codegen


@numba.njit
def _data_address(address):
    """Where :func:`_data` finds the data of the serial N_Vector at ``address`` (checked against
    SUNDIALS' own getter)."""
    content = numba.carray(_voidptr(address), 1, np.intp)[0]
    return numba.carray(_voidptr(content), 2, np.intp)[1]


@numba.njit
def _data(vector, n):
    """The data of a serial N_Vector: its content's third field (sunindextype is a 32-bit int
    in scikit-sundae's SUNDIALS: length and own_data take 8 bytes, the data pointer follows)."""
    content = numba.carray(vector, 1, np.intp)[0]
    data = numba.carray(_voidptr(content), 2, np.intp)[1]
    return numba.carray(_voidptr(data), n, np.float64)


def _libraries():
    import sksundae

    folder = os.path.join(os.path.dirname(os.path.dirname(sksundae.__file__)), "scikit_sundae.libs")

    def load(name):
        return ctypes.CDLL(glob.glob(os.path.join(folder, f"libsundials_{name}-*.so*"))[0], mode=ctypes.RTLD_GLOBAL)

    libs = {name: load(name) for name in ("core", "nvecserial", "sunlinsolspgmr", "cvode")}
    vp = ctypes.c_void_p
    for lib, fn, res in ((libs["nvecserial"], "N_VNew_Serial", vp), (libs["nvecserial"], "N_VGetArrayPointer", vp),
                         (libs["cvode"], "CVodeCreate", vp), (libs["sunlinsolspgmr"], "SUNLinSol_SPGMR", vp)):
        getattr(lib, fn).restype = res
    libs["nvecserial"].N_VGetArrayPointer.argtypes = [vp]
    return libs


def _array(name, value):
    """Source of ``value`` (an array) rebuilt inside a cfunc from its address."""
    return (f"numba.carray(_voidptr({value.ctypes.data}), {tuple(value.shape)!r}, np.{value.dtype.name})"
            if value.size else f"np.empty({tuple(value.shape)!r}, np.{value.dtype.name})")


def callbacks(system, precond):
    """(rhs, psetup, psolve) cfuncs of ``system`` and its block preconditioner, reading and
    writing their arrays in place (kept alive by the caller)."""
    timed = [(j, cable.tension.signal) for j, cable in system._timed]
    if system.inputs_vary and (not timed or not system._fixed_base or system.grid_loads.values or system._friction
                               or system.global_coupling
                               or not all(isinstance(k, rodmol.inputs.Knots) and k.width == 1 for _, k in timed)):
        raise ValueError("the study handles cables' tension knots and held inputs only")
    jac = precond.jacobian
    args = system.kernel_arguments()
    names = {f"A{i}": a for i, a in enumerate(args)}
    names.update(SCALE=jac._scale, GROUPS=jac._groups, HEADER=jac._header, YBUF=jac._ybuf, FBUF=jac._fbuf,
                 JB=jac._jb, JH=jac._jh, HEAD=precond._head, FAC=precond._fac, SX=precond._scratch[0],
                 SP=precond._scratch[1], SH=precond._scratch[2], GAMMA=np.zeros(1))
    for i, (_, knots) in enumerate(timed):
        names[f"KT{i}"], names[f"KV{i}"] = np.array(knots._t), np.array(knots._v)
    inputs = "\n".join(f"    A4[{j}] = tension(t, KT{i}, KV{i})" for i, (j, _) in enumerate(timed))
    n = system.size
    load = "\n".join(f"    {k} = {_array(k, v)}" for k, v in names.items())
    tup = "(" + ", ".join(f"A{i}" for i in range(len(args))) + ",)"
    source = f'''
@numba.njit
def arrays():
{load}
    return {", ".join(names)}

@numba.njit
def tension(t, KT, KV):
    k = np.searchsorted(KT, t, side="right")
    if k == 0:
        return KV[0]
    if k == KT.shape[0]:
        return KV[-1]
    return KV[k - 1] + (KV[k] - KV[k - 1]) * ((t - KT[k - 1]) / (KT[k] - KT[k - 1]))

@numba.cfunc(types.int32(types.float64, types.voidptr, types.voidptr, types.voidptr))
def rhs(t, yv, ydv, user):
    {", ".join(names)} = arrays()
{inputs}
    stencil_rhs(_data(yv, {n}), _data(ydv, {n}), *{tup})
    return 0

@numba.cfunc(types.int32(types.float64, types.voidptr, types.voidptr, types.int32, types.CPointer(types.int32),
                         types.float64, types.voidptr))
def psetup(t, yv, fv, jok, jcur, gamma, user):
    {", ".join(names)} = arrays()
    if jok:
        jcur[0] = 0
    else:
{textwrap.indent(inputs, "    ")}
        jacobian_blocks(_data(yv, {n}), _data(fv, {n}), SCALE, GROUPS, HEADER, {tup}, YBUF, FBUF, JB, JH)
        jcur[0] = 1
    block_setup(JB, JH, gamma, HEAD, FAC)
    GAMMA[0] = gamma
    return 0

@numba.cfunc(types.int32(types.float64, types.voidptr, types.voidptr, types.voidptr, types.voidptr, types.float64,
                         types.float64, types.int32, types.voidptr))
def psolve(t, yv, fv, rv, zv, gamma, delta, lr, user):
    {", ".join(names)} = arrays()
    block_solve(GAMMA[0], HEAD, FAC, _data(rv, {n}), _data(zv, {n}), SX, SP, SH)
    return 0
'''
    scope = dict(numba=numba, np=np, types=types, _voidptr=_voidptr, _data=_data, stencil_rhs=stencil_rhs,
                 jacobian_blocks=jacobian_blocks, block_setup=block_setup, block_solve=block_solve)
    exec(compile(source, "<compiled_driver callbacks>", "exec"), scope)  # noqa: S102 (our own source)
    return scope["rhs"], scope["psetup"], scope["psolve"], names


class CompiledCVODE:
    """CVODE over ``system`` with compiled callbacks, GMRES (Krylov dimension 5) and the block
    preconditioner, as rodmol's default for a rod."""

    def __init__(self, system, rtol, atol, libs, precond=None):
        self.libs, self.system, self.n = libs, system, system.size
        self.precond = precond or system.preconditioner(np.broadcast_to(atol, (system.size,)) / rtol)
        self.rhs, self.psetup, self.psolve, self._kept = callbacks(system, self.precond)
        core, nv, gm, cv = libs["core"], libs["nvecserial"], libs["sunlinsolspgmr"], libs["cvode"]
        self.ctx = ctypes.c_void_p()
        assert core.SUNContext_Create(ctypes.c_int(0), ctypes.byref(self.ctx)) == 0
        self.y = ctypes.c_void_p(nv.N_VNew_Serial(ctypes.c_int(self.n), self.ctx))
        self.atol = ctypes.c_void_p(nv.N_VNew_Serial(ctypes.c_int(self.n), self.ctx))
        self.out = ctypes.c_void_p(nv.N_VNew_Serial(ctypes.c_int(self.n), self.ctx))
        self.yv, self.outv = self._view(self.y), self._view(self.out)
        for vector in (self.y, self.atol, self.out):  # the callbacks' reading of an N_Vector, checked
            if _data_address(vector.value) != nv.N_VGetArrayPointer(vector):
                raise RuntimeError("this SUNDIALS lays out its serial N_Vector otherwise: the study cannot run")
        self._view(self.atol)[:] = np.broadcast_to(atol, (self.n,))
        self.rtol = rtol
        self.mem = ctypes.c_void_p(cv.CVodeCreate(ctypes.c_int(CV_BDF), self.ctx))
        self.ls = ctypes.c_void_p(gm.SUNLinSol_SPGMR(self.y, ctypes.c_int(SUN_PREC_LEFT), ctypes.c_int(5), self.ctx))
        self._initialised = False

    def _view(self, vector):
        pointer = self.libs["nvecserial"].N_VGetArrayPointer(vector)
        return np.ctypeslib.as_array(ctypes.cast(pointer, ctypes.POINTER(ctypes.c_double)), (self.n,))

    def init(self, t0, y0):
        """Start (or restart, keeping the memory) CVODE at state ``y0`` at ``t0`` [s]."""
        cv, d = self.libs["cvode"], ctypes.c_double
        self.yv[:] = y0
        if not self._initialised:
            assert cv.CVodeInit(self.mem, ctypes.c_void_p(self.rhs.address), d(t0), self.y) == 0
            assert cv.CVodeSVtolerances(self.mem, d(self.rtol), self.atol) == 0
            assert cv.CVodeSetLinearSolver(self.mem, self.ls, None) == 0
            assert cv.CVodeSetPreconditioner(self.mem, ctypes.c_void_p(self.psetup.address),
                                             ctypes.c_void_p(self.psolve.address)) == 0
            assert cv.CVodeSetMaxNumSteps(self.mem, ctypes.c_long(1_000_000)) == 0
            self._initialised = True
        else:
            assert cv.CVodeReInit(self.mem, d(t0), self.y) == 0

    def run(self, y0, t_out):
        """(states at t_out, steps, CPU time [s] from the first step on)."""
        cv, d = self.libs["cvode"], ctypes.c_double
        self.yv[:] = y0
        if not self._initialised:
            assert cv.CVodeInit(self.mem, ctypes.c_void_p(self.rhs.address), d(t_out[0]), self.y) == 0
            assert cv.CVodeSVtolerances(self.mem, d(self.rtol), self.atol) == 0
            assert cv.CVodeSetLinearSolver(self.mem, self.ls, None) == 0
            assert cv.CVodeSetPreconditioner(self.mem, ctypes.c_void_p(self.psetup.address),
                                             ctypes.c_void_p(self.psolve.address)) == 0
            assert cv.CVodeSetMaxNumSteps(self.mem, ctypes.c_long(1_000_000)) == 0
            self._initialised = True
        else:
            assert cv.CVodeReInit(self.mem, d(t_out[0]), self.y) == 0
        knots = sorted(float(k) for k in self.system.knot_times())
        times, t_end = [float(t) for t in t_out], float(t_out[-1])
        ys = np.empty((len(times), self.n))
        ys[0] = y0
        tret, k, reached, steps = d(), 1, times[0], 0
        start = time.process_time()
        while k < len(times):
            stop = next((x for x in knots if x > reached), t_end)
            cv.CVodeSetStopTime(self.mem, d(min(stop, t_end)))
            flag = cv.CVode(self.mem, d(times[k]), self.y, ctypes.byref(tret), ctypes.c_int(CV_ONE_STEP))
            if flag < 0:
                raise RuntimeError(f"CVode returned {flag} at t = {tret.value}")
            if tret.value > reached:
                steps += 1
                reached = tret.value
            while k < len(times) and times[k] <= reached:
                if times[k] == reached:
                    ys[k] = self.yv
                else:
                    cv.CVodeGetDky(self.mem, d(times[k]), ctypes.c_int(0), self.out)
                    ys[k] = self.outv
                k += 1
        cpu = time.process_time() - start
        nfe = ctypes.c_long()
        cv.CVodeGetNumRhsEvals(self.mem, ctypes.byref(nfe))
        nfl = ctypes.c_long()
        cv.CVodeGetNumLinRhsEvals(self.mem, ctypes.byref(nfl))
        return ys, steps, nfe.value + nfl.value, cpu


class _Result:
    __slots__ = ("t", "y", "success", "message", "status", "nfev", "njev")


class DropIn:
    """scikit-sundae's ``CVODE`` as rodmol's :class:`~rodmol.solve.stepping.Stepper` uses it
    (``init_step``, ``step``) over a :class:`CompiledCVODE`: the Stepper, its watch, the
    outputs and the stop times run unchanged. Its right-hand sides and preconditioner calls
    bypass the Stepper's and the preconditioner's counters."""

    def __init__(self, compiled):
        self.c, self._tret = compiled, ctypes.c_double()
        self._cv = compiled.libs["cvode"]

    def init_step(self, t0, y0):
        self.c.init(float(t0), np.asarray(y0, dtype=float))

    def step(self, t, method="normal", tstop=None):
        cv, mem = self._cv, self.c.mem
        if tstop is not None:
            cv.CVodeSetStopTime(mem, ctypes.c_double(tstop))
        flag = cv.CVode(mem, ctypes.c_double(t), self.c.y, ctypes.byref(self._tret),
                        ctypes.c_int(CV_ONE_STEP if method == "onestep" else 1))
        if tstop is not None:
            cv.CVodeClearStopTime(mem)
        r = _Result()
        r.t, r.y, r.success, r.status = self._tret.value, self.c.yv.copy(), flag >= 0, flag
        r.message, r.nfev, r.njev = f"CVode returned {flag}", 0, 0
        return r


class Patched:
    """Within ``with``: rodmol's Steppers build a :class:`DropIn` instead of scikit-sundae's
    CVODE, one :class:`CompiledCVODE` per system (compiled once, restarted for each run)."""

    def __init__(self, libs):
        self.libs, self.made = libs, {}

    def __enter__(self):
        import sksundae.cvode

        self._cvode, self.module = sksundae.cvode.CVODE, sksundae.cvode

        def make(rates, **options):
            system = rates.__self__.system
            key = id(system)
            if key not in self.made:
                self.made[key] = (system, CompiledCVODE(system, options["rtol"], options["atol"], self.libs))
            return DropIn(self.made[key][1])

        sksundae.cvode.CVODE = make
        return self

    def __exit__(self, *exc):
        self.module.CVODE = self._cvode


def main(argv=None):
    args = C.parse_args(__doc__.splitlines()[0], argv)
    if args.reps == 3 and args.mode != "smoke":
        args.reps = 9
    header = C.header_lines(args, SCRIPT)
    configs = C.pick(args, [("bending", 100, None), ("bending", 100, 1e-4), ("bending", 30, None),
                            ("bending", 30, 3e-4), ("reaching", 100, None), ("fetching", 100, None)],
                     [("bending", 100, None)], [("bending", 8, None), ("reaching", 8, None)])
    t_bending = C.pick(args, 6.0, 6.0, 0.2)
    libs = _libraries()
    bending = rodmol.scenarios.get("bending")
    reference, _ = cached_reference(bending, C.pick(args, (400, 800), (400, 800), (24, 48)), C.outputs(t_bending))
    rows = []
    for test, n, rtol in configs:
        scenario = rodmol.scenarios.get(test)
        model = scenario.model(n)
        t_end = C.pick(args, scenario.t_end, scenario.t_end, 0.2)
        system = C.SemiDiscrete(model)
        y0 = C.initial_state(model, system=system)
        rtol = rtol or rodmol.SCHEMES[system.scheme.name].default_rtol
        atol = C.default_atol(model, rtol)
        t_out = C.outputs(t_end)
        C.warm_up(system, y0, linsolver="gmres")
        t0 = time.perf_counter()
        driver = CompiledCVODE(system, rtol, atol, libs)
        driver.run(y0, t_out[:3])
        compile_s = time.perf_counter() - t0
        patched = Patched(libs)
        with patched:  # compile the drop-in's callbacks outside the timing
            C.run(C.cvode, system, y0, t_out[:3], rtol, linsolver="gmres")
        ours, theirs, default, dropin = [], [], [], []
        for _ in range(args.reps):
            with patched:
                inner, cpu = C.run_cpu(C.cvode, system, y0, t_out, rtol, linsolver="gmres")
            dropin.append(cpu)
            auto, cpu = C.run_cpu(C.cvode, system, y0, t_out, rtol)
            default.append(cpu)
            raw, cpu = C.run_cpu(C.cvode, system, y0, t_out, rtol, linsolver="gmres")
            theirs.append(cpu)
            ys, steps, rhs_evals, cpu = driver.run(y0, t_out)
            ours.append(cpu)
        tip_theirs = C.tip(raw, model)
        raw.y[:] = ys  # the same frames through the same tip reconstruction
        system.project_quaternions(raw.y[1:])
        gap = float(np.max(np.linalg.norm(C.tip(raw, model) - tip_theirs, axis=1)))
        inner_gap = float(np.max(np.linalg.norm(C.tip(inner, model) - tip_theirs, axis=1)))
        row = dict(test=test, N=n, rtol=rtol, rodmol_default_solver=auto.stats["linear_solver"],
                   rodmol_default_cpu_ms=1e3 * float(np.median(default)),
                   rodmol_cpu_ms=1e3 * float(np.median(theirs)), compiled_cpu_ms=1e3 * float(np.median(ours)),
                   rodmol_driver_compiled_cpu_ms=1e3 * float(np.median(dropin)),
                   rodmol_driver_compiled_steps=inner.stats["steps"], rodmol_driver_compiled_tip_gap_m=inner_gap,
                   ratio=float(np.median(np.array(ours) / np.array(theirs))), rodmol_steps=raw.stats["steps"],
                   compiled_steps=steps, rodmol_rhs=raw.stats["rhs_evals"], compiled_rhs=rhs_evals,
                   tip_gap_m=gap, tip_err_mm=1e3 * float(np.max(np.linalg.norm(tip_theirs - reference, axis=1)))
                   if test == "bending" else float("nan"),
                   realtime_compiled=t_end / float(np.median(ours)),
                   compiled_of_private_reference=float(np.median(ours)) / PRIVATE_REFERENCE_S, compile_s=compile_s)
        rows.append(row)
        print(row, flush=True)
    base = os.path.join(args.out, "compiled_driver")
    note = ("the paper's tests over their whole spans (smoke: 0.2 s), the default scheme, GMRES with the block preconditioner (rodmol_cpu_ms, "
            "and rodmol's default linear solver: rodmol_default_cpu_ms); tip_err_mm: the bending test's against "
            "accuracy_per_cost.py's reference; CPU time "
            f"from the first step on, medians of {args.reps} interleaved runs; ratio: median of compiled/rodmol "
            "per pair; compile_s: building the cfuncs (not cached) and a first short run")
    C.write_csv(base + ".csv", rows, header + [note])
    fmt = {"rtol": ".0e", "rodmol_default_cpu_ms": ".1f", "rodmol_driver_compiled_cpu_ms": ".1f",
           "rodmol_driver_compiled_tip_gap_m": ".1e", "rodmol_cpu_ms": ".1f", "compiled_cpu_ms": ".1f", "ratio": ".3f", "tip_gap_m": ".1e",
           "realtime_compiled": ".0f", "compile_s": ".1f", "tip_err_mm": ".3g", "compiled_of_private_reference": ".2f"}
    C.write_markdown(base + ".md", "A compiled driver against rodmol's, bending test", header,
                     [("Results", note + "\n\n" + C.markdown_table(rows, None, fmt))])
    print("wrote", base + ".{csv,md}")


if __name__ == "__main__":
    main()
