"""Signals that ask a run to stop, honoured at the run's next safe point.

Python's own Ctrl-C handler raises ``KeyboardInterrupt`` at whatever bytecode
runs when the signal arrives. Inside a weakref callback or a finaliser (h5py
closing a file) the exception is printed ("Exception ignored in ...") and
dropped, and the run goes on to its end; inside a sink's write it cuts the
chunk short. Within :class:`DeferredSignals` a signal only records that a stop
was asked; the integrations poll :func:`stop_reason` where stopping is safe
(every backend's accepted step, :meth:`rodmol.solve.watch.Watch.pace`; a
system's CVODE at each right-hand side, before its work) and end there with
the frames done, which the run's sink then stores whole. A second signal
raises ``KeyboardInterrupt`` at once (the user insists), unless ``forcing``
is off.
"""

import contextlib
import os
import signal
import sys
import threading

#: The signal that asked the running integration to stop (``signal.Signals``), or None.
_asked = None


def stop_reason():
    """Why the running integration must stop, for its message, or None while no signal asked it."""
    return None if _asked is None else f"interrupted by {_asked.name}"


class DeferredSignals:
    """Within ``with``: each of ``signals`` asks the run to stop at its next safe point
    (:func:`stop_reason`) instead of raising where it lands; ``notice`` is written to
    standard error at the first. Handlers can only be set in the main thread; elsewhere
    the signals keep theirs.

    Attributes
    ----------
    signal : signal.Signals or None
        The first signal received.
    count : int
        The signals received.
    forcing : bool
        A signal after the first raises ``KeyboardInterrupt`` (default True); off, it is
        only counted (e.g. while files are written between frames, which checks ``count``).
    """

    def __init__(self, signals=(signal.SIGINT, signal.SIGTERM), notice=None):
        self.signals, self.notice = tuple(signals), notice
        self.signal, self.count, self.forcing, self._previous = None, 0, True, {}

    def __enter__(self):
        global _asked
        _asked = None
        if threading.current_thread() is threading.main_thread():
            self._previous = {signum: signal.signal(signum, self) for signum in self.signals}
        return self

    def __exit__(self, *exc):
        global _asked
        for signum, handler in self._previous.items():
            signal.signal(signum, handler)
        self._previous, _asked = {}, None

    def __call__(self, signum, frame):
        global _asked
        self.count += 1
        if self.signal is not None:
            if self.forcing:
                raise KeyboardInterrupt
            return
        self.signal = _asked = signal.Signals(signum)
        if self.notice:
            _write_stderr(self.notice)


def _write_stderr(text):
    """``text`` on standard error by one system call: a handler that printed through
    ``sys.stderr`` could land inside another write to it (a reentrant call)."""
    with contextlib.suppress(AttributeError, OSError, ValueError):  # no file behind it (a test's capture)
        os.write(sys.stderr.fileno(), f"\n{text}\n".encode())
