"""Time-integration backends, chosen by name from one table.

Each backend integrates ``dy/dt = system(t, y)`` from ``t_out[0]`` and returns
a :class:`rodmol.solve.outputs.RawSolution` holding the states at the output
times reached. A backend sees only the system's narrow interface (see
:mod:`rodmol.discretise.system`).
"""

from .. import _checks
from .cvode import cvode
from .galpha import generalized_alpha
from .rk23 import rk23
from .system_cvode import cvode_system
from .system_stepping import on_assembly

#: Backends by name, of one rod (a ``SemiDiscrete``).
BACKENDS = {"cvode": cvode, "rk23": rk23, "galpha": generalized_alpha}
#: The same backends of a system of rods and bodies (an ``Assembly``): CVODE's own system
#: run, the others the single rod's on the assembly seen as one system.
SYSTEM_BACKENDS = {"cvode": cvode_system, "rk23": on_assembly(rk23), "galpha": on_assembly(generalized_alpha)}


def get_backend(name, backends=BACKENDS):
    """The backend called ``name`` in ``backends`` (a near miss gets a did-you-mean)."""
    return backends[_checks.choice("backend", name, tuple(backends))]
