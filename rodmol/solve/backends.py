"""Time-integration backends, chosen by name from one table.

Each backend integrates ``dy/dt = system(t, y)`` from ``t_out[0]`` and returns
a :class:`rodmol.solve.outputs.RawSolution` holding the states at the output
times reached. A backend sees only the system's interface,
:class:`rodmol.discretise.protocol.Discretised`: one rod's system and a system
of rods and bodies run through the same backends.
"""

from .. import _checks
from .cvode import cvode
from .galpha import generalized_alpha
from .rk23 import rk23

#: Backends by name, of any discretised system.
BACKENDS = {"cvode": cvode, "rk23": rk23, "galpha": generalized_alpha}


def get_backend(name):
    """The backend called ``name`` (a near miss gets a did-you-mean)."""
    return BACKENDS[_checks.choice("backend", name, tuple(BACKENDS))]
