"""Rigid bodies and systems on the problem floor: mass properties of meshes
against analytic values, and the checks of bodies, joints and systems."""

import meshio
import numpy as np
import pytest

import rodmol
from rodmol.bodies import mesh_properties

# A unit cube's 12 outward triangles, vertices indexed by the bits (x, y, z).
_CUBE = np.array([[0, 2, 3], [0, 3, 1], [4, 5, 7], [4, 7, 6], [0, 1, 5], [0, 5, 4],
                  [2, 6, 7], [2, 7, 3], [0, 4, 6], [0, 6, 2], [1, 3, 7], [1, 7, 5]])
_CORNERS = np.array([[(i >> 2) & 1, (i >> 1) & 1, i & 1] for i in range(8)], dtype=float)


@pytest.mark.filterwarnings("ignore:overflow encountered:RuntimeWarning")  # meshio's binary-STL size probe
def test_box_from_an_stl_file_has_the_analytic_mass_properties(tmp_path):
    size, corner, density = np.array([0.3, 0.2, 0.1]), np.array([1.0, -2.0, 0.5]), 700.0
    path = tmp_path / "box.stl"
    meshio.write(path, meshio.Mesh(corner + _CORNERS * size, [("triangle", _CUBE)]), binary=False)
    body = rodmol.RigidBody.from_mesh(path, density)
    a, b, c = size
    mass = density * a * b * c
    assert body.volume == pytest.approx(a * b * c, rel=1e-12)
    assert body.mass == pytest.approx(mass, rel=1e-12)
    np.testing.assert_allclose(body.centre_of_mass, corner + size / 2, rtol=1e-12)
    expected = mass / 12.0 * np.diag([b * b + c * c, a * a + c * c, a * a + b * b])
    np.testing.assert_allclose(body.inertia, expected, rtol=1e-9, atol=1e-12 * mass)


def test_corner_tetrahedron_matches_its_moments_and_ignores_orientation():
    # The tetrahedron (0, a e1, b e2, c e3): V = abc/6, centroid (a, b, c)/4,
    # integral of x^2 = a^3 bc/60, of xy = a^2 b^2 c/120 (about the origin).
    a, b, c = 0.5, 0.7, 1.1
    points = np.array([[0, 0, 0], [a, 0, 0], [0, b, 0], [0, 0, c]], dtype=float) + 0.25
    outward = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
    volume, centre, inertia = mesh_properties(points, outward)
    assert volume == pytest.approx(a * b * c / 6.0, rel=1e-12)
    np.testing.assert_allclose(centre, np.array([a, b, c]) / 4.0 + 0.25, rtol=1e-12)
    abc = a * b * c
    second = np.array([[a * a * abc / 60, a * b * abc / 120, a * c * abc / 120],
                       [a * b * abc / 120, b * b * abc / 60, b * c * abc / 120],
                       [a * c * abc / 120, b * c * abc / 120, c * c * abc / 60]])
    m = np.array([a, b, c]) / 4.0
    second -= volume * np.outer(m, m)  # about the centroid
    np.testing.assert_allclose(inertia, np.trace(second) * np.eye(3) - second, rtol=1e-10)
    flipped = mesh_properties(points, outward[:, ::-1])
    np.testing.assert_allclose(flipped[2], inertia, rtol=1e-12)
    assert flipped[0] == pytest.approx(volume)


def test_mass_matrix_about_the_origin_shifts_the_inertia_by_parallel_axes():
    c = np.array([0.1, -0.2, 0.05])
    body = rodmol.RigidBody(2.0, (0.01, 0.02, 0.03), centre_of_mass=c, added_mass=[1, 1, 1, 0, 0, 0])
    shifted = np.diag([0.01, 0.02, 0.03]) + 2.0 * (c @ c * np.eye(3) - np.outer(c, c))
    np.testing.assert_allclose(body.mass_matrix[3:, 3:], shifted)
    np.testing.assert_allclose(body.mass_matrix[:3, :3], 3.0 * np.eye(3))
    # The momentum of a body turning about its origin is m w x c.
    w = np.array([0.3, -1.0, 2.0])
    np.testing.assert_allclose(body.mass_matrix[:3, 3:] @ w, 2.0 * np.cross(w, c))


