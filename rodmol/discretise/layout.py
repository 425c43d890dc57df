"""Packing of the semi-discrete state vector, node by node, and its Jacobian pattern.

The vector starts with the base pose (u0, Q0: 7 values), then one block of 19
values per element b = 0..N-1 holding the pose and velocities of velocity node
b + 1 and the strains of strain node b::

    [u (3), Q (4), q (3), k (3), v (3), w (3)]

Strains and velocities are coupled only to the neighbouring blocks, so the
Jacobian is banded; keeping (q, k, v, w) contiguous with v, w last makes the
half-bandwidths as small as this blocking allows.
"""

from dataclasses import dataclass

import numpy as np

HEADER = 7
FIELDS = {"u": slice(0, 3), "Q": slice(3, 7), "q": slice(7, 10), "k": slice(10, 13),
          "v": slice(13, 16), "w": slice(16, 19)}
BLOCK = 19

# Which fields of which block (offset -1, 0, +1) each field's rate depends on.
_DEPENDS = {
    "u": {0: ("Q", "v")},
    "Q": {0: ("Q", "w")},
    "q": {-1: ("v", "w"), 0: ("q", "k", "v")},
    "k": {-1: ("w",), 0: ("k", "w")},
    # The next block's w reaches the force only through the moment, and the
    # torque sees the previous block only through k_t (its w).
    "v": {-1: ("v", "w"), 0: ("Q", "q", "k", "v", "w"), 1: ("q", "k", "v")},
    "w": {-1: ("w",), 0: ("q", "k", "v", "w"), 1: ("q", "k", "v", "w")},
}


@dataclass(frozen=True)
class StateLayout:
    """Owns the packing of the state vector for N elements."""

    n_elements: int

    @property
    def size(self):
        return HEADER + BLOCK * self.n_elements

    def blocks(self, y):
        """(N, 19) view of the element blocks of y."""
        return y[HEADER:].reshape(self.n_elements, BLOCK)

    def field(self, y, name):
        """(N, 3 or 4) view of one field of y (see ``FIELDS``)."""
        return self.blocks(y)[:, FIELDS[name]]

    def pack(self, u0, quat0, u, quat, q, k, v, w):
        y = np.empty(self.size)
        y[:3], y[3:7] = u0, quat0
        b = self.blocks(y)
        for name, value in zip(["u", "Q", "q", "k", "v", "w"], (u, quat, q, k, v, w)):
            b[:, FIELDS[name]] = value
        return y

    def pattern(self):
        """Structural Jacobian pattern (bool, size x size), from ``_DEPENDS``.

        It covers every coupling of the right-hand side except cable tensions
        that feed back on the state, which are global.
        """
        n = self.n_elements
        pat = np.zeros((self.size, self.size), dtype=bool)
        pat[:HEADER, :HEADER] = True  # base pose integrates the prescribed base velocities
        for row_field, deps in _DEPENDS.items():
            rows = np.arange(BLOCK)[FIELDS[row_field]]
            for offset, cols in deps.items():
                cidx = np.concatenate([np.arange(BLOCK)[FIELDS[c]] for c in cols])
                for b in range(n):
                    if 0 <= b + offset < n:
                        r = HEADER + b * BLOCK + rows
                        c = HEADER + (b + offset) * BLOCK + cidx
                        pat[np.ix_(r, c)] = True
        return pat

    def bandwidths(self):
        """(lower, upper) half-bandwidths of :meth:`pattern`, from the layout alone."""
        # The pattern is block-periodic, so three blocks tell the whole story.
        small = StateLayout(min(self.n_elements, 3))
        rows, cols = np.nonzero(small.pattern())
        return int(np.max(rows - cols)), int(np.max(cols - rows))
