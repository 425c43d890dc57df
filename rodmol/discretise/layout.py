"""Packing of the semi-discrete state vector, node by node, and every structure
derived from it: offsets, accessors, absolute-tolerance
scales, the Jacobian pattern, its bandwidths and its colouring.

The state starts with the base pose (u0, Q0: 7 values), then one block of 19
values per element b = 0..N-1 holding the pose and velocities of velocity node
b + 1 and the strains of strain node b::

    [u (3), Q (4), q (3), k (3), v (3), w (3)]

Couplings are declared, never drawn by hand: a *dependency table* maps each
row field to ``{block offset: column fields}`` (the scheme's table lives with
the scheme, each load kind declares its own), and :meth:`BlockLayout.pattern`,
:meth:`~BlockLayout.bandwidths` and :meth:`~BlockLayout.colouring` are computed
from it. Keeping (q, k, v, w) contiguous with v, w last keeps the half-
bandwidths as small as this blocking allows.
"""

from dataclasses import dataclass, field

import numpy as np

from .rotations import normalise

#: Fields of an element block and their widths, in storage order.
STATE_FIELDS = {"u": 3, "Q": 4, "q": 3, "k": 3, "v": 3, "w": 3}
#: Fields of the base header: base position and quaternion.
HEADER_FIELDS = {"u": 3, "Q": 4}


def _slices(fields):
    out, start = {}, 0
    for name, width in fields.items():
        out[name] = slice(start, start + width)
        start += width
    return out


FIELDS = _slices(STATE_FIELDS)
BLOCK = sum(STATE_FIELDS.values())
HEADER = sum(HEADER_FIELDS.values())
# Integer offsets of each field inside a block, for the compiled kernels (numba
# freezes module-level ints into the machine code).
U, QUAT, Q, K, V, W = (FIELDS[f].start for f in ("u", "Q", "q", "k", "v", "w"))
#: The fields of the strain and velocity rows a state leaves out, as a Result
#: stores them: the base node's velocities v0, w0 (prescribed) and the tip's
#: strains q, k (from the tip load).
BOUNDARY_FIELDS = {"v": 3, "w": 3, "q": 3, "k": 3}


def span(names):
    """The slice of a block covering the fields ``names``, which must be adjacent."""
    slices = [FIELDS[f] for f in names]
    if any(a.stop != b.start for a, b in zip(slices, slices[1:])):
        raise ValueError(f"the fields {names} are not adjacent in a block")
    return slice(slices[0].start, slices[-1].stop)


def merge(*tables):
    """Union of dependency tables ``{row: {offset: (cols...)}}``."""
    out = {}
    for table in tables:
        for row, deps in table.items():
            for offset, cols in deps.items():
                have = out.setdefault(row, {}).setdefault(offset, ())
                out[row][offset] = have + tuple(c for c in cols if c not in have)
    return out


@dataclass(frozen=True)
class BlockLayout:
    """A vector of ``header`` values followed by ``n_blocks`` blocks of ``fields``."""

    n_blocks: int
    fields: dict = field(default_factory=lambda: dict(STATE_FIELDS))
    header: int = 0

    @property
    def block(self):
        return sum(self.fields.values())

    @property
    def size(self):
        return self.header + self.block * self.n_blocks

    def slices(self):
        return _slices(self.fields)

    def blocks(self, y):
        """(..., n_blocks, block) view of the blocks of y (y may have leading axes)."""
        y = np.asarray(y)
        return y[..., self.header:].reshape(y.shape[:-1] + (self.n_blocks, self.block))

    def field(self, y, name):
        """(..., n_blocks, width) view of one field of y."""
        return self.blocks(y)[..., self.slices()[name]]

    def pattern(self, depends, header_depends=None):
        """Structural Jacobian pattern (bool, size x size) of a dependency table.

        ``header_depends`` is a (header, header) bool array of the header's
        own coupling (headers couple to nothing else).
        """
        n, block, sl = self.n_blocks, self.block, self.slices()
        pat = np.zeros((self.size, self.size), dtype=bool)
        if header_depends is not None:
            pat[:self.header, :self.header] = header_depends
        local = np.arange(block)
        for row_field, deps in depends.items():
            rows = local[sl[row_field]]
            for offset, cols in deps.items():
                cidx = np.concatenate([local[sl[c]] for c in cols]) if cols else local[:0]
                for b in range(n):
                    if 0 <= b + offset < n:
                        r = self.header + b * block + rows
                        c = self.header + (b + offset) * block + cidx
                        pat[np.ix_(r, c)] = True
        return pat

    def bandwidths(self, depends):
        """(lower, upper) half-bandwidths of :meth:`pattern` (headers excluded)."""
        # The pattern is block-periodic: three blocks tell the whole story.
        small = BlockLayout(min(self.n_blocks, 3), self.fields, 0)
        rows, cols = np.nonzero(small.pattern(depends))
        return int(np.max(rows - cols)), int(np.max(cols - rows))

    def column_reach(self, depends):
        """For each entry j of a block, the (lowest, highest) offset of the
        blocks whose rows depend on it, or None if no row does."""
        sl = self.slices()
        reach = [None] * self.block
        for deps in depends.values():
            for offset, cols in deps.items():
                for c in cols:
                    for j in range(sl[c].start, sl[c].stop):
                        lo, hi = reach[j] or (-offset, -offset)
                        reach[j] = (min(lo, -offset), max(hi, -offset))
        return reach

    def colouring(self, depends):
        """Column groups for finite differences, as an int array (n_groups, 4):
        (entry j, residue r, period p, lowest row offset). A group perturbs
        entry j of every block b with b % p == r: the row blocks b + lo ..
        b + lo + p - 1 they reach are then disjoint between members."""
        groups = []
        for j, reach in enumerate(self.column_reach(depends)):
            if reach is None:
                continue
            lo, hi = reach
            period = hi - lo + 1
            groups += [(j, r, period, lo) for r in range(min(period, self.n_blocks))]
        return np.array(groups, dtype=np.int64).reshape(-1, 4)


