"""How rodmol's kernels are compiled: numba's njit with the project's options, one
compilation per argument type, explicit signatures compiled at a run's announced stage
(the right-hand side in this process, the others in a helper process on a second core:
:mod:`rodmol.discretise.compile_ahead`).
"""

import numba
from numba.core.registry import CPUDispatcher

from . import compile_ahead, kernel_cache

kernel_cache.install()  # before any kernel is compiled or loaded
#: (dispatcher, signature, ahead) of the kernels with an explicit signature not yet compiled.
_UNCOMPILED = []


def jit(fn=None, *, signature=None, ahead=False, by_value=False):
    """numba.njit with the project's options.

    cache=True: the machine code is stored next to this package (or in
    numba's user cache if that is read-only), so only the first process pays
    the compilation. error_model="numpy" drops Python's zero-division checks
    from the inner loops. An explicit ``signature`` is compiled by
    :func:`compile_signatures` (not at import, so that ``import rodmol``
    stays quick and a run can announce the wait), or by its first call if that
    comes earlier; ``ahead``: in the helper process while this one compiles the
    others. A kernel called from another with a constant argument is compiled
    for its type, not its value (:func:`_one_per_type`), unless ``by_value``: the
    preconditioner's small inverses, whose loops run faster unrolled for each block size.
    """
    if fn is None:
        return lambda f: jit(f, signature=signature, ahead=ahead, by_value=by_value)
    dispatcher = numba.njit(cache=True, error_model="numpy")(fn)
    if not isinstance(dispatcher, CPUDispatcher):  # numba's jit turned off (NUMBA_DISABLE_JIT): Python
        return dispatcher
    if not by_value:
        dispatcher = _one_per_type(dispatcher, signature, ahead)
    if signature is None:
        _twin(dispatcher, fn, by_value)
    if signature is not None:
        _UNCOMPILED.append((dispatcher, signature, ahead))
        # A call before compile_signatures compiles the signature too, not the call's types.
        dispatcher._compile_for_args = lambda *args, **kws: _compile(dispatcher, signature, ahead)
    return dispatcher


def _one_per_type(dispatcher, signature, ahead):
    """Type the calls of ``dispatcher`` from compiled code by their arguments' types only
    (by its explicit ``signature`` if it has one).

    numba types a constant argument (``_vec(row, 12)``, a block size) as its literal value
    and compiles the callee once per value: a fresh cache compiled the stencil's helpers
    sixteen times more than needed. The callee's machine code is inlined into its caller,
    where LLVM folds the constant just the same, so one compilation per type loses nothing.
    """
    by_literal = dispatcher.get_call_template

    def get_call_template(args, kws):
        if signature is not None and dispatcher._can_compile:
            _compile(dispatcher, signature, ahead)
        return by_literal([numba.types.unliteral(a) for a in args],
                          {k: numba.types.unliteral(v) for k, v in kws.items()})

    dispatcher.get_call_template = get_call_template
    return dispatcher


class _Twinned(CPUDispatcher):
    """A kernel that compiled code calls through its twin (:func:`_twin`)."""

    @property
    def _numba_type_(self):
        return numba.types.Dispatcher(getattr(self, "_nested", self))


def _twin(dispatcher, fn, by_value):
    """Let compiled callers of ``dispatcher`` call a twin compiled without a Python wrapper.

    numba compiles every function a kernel calls as a function of its own, with a wrapper
    for calls from Python and the machine code for it, and caches it: for the stencil's ~30
    helpers that was most of the right-hand side's compilation, for code inlined into its
    callers. The twin skips the wrapper and the cache (its code lives in its callers'
    cached machine code); Python calls still go to ``dispatcher`` itself.
    """
    nested = numba.njit(error_model="numpy", no_cpython_wrapper=True)(fn)
    if not by_value:
        _one_per_type(nested, None, False)
    dispatcher._nested = nested
    dispatcher.__class__ = _Twinned


def strided(ndim, writes=False):
    """numba's type of a float64 array of ``ndim`` dimensions in any layout, read only unless
    it ``writes``: for a kernel's explicit signature when it takes strided views of the
    states, so that one compilation takes contiguous arrays too (numba alone compiles a
    second one for them)."""
    return numba.types.float64[(slice(None),) * ndim].copy(readonly=not writes)


def compile_signatures():
    """Compile (or load from the disk cache) the kernels with explicit signatures, and allow
    no other: every later call converts to them. Those marked ``ahead`` that the cache lacks
    are compiled meanwhile by a helper process, where the machine has a second core
    (:mod:`rodmol.discretise.compile_ahead`); each is loaded from the cache it wrote at its
    first call, which waits for the helper if it is still at work: the run goes on in the
    meantime (the Jacobian's kernel, the initial state)."""
    compile_ahead.start([d for d, _, ahead in _UNCOMPILED if ahead])
    try:
        _compile_entries(lambda ahead: not ahead)
    except BaseException:  # interrupted or failed: stop the helper, do not wait for it
        compile_ahead.finish(timeout=0.0)
        raise
    if not compile_ahead.running():
        _compile_entries(lambda ahead: True)


def helper_wanted():
    """True if :func:`compile_signatures` will start the helper process (for the progress line)."""
    return compile_ahead.wanted([d for d, _, ahead in _UNCOMPILED if ahead])


def compile_ahead_here():
    """Compile (or load) the kernels marked ``ahead``: the helper process's work."""
    _compile_entries(lambda ahead: ahead)


def _compile_entries(chosen):
    for entry in [e for e in _UNCOMPILED if chosen(e[2])]:
        _compile(*entry)


def _compile(dispatcher, signature, ahead=False):
    """``dispatcher`` compiled for ``signature`` alone (``ahead``: loaded from the cache the
    helper writes, once it is done); returns it (numba calls it again with the arguments,
    converted to that signature's types)."""
    if ahead:
        compile_ahead.finish()
    dispatcher.compile(signature)
    dispatcher.disable_compile()
    _UNCOMPILED[:] = [e for e in _UNCOMPILED if e[0] is not dispatcher]
    return dispatcher
