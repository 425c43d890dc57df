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

To add a scheme, add a :class:`Scheme` to :data:`SCHEMES` and, if its loop
differs from the existing ones, a :class:`Kernel` code and that code's branch
in the stencil.
"""

from dataclasses import dataclass
from enum import IntEnum

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


class Kernel(IntEnum):
    """The branch of the compiled loop (:mod:`rodmol.discretise.stencil`) a
    scheme runs: where the non-derivative terms are evaluated."""

    #: Strain rates at the cell's base-side node, balances with the tip-side cell's products.
    UPWIND = 0
    #: Strain rates and balances with the averages over the cell's nodes and the node's cells.
    CENTRED = 1


@dataclass(frozen=True)
class Scheme:
    """A spatial scheme on the staggered grid (see the module docstring).

    ``kernel`` is the stencil's branch; ``cell_point`` the fraction of a cell
    (from its base-side node) where its properties are sampled; ``tip_share``
    the fraction of a cell the tip node stands for (the other nodes: one cell);
    ``base_share`` the fraction of cell 0's non-derivative products (k x N,
    k x M + q x N) that the base node's balance would take (node 1 takes the
    rest): a body clamped to the base feels them with cell 0's stress, so
    that the pair of forces on body and node 1 is the same as between any two
    nodes (:mod:`rodmol.discretise.assembly`).
    """

    name: str
    summary: str
    order: int
    kernel: Kernel
    cell_point: float
    tip_share: float
    depends: dict
    #: Default relative tolerance: the time error at most a tenth of the
    #: spatial error at N = 100 on the paper's tests (docs/model.md,
    #: docs/performance.md).
    default_rtol: float
    base_share: float

    def cell_points(self, s_nodes):
        """Arc lengths [m] where the properties of cells 0..N-1 are sampled."""
        s_nodes = np.asarray(s_nodes, dtype=float)
        if self.cell_point == 0.0:
            return s_nodes[:-1]
        return (1.0 - self.cell_point) * s_nodes[:-1] + self.cell_point * s_nodes[1:]

    def node_lengths(self, n, ds):
        """Length of rod [m] each velocity node 1..N stands for, shape (N,)."""
        lengths = np.full(n, float(ds))
        lengths[-1] *= self.tip_share
        return lengths


SCHEMES = {
    "centred": Scheme(
        "centred",
        "second order: cell properties at cell midpoints, centred non-derivative "
        "terms, half a cell at the tip", 2, Kernel.CENTRED, 0.5, 0.5, _CENTRED, 3e-5, 0.5),
    "upwind": Scheme(
        "upwind",
        "the paper's scheme (section IV-C): one-sided non-derivative terms, first order",
        1, Kernel.UPWIND, 0.0, 1.0, _UPWIND, 1e-4, 1.0),
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