class StateLayout(BlockLayout):
    """Owns the packing of the rod's state vector for N elements."""

    def __init__(self, n_elements):
        super().__init__(n_elements, dict(STATE_FIELDS), HEADER)

    @property
    def n_elements(self):
        return self.n_blocks

    def base_position(self, y):
        """(..., 3) base position u0 [m], global."""
        return np.asarray(y)[..., 0:3]

    def base_quaternion(self, y):
        """(..., 4) base orientation Q0."""
        return np.asarray(y)[..., 3:HEADER]

    def quaternions(self, y):
        """(..., N+1, 4) orientations of nodes 0..N (node 0: the base)."""
        return np.concatenate([self.base_quaternion(y)[..., None, :], self.field(y, "Q")], axis=-2)

    def project_quaternions(self, y):
        """Scale every orientation quaternion of ``y`` (..., size) to unit norm, in place.

        The dynamics do not see |Q| (rotations divide by |Q|^2 and the
        kinematics Q_t = Q (x) (0, w) / 2 are linear in Q), so this moves
        nothing but the norm: the integrator lets it stray by up to its
        tolerance during fast motion, and the stored states are put back on
        the unit sphere.
        """
        y = y.reshape(-1, self.size)  # a view: the states are contiguous
        normalise(y[:, None, 3:HEADER])
        normalise(self.field(y, "Q"))

    def integrated_positions(self, y):
        """(..., N+1, 3) time-integrated positions of nodes 0..N [m], global."""
        return np.concatenate([self.base_position(y)[..., None, :], self.field(y, "u")], axis=-2)

    @property
    def boundary(self):
        """The layout of the rows of :data:`BOUNDARY_FIELDS` (one block)."""
        return BlockLayout(1, dict(BOUNDARY_FIELDS))

    def tip_slice(self, name):
        """Index range of field ``name`` of the tip node's block."""
        sl = FIELDS[name]
        start = HEADER + BLOCK * (self.n_blocks - 1)
        return slice(start + sl.start, start + sl.stop)

    def pack(self, u0, quat0, u, quat, q, k, v, w):
        y = np.empty(self.size)
        y[0:3], y[3:HEADER] = u0, quat0
        b = self.blocks(y)
        for name, value in zip(STATE_FIELDS, (u, quat, q, k, v, w)):
            b[:, FIELDS[name]] = value
        return y

    def scales(self, per_field):
        """Every entry's typical magnitude, from one scale per field
        (``per_field``: a dict with "u", "Q", "q", "k", "v", "w")."""
        block = np.concatenate([np.full(w, per_field[f]) for f, w in STATE_FIELDS.items()])
        head = np.concatenate([np.full(w, per_field[f]) for f, w in HEADER_FIELDS.items()])
        return np.concatenate([head, np.tile(block, self.n_blocks)])

    def header_pattern(self):
        """The base pose integrates prescribed base velocities: u0 and Q0
        rates read Q0 only."""
        pat = np.zeros((HEADER, HEADER), dtype=bool)
        pat[:, 3:HEADER] = True
        return pat

    def entry_name(self, index):
        """A readable name of state entry ``index`` (``"k[2] of element 7"``)."""
        if not 0 <= index < self.size:
            raise IndexError(f"state entry {index} of a rod's state of {self.size}")
        if index < HEADER:
            return f"base {'u' if index < 3 else 'Q'}[{index if index < 3 else index - 3}]"
        b, j = divmod(index - HEADER, BLOCK)
        name = next(f for f, sl in FIELDS.items() if sl.start <= j < sl.stop)
        return f"{name}[{j - FIELDS[name].start}] of element {b}"
