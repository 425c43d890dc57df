"""Exceptions raised by rodmol.

Every input check raises :class:`ParameterError`, a :class:`ValueError`
subclass whose message names the parameter and the offending value.
"""


class RodmolError(Exception):
    """Base class of every rodmol exception."""


class ParameterError(RodmolError, ValueError):
    """An input parameter is invalid; the message names it and its value."""


class UserFunctionError(ParameterError):
    """A function the user gave (a tension, a load, a base motion, a radius)
    raised or returned garbage; the original exception, with its traceback,
    is the ``__cause__``."""


class IntegrationError(RodmolError, RuntimeError):
    """A time integration failed; ``result`` holds what was computed so far."""

    def __init__(self, message, result=None):
        super().__init__(message)
        self.result = result


class EquilibriumError(RodmolError, RuntimeError):
    """The static equilibrium could not be found."""