@pytest.mark.parametrize("kwargs, name", [
    (dict(mass=-1.0, inertia=(1, 1, 1)), "mass"),
    (dict(mass=1.0, inertia=(1, -1, 1)), "inertia"),
    (dict(mass=1.0, inertia=[[1, 0.5, 0], [0, 1, 0], [0, 0, 1]]), "inertia"),
    (dict(mass=1.0, inertia=(1, 1, 1), drag=(1, 1, 1)), "drag"),
    (dict(mass=1.0, inertia=(1, 1, 1), motion="floating"), "motion"),
    (dict(mass=1.0, inertia=(1, 1, 1), motion=rodmol.BaseMotion(), position=(1, 0, 0)), "position"),
])
def test_bad_bodies_are_refused_naming_the_parameter(kwargs, name):
    with pytest.raises(rodmol.ParameterError, match=name):
        rodmol.RigidBody(**kwargs)


def _arm(n=4):
    rod = rodmol.Rod(0.2, radius=0.01, material=rodmol.Material(E=1e5, nu=0.5, mu=100.0, rho=1000.0))
    return rodmol.Model(rod, n)


def test_system_graph_checks():
    head = rodmol.RigidBody(1.0, (1e-3, 1e-3, 1e-3))
    on_head = rodmol.Joint(("head", (0.1, 0, 0)), ("arm", "base"))
    system = rodmol.System({"arm": _arm()}, {"head": head}, [on_head])
    assert system.rods_on("head") == ["arm"]
    with pytest.raises(rodmol.ParameterError, match="'hed'.*did you mean 'head'"):
        rodmol.System({"arm": _arm()}, {"head": head}, [rodmol.Joint(("hed", (0, 0, 0)), ("arm", "base"))])
    with pytest.raises(rodmol.ParameterError, match="already jointed"):
        rodmol.System({"arm": _arm()}, {"head": head}, [on_head, rodmol.Joint("world", ("arm", "base"))])
    # A pinned base is clamped to a body of its own (named after the rod), pinned where the joint says.
    pinned = rodmol.System({"arm": _arm()}, {"head": head}, [rodmol.Joint(("head", (0.1, 0, 0)), ("arm", "base"),
                                                                          "pin")])
    assert pinned.base_bodies == {"arm": "arm.base"} and pinned.rods_on("arm.base") == ["arm"]
    (pin,) = pinned.body_joints
    assert (pin.a, pin.b, pin.kind, tuple(pin.point_b)) == ("arm.base", "head", "pin", (0.1, 0.0, 0.0))
    np.testing.assert_array_equal(pinned.bodies["arm.base"].position, (0.1, 0.0, 0.0))
    with pytest.raises(rodmol.ParameterError, match="'arm.base'.*taken"):
        rodmol.System({"arm": _arm()}, {"arm.base": head}, [rodmol.Joint("world", ("arm", "base"), "pin")])
    branched = rodmol.System({"arm": _arm(), "arm2": _arm()}, joints=[rodmol.Joint(("arm", "tip"), ("arm2", "base"))])
    (held,) = branched.penalty_joints  # arm2's base body held by arm's tip (tests/test_system_branches.py)
    assert branched.base_bodies == {"arm2": "arm2.base"} and (held.rod, held.body) == ("arm", "arm2.base")
    joined = rodmol.System({"arm": _arm(), "arm2": _arm()}, joints=[rodmol.Joint(("arm", "base"), ("arm2", "base"))])
    assert [(j.a, j.b) for j in joined.body_joints] == [("arm.base", "arm2.base")]  # two base bodies joined
    with pytest.raises(rodmol.ParameterError, match="to itself"):
        rodmol.System({"arm": _arm()}, joints=[rodmol.Joint(("arm", "tip"), ("arm", "tip"))])
    with pytest.raises(rodmol.ParameterError, match="velocity node"):
        rodmol.System({"arm": _arm()}, joints=[rodmol.Joint("world", ("arm", 0.07))])
    with pytest.raises(rodmol.ParameterError, match="'middle'"):
        rodmol.Joint("world", ("arm", "middle"))
    with pytest.raises(rodmol.ParameterError, match="stiffness"):
        rodmol.Joint("world", ("arm", "tip"), stiffness=-1.0)
    with pytest.raises(rodmol.ParameterError, match="eliminated"):
        rodmol.System({"arm": _arm()}, {"head": head}, [rodmol.Joint(("head", (0, 0, 0)), ("arm", "base"),
                                                                     stiffness=1e3)])
    # A tip held to the world is the rod's Hold; to a body, a Hold its assembly moves with the body.
    held = rodmol.System({"arm": _arm()}, {"head": head}, [rodmol.Joint("world", ("arm", "tip"), "pin"),
                                                           rodmol.Joint(("head", (0, 0, 0)), ("arm", 0.1))])
    assert [(h.s, h.kind, h.name) for h in held.rods["arm"].loads] == [(0.2, "pin", "joints[0]"),
                                                                      (0.1, "clamp", "joints[1]")]
    assert [(j.rod, j.load, j.body) for j in held.penalty_joints] == [("arm", 0, None), ("arm", 1, "head")]
    # Bodies join each other and the world at points that meet at rest, one of them free.
    fixed = rodmol.RigidBody(1.0, (1e-3, 1e-3, 1e-3), motion="fixed", position=(0.0, 0.3, 0.0))
    joined = rodmol.System({"arm": _arm()}, {"head": head, "wall": fixed},
                           [rodmol.Joint("world", ("head", (0, 0, 0))),
                            rodmol.Joint(("head", (0.0, 0.1, 0.0)), ("wall", (0.0, -0.2, 0.0)), "pin")])
    assert [(j.a, j.b, j.kind) for j in joined.body_joints] == [("head", None, "clamp"), ("head", "wall", "pin")]
    with pytest.raises(rodmol.ParameterError, match="0.1 m apart"):
        rodmol.System({"arm": _arm()}, {"head": head, "wall": fixed},
                      [rodmol.Joint(("head", (0.0, 0.1, 0.0)), ("wall", (0.0, -0.1, 0.0)))])
    with pytest.raises(rodmol.ParameterError, match="neither of which is free"):
        rodmol.System({"arm": _arm()}, {"wall": fixed}, [rodmol.Joint(("wall", (0, 0, 0)), "world")])
    with pytest.raises(rodmol.ParameterError, match="to itself"):
        rodmol.System({"arm": _arm()}, {"head": head}, [rodmol.Joint(("head", (0, 0, 0)), ("head", (0, 0, 0)))])
    with pytest.raises(rodmol.ParameterError, match="'head' is used twice, by a rod and a body"):
        rodmol.System({"head": _arm()}, {"head": head})
    with pytest.raises(rodmol.ParameterError, match="`bodies`: the name 'world' is reserved"):
        rodmol.System({"arm": _arm()}, {"world": head})
    moving = _arm().replace(base=rodmol.BaseMotion(velocity=lambda t: (0, 0, 0)))
    with pytest.raises(rodmol.ParameterError, match="`base` must be the default"):
        rodmol.System({"arm": moving}, {"head": head}, [on_head])


