"""A helper process that compiles kernels on a second core while this process compiles
the right-hand side: a fresh cache then costs about the larger part, not their sum.

The helper imports rodmol from the same place, compiles the kernels marked ``ahead``
(:func:`rodmol.discretise.compiling.jit`) and exits; numba writes each into its disk
cache (index and data, each to a temporary file renamed into place, so a helper that
fails or is killed leaves no half-written entry), and this process then loads them
instead of compiling them. It is started only where it can help: a machine with a second
core that looks idle (:func:`idle_core`), a kernel the cache lacks and a cache this user
can write (a read-only installation whose kernels are not in numba's user-wide cache
compiles in this process alone). ``RODMOL_COMPILE_AHEAD=0`` turns it off, ``=1`` starts
it on a busy machine too. This process goes on meanwhile and waits for it
(at most :data:`TIMEOUT`) at the first call of a kernel it compiles; it is stopped with
this process; whatever it did not finish is compiled here.
"""

import atexit
import os
import subprocess
import sys
from pathlib import Path

from .kernel_cache import cached

#: Longest wait [s] for the helper once this process's own kernels are compiled.
TIMEOUT = 120.0
#: The environment variable that turns the helper off ("0") or on however busy the machine ("1").
SWITCH = "RODMOL_COMPILE_AHEAD"
_helper = None  # this process's running helper, if any
_PARENT = str(Path(__file__).resolve().parents[2])  # the directory holding the rodmol package
# The helper's work, as its command: import rodmol (which registers every kernel), then
# compile the ``ahead`` kernels (the command does the imports: this module imports no floor above).
_CODE = ("import sys; sys.path.insert(0, {parent!r}); import rodmol; "
         "from rodmol.discretise import compiling; compiling.compile_ahead_here()")


def cores():
    """The CPU cores this process may run on."""
    try:
        return len(os.sched_getaffinity(0))
    except (AttributeError, OSError):
        return os.cpu_count() or 1


def _writable(dispatcher):
    path = getattr(getattr(dispatcher, "_cache", None), "_cache_path", None)
    return path is not None and os.access(path, os.W_OK)


def idle_core():
    """True if a core looks free: the load average (1 min) leaves one beside this process
    (on a machine busy with other jobs a helper only competes with them and this process)."""
    try:
        return os.getloadavg()[0] < cores() - 0.5
    except OSError:
        return True


def wanted(dispatchers):
    """True if a helper would compile some of ``dispatchers`` (see the module docstring)."""
    switch = os.environ.get(SWITCH, "")
    if switch == "0" or cores() < 2 or (switch != "1" and not idle_core()):
        return False
    missing = [d for d in dispatchers if cached(d) is False]
    return bool(missing) and all(_writable(d) for d in missing)


def start(dispatchers):
    """Start the helper process compiling the kernels marked ``ahead``, unless one is running
    or it would not help (:func:`wanted`) or cannot start."""
    global _helper
    if _helper is not None or not wanted(dispatchers):
        return
    env = dict(os.environ, **{SWITCH: "0"})  # a helper starts no helper
    try:
        _helper = subprocess.Popen([sys.executable, "-c", _CODE.format(parent=_PARENT)], env=env,
                                   stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL,
                                   stderr=subprocess.DEVNULL)
    except OSError:
        _helper = None


def running():
    """True while a helper started by :func:`start` has not been waited for."""
    return _helper is not None


def finish(timeout=TIMEOUT):
    """Wait for the helper (if one runs) at most ``timeout`` [s], and stop it if it is still
    running then; what it did not finish, this process compiles."""
    global _helper
    helper, _helper = _helper, None
    if helper is None:
        return
    try:
        helper.wait(timeout=timeout)
    except subprocess.TimeoutExpired:
        helper.kill()
        helper.wait()


atexit.register(finish, 0.0)  # a run that ends (or fails) before it needs the helper's work

