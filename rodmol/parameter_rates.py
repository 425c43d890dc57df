"""df/dp of a model's rates for named parameters (:mod:`rodmol.named_parameters`), at any
(t, y): the columns F(t) of a continuous adjoint, and the initial equilibrium's derivative.

Two rules, each written once:

* a tension's values (a knot input's knots, a constant tension): the rates are linear in a
  cable's tension, so df/dT(t) is one difference of the rates of the model with every value
  moved by delta (T(t) + delta at every t: the hat functions sum to 1), divided by delta,
  exact for any delta; the column of knot k is that times its hat function b_k(t). One
  right-hand side per cable, whatever the number of knots;
* any other parameter: the central difference of the rates of the two models of
  :meth:`~rodmol.named_parameters.Parameter.pair`, per component.

The models are discretised once (no recompilation: the kernels read arrays).
"""

import numpy as np

from .sensitivities import EQUILIBRIUM_STEP, EQUILIBRIUM_TOL
from .solve.equilibrium import equilibrium


def is_tension_value(parameter):
    """True if ``parameter`` is a tension's own values (knots or a constant), not a scale or offset."""
    parts = parameter.fields[0].split(".")
    return "tension" in parts and parts[-1] not in ("scale", "offset")


def hats(parameter, t):
    """d T(t) / d value (m,): a knot input's hat functions at ``t`` [s] (held flat outside
    the knots, as :class:`rodmol.inputs.Knots` interpolates), 1 for a constant."""
    if parameter.knots is None:
        return np.ones(1)
    knots, out = parameter.knots, np.zeros(parameter.size)
    if t <= knots[0]:
        out[0] = 1.0
    elif t >= knots[-1]:
        out[-1] = 1.0
    else:
        j = int(np.searchsorted(knots, t, side="right"))
        s = (t - knots[j - 1]) / (knots[j] - knots[j - 1])
        out[j - 1], out[j] = 1.0 - s, s
    return out


def shifted(parameter, model, delta):
    """``model`` with every value of ``parameter`` moved by ``delta``."""
    return parameter.at(model, parameter.value + delta)


class ParameterColumns:
    """F(t, y) = df/dp (n, width) of ``system`` (``kind``'s, of ``model``) for ``parameters``,
    weighted by the adjoint (:meth:`weighted`), and dy0/dp of the initial equilibrium."""

    def __init__(self, kind, model, system, parameters):
        self.kind, self.model, self.system, self.parameters = kind, model, system, tuple(parameters)
        self.width = sum(p.size for p in self.parameters)
        self._rules = []  # (first column, parameter, "linear", shifted system, delta) or (.., "pair", [(up, down, h)])
        column = 0
        for p in self.parameters:
            if is_tension_value(p):
                delta = p.scale
                self._rules.append((column, p, "linear", kind.discretise(shifted(p, model, delta), system.scheme),
                                    delta))
            else:
                pairs = []
                for j in range(p.size):
                    up, down, h = p.pair(model, j)
                    pairs.append((kind.discretise(up, system.scheme), kind.discretise(down, system.scheme), h))
                self._rules.append((column, p, "pair", pairs, None))
            column += p.size

    def weighted(self, t, y, lam):
        """lambda^T F(t, y) (width,): the columns weighted by ``lam`` (n,), at (t, y)."""
        fy = self.system(t, y).copy()
        out = np.empty(self.width)
        for column, p, rule, systems, delta in self._rules:
            if rule == "linear":
                out[column:column + p.size] = (lam @ (systems(t, y) - fy)) / delta * hats(p, t)
            else:
                for j, (up, down, h) in enumerate(systems):
                    out[column + j] = lam @ (up(t, y) - down(t, y)) / (2.0 * h)
        return out

    def split(self, values):
        """{key: (m,) array} of a vector over the columns."""
        out, column = {}, 0
        for p in self.parameters:
            out[p.key] = np.array(values[column:column + p.size], dtype=float)
            column += p.size
        return out

    def initial_equilibrium(self, t0, y0):
        """dy0/dp (n, width) of the equilibrium at ``t0`` [s] (``initial="equilibrium"``): central
        differences of two equilibria per component (:meth:`Parameter.pair`, as the forward
        sensitivities take them, each solved by Newton from the run's ``y0``); a tension's of its value at t0 (one-sided of second order
        where a value sits at zero), times the hats there."""
        out = np.zeros((self.system.size, self.width))

        def rest(model):
            return equilibrium(self.kind.discretise(model, self.system.scheme), t0, tol=EQUILIBRIUM_TOL, start=y0)

        for column, p, rule, _, _ in self._rules:
            h = EQUILIBRIUM_STEP * p.scale
            if rule == "linear":
                if np.min(p.value) - h >= 0.0:
                    derivative = (rest(shifted(p, self.model, h)) - rest(shifted(p, self.model, -h))) / (2.0 * h)
                else:
                    derivative = (-3.0 * rest(self.model) + 4.0 * rest(shifted(p, self.model, h))
                                  - rest(shifted(p, self.model, 2.0 * h))) / (2.0 * h)
                out[:, column:column + p.size] = derivative[:, None] * hats(p, t0)
                continue
            for j in range(p.size):
                up, down, step = p.pair(self.model, j, step=h)
                out[:, column + j] = (rest(up) - rest(down)) / (2.0 * step)
        return out