def test_a_bodys_pose_inertia_and_mesh_options_are_refused_by_their_own_names(tmp_path):
    path = tmp_path / "box.stl"
    meshio.write(path, meshio.Mesh(_CORNERS * 0.1, [("triangle", _CUBE)]), binary=False)
    with pytest.raises(rodmol.ParameterError, match="`mass` comes from the mesh"):
        rodmol.RigidBody.from_mesh(path, 1000.0, mass=2.0)
    with pytest.raises(rodmol.ParameterError, match="`position` must have three components"):
        rodmol.RigidBody(1.0, (1.0, 1.0, 1.0), position=(0.0, 0.0))
    with pytest.raises(rodmol.ParameterError, match="`rotation` must be a rotation matrix"):
        rodmol.RigidBody(1.0, (1.0, 1.0, 1.0), rotation=2 * np.eye(3))
    with pytest.raises(rodmol.ParameterError, match=r"I_i <= I_j \+ I_k"):  # no rigid body has these
        rodmol.RigidBody(1.0, (1.0, 1.0, 5.0))
    rodmol.RigidBody(1.0, (1.0, 1.0, 2.0))  # a flat plate's: the limit
    with pytest.raises(rodmol.ParameterError, match="`joint end a rotation` must be a rotation matrix"):
        rodmol.System({"arm": rodmol.paper_arm(4)}, {"head": rodmol.RigidBody(1.0, (1.0, 1.0, 1.0))},
                      [rodmol.Joint(("head", (0.0, 0.0, 0.0), np.ones((3, 3))), ("arm", "base"))])


