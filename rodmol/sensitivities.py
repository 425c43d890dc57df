"""Forward sensitivities of a run: :func:`rodmol.simulate` with ``sensitivities=[keys]``.

:class:`Plan` resolves the keys (:mod:`rodmol.named_parameters`), builds the
two systems of each parameter component's central difference once (no
recompilation), the larger system of the state and its sensitivities
(:class:`rodmol.discretise.sensitivity_system.SensitivitySystem`), its
initial state and tolerances, and, after the run, each parameter's
:class:`rodmol.derivatives.Derivative`.

Why an augmented system on today's CVODE: scikit-sundae 1.2 has no CVODES;
SUNDIALS' own bindings (``sundials4py``) need Python >= 3.12, and the
project runs on 3.11. The cost is measured in ``solvers/sensitivity_accuracy.py``
(``docs/gradients.md``).
"""

import numpy as np

from . import named_parameters
from .derivatives import Derivative
from .discretise.sensitivity_system import SensitivitySystem
from .errors import ParameterError
from .solve.equilibrium import equilibrium

#: Backends that integrate the sensitivities with the state (they read the system's protocol only).
BACKENDS = ("cvode", "rk23")
#: Relative step of the equilibrium's central difference (the initial sensitivities):
#: larger than the run's, so the equilibrium's own tolerance is not amplified.
EQUILIBRIUM_STEP = 1e-4
#: The equilibria's tolerance there (relative to the load scale).
EQUILIBRIUM_TOL = 1e-12


def check(keys, backend, out, resume):
    """Refuse, before any work, what sensitivities cannot do: another backend, streaming."""
    if backend not in BACKENDS:
        raise ParameterError(f"`sensitivities` with backend={backend!r}: only {', '.join(BACKENDS)} "
                             "integrate them")
    if out is not None or resume:
        raise ParameterError("`sensitivities` are not streamed to files: leave out `out` (and `resume`) and "
                             "save the result's arrays yourself")
    if isinstance(keys, str) or not keys:
        raise ParameterError(f"`sensitivities` must be a non-empty list of parameter keys such as "
                             f"['material.E'], got {keys!r}")


class Plan:
    """The sensitivities of one run of ``model`` (its system ``system``, of kind ``kind``)
    to the parameters ``keys``."""

    def __init__(self, kind, model, system, keys):
        self.kind, self.model, self.base = kind, model, system
        self.parameters = named_parameters.parameters(model, keys)
        self.columns = [(p, j) for p in self.parameters for j in range(p.size)]
        pairs, steps = [], []
        for p, j in self.columns:
            up, down, h = p.pair(model, j)
            pairs.append((kind.discretise(up, system.scheme), kind.discretise(down, system.scheme)))
            steps.append(h)
        self.system = SensitivitySystem(system, pairs, steps)

    def atol(self, atol):
        """The tolerances of Y: the state's ``atol``, and for each s_i ``atol / scale_i``,
        so that p_i s_i is held as the state is."""
        atol = np.broadcast_to(np.asarray(atol, dtype=float), (self.base.size,))
        return np.concatenate([atol] + [atol / p.scale for p, _ in self.columns])

    def initial(self, y0, initial, t0):
        """Y at ``t0`` [s]: ``y0`` and its sensitivities: 0 for a given state or the rest
        shape, the equilibrium's central difference for ``initial="equilibrium"`` (each side
        solved by Newton from ``y0``: a few iterations)."""
        s0 = np.zeros((len(self.columns), self.base.size))
        if isinstance(initial, str) and initial == "equilibrium":
            for i, (p, j) in enumerate(self.columns):
                up, down, h = p.pair(self.model, j, step=EQUILIBRIUM_STEP * p.scale)
                systems = [self.kind.discretise(m, self.base.scheme) for m in (up, down)]
                plus, minus = (equilibrium(s, t0, tol=EQUILIBRIUM_TOL, start=y0) for s in systems)
                s0[i] = (plus - minus) / (2.0 * h)
        return np.concatenate([np.asarray(y0, dtype=float), s0.reshape(-1)])

    def derivatives(self, t, Y, success, message, stats):
        """{key: Derivative} of the run's frames ``Y`` (n_t, size) at times ``t``."""
        y, *sensitivities = self.system.blocks(np.asarray(Y))
        out, i = {}, 0
        for p in self.parameters:
            plus, minus, steps = [], [], []
            for _ in range(p.size):
                up, down = self.system.pairs[i]
                h, s = self.system.steps[i], sensitivities[i]
                plus.append(self.kind.result(up, t, y + h * s, success, message, dict(stats)))
                minus.append(self.kind.result(down, t, y - h * s, success, message, dict(stats)))
                steps.append(h)
                i += 1
            out[p.key] = Derivative(plus, minus, steps, stacked=p.knots is not None)
        return out
