"""A body's clamped rods' base velocities (rodmol.discretise.body_part.clamp_map)."""

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from rodmol.discretise.body_part import clamp_map
from rodmol.discretise.rotations import matrices

floats = st.floats(-2.0, 2.0)


@settings(max_examples=30, deadline=None)
@given(st.lists(floats, min_size=24, max_size=24))
def test_bases_move_with_the_body(numbers):
    """A base clamped at p with turn R moves at R^T (v + w x p) and turns at R^T w (body frame in,
    base frame out): the rigid motion of the clamp, whatever the clamp and the motion."""
    a = np.array(numbers)
    points = a[:6].reshape(2, 3)
    quats = a[6:14].reshape(2, 4) + np.array([3.0, 0.0, 0.0, 0.0])  # never zero
    turns = matrices(quats / np.linalg.norm(quats, axis=1, keepdims=True))
    v, w = a[14:17], a[17:20]
    bases = (clamp_map(points, turns) @ np.concatenate([v, w])).reshape(-1, 6)
    for p, turn, base in zip(points, turns, bases):
        assert np.allclose(base[:3], turn.T @ (v + np.cross(w, p)), atol=1e-12)
        assert np.allclose(base[3:], turn.T @ w, atol=1e-12)
