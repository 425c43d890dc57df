"""The unloaded rod at rest in its rest shape: the state every rest and
straight start, the equilibrium's first guess and the holds' rest poses share."""

import numpy as np

from . import centreline, rotations
from .layout import StateLayout
from .sampling import rest_strains
from .schemes import DEFAULT_SCHEME, get_scheme


def undeformed_state(model, scheme=DEFAULT_SCHEME):
    """The unloaded rod at rest in its rest shape, for the spatial ``scheme``.

    The strains are the rod's rest strains sampled at the scheme's cells (where
    the stresses measure them from), the orientations follow from the base's
    with the scheme's own kinematics, Q_{i+1} = Q_i exp(ds k*_i), and the
    positions are the chords of ``physics.chord`` (as ``Result.positions``
    rebuilds them): without loads every rate vanishes. A straight rod lies
    along the base's local x axis, with positions s_i on it.
    """
    base, n = model.base, model.n_elements
    position, rotation = np.asarray(base.position, dtype=float), np.asarray(base.rotation, dtype=float)
    quat0 = rotations.from_matrix(base.rotation)
    q, k = rest_strains(model, get_scheme(scheme).cell_points(model.s_nodes))
    if model.rod.straight:  # in closed form: no round-off accumulated along the rod
        u, quat = position + model.s_nodes[1:, None] * rotation[:, 0], np.tile(quat0, (n, 1))
    else:
        chain = np.empty((n + 1, 4))
        chain[0] = quat0
        for i, step in enumerate(rotations.from_rotation_vector(model.ds * k)):
            chain[i + 1] = rotations.multiply(chain[i], step)
        rotations.normalise(chain[None])
        u, quat = centreline.positions(position, chain, q, k, model.ds)[1:], chain[1:]
    zeros = np.zeros((n, 3))
    return StateLayout(n).pack(position, quat0, u, quat, q, k, zeros, zeros)
