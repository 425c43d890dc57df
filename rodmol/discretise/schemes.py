"""The spatial schemes, by name: what each one evaluates where, and what its
stencil reads.

Both schemes share the paper's staggered grid, unknowns and state layout and
one compiled loop (:mod:`rodmol.discretise.stencil`); a scheme says

* ``depends``: which fields of which neighbouring block each rate reads (the
  Jacobian's pattern, bandwidths and colouring, the preconditioner's check and
  the equilibrium's band are all derived from it);
* where the cell properties (stiffness, viscosity) are sampled;
* the length of the rod each velocity node stands for (its control volume),
  which weighs the node in the energy, in point loads and in the tip wrench.

To add a scheme, add a :class:`Scheme` to :data:`SCHEMES` (and, if its loop
differs, a switch in the stencil).
"""

from dataclasses import dataclass

import numpy as np

from .._checks import did_you_mean
from ..errors import ParameterError

#: Fields of the upwind stencil. The next block's w reaches the force only
#: through the moment, and the torque sees the previous block only through
#: k_t (its w).
_UPWIND = {
    "u": {0: ("Q", "v")},
    "Q": {0: ("Q", "w")},
    "q": {-1: ("v", "w"), 0: ("q", "k", "v")},
    "k": {-1: ("w",), 0: ("k", "w")},
    "v": {-1: ("v", "w"), 0: ("Q", "q", "k", "v", "w"), 1: ("q", "k", "v")},
    "w": {-1: ("w",), 0: ("q", "k", "v", "w"), 1: ("q", "k", "v", "w")},
}
#: The centred stencil also reads both cells' stresses in both balances
#: (their rates read both nodes' v and w) and the cell's own w in q_t.
_CENTRED = {
    "u": {0: ("Q", "v")},
    "Q": {0: ("Q", "w")},
    "q": {-1: ("v", "w"), 0: ("q", "k", "v", "w")},
    "k": {-1: ("w",), 0: ("k", "w")},
    "v": {-1: ("v", "w"), 0: ("Q", "q", "k", "v", "w"), 1: ("q", "k", "v", "w")},
    "w": {-1: ("v", "w"), 0: ("q", "k", "v", "w"), 1: ("q", "k", "v", "w")},
}


@dataclass(frozen=True)
class Scheme:
    """A spatial scheme on the staggered grid (see the module docstring)."""

    name: str
    summary: str
    order: int
    centred: bool
    depends: dict
    #: Default relative tolerance: the time error at most a tenth of the
    #: spatial error at N = 100 on the paper's tests (docs/model.md,
    #: docs/performance.md).
    default_rtol: float

    def cell_points(self, s_nodes):
        """Arc lengths [m] where the properties of cells 0..N-1 are sampled."""
        s_nodes = np.asarray(s_nodes, dtype=float)
        return 0.5 * (s_nodes[:-1] + s_nodes[1:]) if self.centred else s_nodes[:-1]

    def node_lengths(self, n, ds):
        """Length of rod [m] each velocity node 1..N stands for, shape (N,)."""
        lengths = np.full(n, float(ds))
        if self.centred:
            lengths[-1] *= 0.5
        return lengths


SCHEMES = {
    "centred": Scheme(
        "centred",
        "second order: cell properties at cell midpoints, centred non-derivative "
        "terms, half a cell at the tip", 2, True, _CENTRED, 3e-5),
    "upwind": Scheme(
        "upwind",
        "the paper's scheme (section IV-C): one-sided non-derivative terms, first order",
        1, False, _UPWIND, 1e-4),
}
DEFAULT_SCHEME = "centred"


def get_scheme(name):
    """The :class:`Scheme` called ``name`` (a Scheme is returned as is)."""
    if isinstance(name, Scheme):
        return name
    if name in SCHEMES:
        return SCHEMES[name]
    raise ParameterError(f"unknown `scheme` {name!r}{did_you_mean(name, SCHEMES)} "
                         f"(schemes: {', '.join(map(repr, SCHEMES))})")
