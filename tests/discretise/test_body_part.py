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


def test_an_assemblys_rods_read_the_bodys_motion():
    """The rods clamped to a free body take their base velocities from its velocities at every
    right-hand side: the arrays their kernels read are rows of the body's one buffer."""
    import rodmol
    from rodmol.discretise.assembly import Assembly

    mat = rodmol.Material(E=1e5, nu=0.5, mu=300.0, rho=1080.0)
    arm = rodmol.Model(rodmol.Rod(0.2, radius=0.01, material=mat), 4)
    head = rodmol.RigidBody(0.05, (2e-5, 3e-5, 4e-5))
    turn = np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])
    joints = [rodmol.Joint(("head", (0.02, 0.0, 0.0)), ("a", "base")),
              rodmol.Joint(("head", (0.0, 0.03, -0.01), turn), ("b", "base"))]
    assembly = Assembly(rodmol.System({"a": arm, "b": arm}, {"head": head}, joints))
    part = assembly.bodies["head"]
    y = assembly.undeformed_state()
    v, w = np.array([0.1, -0.2, 0.05]), np.array([0.3, 0.0, -0.4])
    y[part.fields["v"]], y[part.fields["w"]] = v, w
    assembly(0.0, y)
    for sd, p, rj in zip(part.systems, part.points, part.turns):
        assert any(a is sd.base_velocities for a in sd.kernel_arguments())
        assert np.allclose(sd.base_velocities, np.concatenate([rj.T @ (v + np.cross(w, p)), rj.T @ w]), atol=1e-15)