_FLOOR = rodmol.PlaneContact((0.0, 0.0, 0.0), (0.0, 0.0, 1.0), stiffness=1e4)


@pytest.mark.parametrize("kwargs, message", [
    (dict(contacts=_FLOOR, contact_points=[(0, 0, 0)]), "`contacts` must be a sequence"),
    (dict(contacts=[rodmol.PointForce(0.0, (1, 0, 0))], contact_points=[(0, 0, 0)]), r"`contacts\[0\]`"),
    (dict(contacts=[_FLOOR]), "`contacts` need `contact_points`"),
    (dict(contacts=[_FLOOR], contact_points=[(0, 0)]), r"`contact_points` must be \(n, 3\)"),
    (dict(contacts=[_FLOOR], contact_points=[(0, 0, 0)] * 2, contact_radius=(0.1, 0.1, 0.1)), "`contact_radius`"),
    (dict(contacts=[_FLOOR], contact_points=[(0, 0, 0)], contact_radius=-0.1), "`contact_radius` must be >= 0"),
    (dict(contacts=[_FLOOR], contact_points=[(0, 0, 0)]), "give the contacts a `smoothing_depth`"),
    (dict(contacts=[_FLOOR], contact_points=[(0, 0, 0)], contact_radius=0.1, motion="fixed"), "free body only"),
])
def test_bad_contacts_are_refused_naming_the_parameter(kwargs, message):
    with pytest.raises(rodmol.ParameterError, match=message):
        rodmol.RigidBody(1.0, (1.0, 1.0, 1.0), **kwargs)


@pytest.mark.filterwarnings("ignore:overflow encountered:RuntimeWarning")  # meshio's binary-STL size probe
def test_a_meshed_body_touches_by_its_vertices_smoothed_over_its_size(tmp_path):
    path = tmp_path / "box.stl"
    meshio.write(path, meshio.Mesh(_CORNERS * 0.1, [("triangle", _CUBE)]), binary=False)
    body = rodmol.RigidBody.from_mesh(path, 1000.0, contacts=[_FLOOR], contact_points="vertices")
    np.testing.assert_allclose(np.unique(body.contact_points, axis=0), np.unique(_CORNERS * 0.1, axis=0))
    np.testing.assert_array_equal(body.contact_radius, np.zeros(8))
    # The corners are 0.1 * sqrt(3) / 2 from their centroid: 1% of that is the default smoothing.
    assert body.contact_smoothing == pytest.approx(0.01 * 0.1 * np.sqrt(3) / 2, rel=1e-12)
