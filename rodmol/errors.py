"""Exceptions raised by rodmol.

Every input check raises :class:`ParameterError`, a :class:`ValueError`
subclass whose message names the parameter and the offending value.
"""


class RodmolError(Exception):
    """Base class of every rodmol exception."""


#: Longest line of an error message [characters]: a value quoted in full
#: (say a 100,000-entry list) is cut, so messages stay readable.
MAX_LINE = 600


class ParameterError(RodmolError, ValueError):
    """An input parameter is invalid; the message names it and its value."""

    def __init__(self, message="", *args):
        lines = str(message).split("\n")
        cut = [line if len(line) <= MAX_LINE else f"{line[:MAX_LINE]}... ({len(line)} characters)"
               for line in lines]
        super().__init__("\n".join(cut), *args)


class UserFunctionError(ParameterError):
    """A function the user gave (a tension, a feedback law, a load, a base
    motion, a radius, a progress callable) raised or returned garbage; the
    original exception, with its traceback, is the ``__cause__``. ``t`` is the
    time [s] at which it failed (None outside a time evaluation)."""

    def __init__(self, message="", *args, t=None):
        super().__init__(message, *args)
        self.t = None if t is None else float(t)


class IntegrationError(RodmolError, RuntimeError):
    """A time integration failed; ``result`` holds what was computed so far."""

    def __init__(self, message, result=None):
        super().__init__(message)
        self.result = result


class EquilibriumError(RodmolError, RuntimeError):
    """The static equilibrium could not be found."""


class NotSupportedYet(ParameterError):
    """A valid request that rodmol does not handle yet (a joint at a rod's tip,
    a closed loop, streamed output of a system); the message says what."""
