"""The Jacobian of a system of rods and rigid bodies
(:class:`rodmol.discretise.assembly.Assembly`) by coloured finite
differences over its structural pattern (``Assembly.pattern``), for the
sparse Newton matrix of the fixed-step schemes
(:class:`rodmol.solve.newton_matrix.SparseNewton`).

The columns are grouped greedily so that no two columns of a group share a
row of the pattern: one right-hand side per group gives all of their
entries. The rods' banded blocks need about their bandwidth in groups, the
coupling blocks a few more.
"""

import numpy as np
from scipy import sparse

from .body_part import first_element
from .joints import JOINT_COLUMNS, JOINT_ROWS

#: Relative step of the differences, times max(|y_j|, the entry's scale).
STEP = np.sqrt(np.finfo(float).eps)


def column_groups(pattern):
    """Greedy colouring of the columns of ``pattern`` (scipy CSC, bool):
    a list of int arrays, no two columns of one sharing a row."""
    n_rows = pattern.shape[0]
    groups, taken = [], []
    for j in range(pattern.shape[1]):
        rows = pattern.indices[pattern.indptr[j]:pattern.indptr[j + 1]]
        for members, used in zip(groups, taken):
            if not used[rows].any():
                members.append(j)
                used[rows] = True
                break
        else:
            used = np.zeros(n_rows, dtype=bool)
            used[rows] = True
            groups.append([j])
            taken.append(used)
    return [np.array(g, dtype=np.int64) for g in groups]


class SystemJacobian:
    """J = df/dy of ``assembly`` on its pattern (the interface of
    :class:`rodmol.discretise.jacobian.CompiledJacobian` with a sparse matrix:
    ``sparsity``, ``__call__``, ``dense``).

    Parameters
    ----------
    assembly : Assembly
    scale : ndarray (size,)
        Typical magnitude of each entry (atol / rtol): it sets the steps.
    """

    def __init__(self, assembly, scale):
        self.assembly = assembly
        self.sparsity = assembly.pattern()
        self.sparsity.sort_indices()
        self.groups = column_groups(self.sparsity)
        self._scale = np.maximum(np.broadcast_to(np.asarray(scale, dtype=float), (assembly.size,)), 1e-300)
        self._f = np.empty(assembly.size)

    def __call__(self, t, y, fy, jj):
        """Fill ``jj`` (the data of a copy of ``sparsity``, CSC order) with J at
        (t, y), ``fy`` = f(t, y); the assembly is left evaluated at y."""
        indptr, indices = self.sparsity.indptr, self.sparsity.indices
        z = np.array(y, dtype=float)
        steps = STEP * np.maximum(np.abs(z), self._scale)
        for group in self.groups:
            z[group] += steps[group]
            self.assembly(t, z, self._f)
            for j in group:
                lo, hi = indptr[j], indptr[j + 1]
                rows = indices[lo:hi]
                jj[lo:hi] = (self._f[rows] - fy[rows]) / steps[j]
            z[group] = y[group]
        self.assembly(t, np.asarray(y, dtype=float), self._f)

    def dense(self, t, y):
        """J at (t, y) as a dense (size, size) array (for tests)."""
        fy = self.assembly(t, np.asarray(y, dtype=float)).copy()
        matrix = self.sparsity.astype(float)
        self(t, y, fy, matrix.data)
        return matrix.toarray()


def assembly_pattern(assembly):
    """An :class:`~rodmol.discretise.assembly.Assembly`'s structural Jacobian pattern (scipy
    CSC, size x size): each rod's
    pattern on the diagonal, each body's block (:func:`_body_pattern`), and for each rod clamped
    to a free body its header and first element against the body's
    velocities, and the body's velocity rows against that element."""
    blocks = [sparse.csr_matrix(sd.pattern()) for sd in assembly.rods.values()]
    blocks += [sparse.csr_matrix(_body_pattern(p)) for p in assembly.bodies.values()]
    pat = sparse.block_diag(blocks, format="lil", dtype=bool)
    for part in assembly.free:
        velocity = np.r_[part.fields["v"], part.fields["w"]]
        for name, sd in zip(part.rods, part.systems):
            start = assembly.parts[name].start
            first = first_element(start, sd)
            pat[np.ix_(first, velocity)] = True
            pat[np.ix_(velocity, first)] = True
    for joint in assembly.joints:
        body = joint.part.slice
        rows = joint.node + JOINT_ROWS
        pat[np.ix_(rows, np.arange(body.start, body.stop))] = True
        if joint.part.body.free:
            node = joint.node + JOINT_COLUMNS
            velocity = np.r_[joint.part.fields["v"], joint.part.fields["w"]]
            pat[np.ix_(velocity, node)] = True
    for joint in assembly.rod_joints:  # each side: its node's velocity rows against the partner node
        pat[np.ix_(joint.node + JOINT_ROWS, joint.partner_fields)] = True
    for joint in assembly.body_joints:  # each free body's velocity rows against the other's block
        for part in joint.parts:
            for other in joint.parts:
                if part.body.free:
                    velocity = np.r_[part.fields["v"], part.fields["w"]]
                    pat[np.ix_(velocity, np.arange(other.slice.start, other.slice.stop))] = True
    return pat.tocsc()


def _body_pattern(part):
    """A body block's own coupling: its quaternion rates read Q (the restoring
    term), its position rates Q unless it is fixed, and a free body's pose
    rates its velocities; its velocity rates read everything (gravity's
    direction, gyroscopic terms)."""
    sl, size = part.layout.slices(), part.layout.size
    pat = np.zeros((size, size), dtype=bool)
    pat[sl["Q"], sl["Q"]] = True
    if part.body.motion != "fixed":
        pat[sl["x"], sl["Q"]] = True
    if "v" in sl:
        pat[sl["x"], sl["v"]] = pat[sl["Q"], sl["w"]] = True
        pat[sl["v"].start:, :] = True
    return pat
