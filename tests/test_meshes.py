"""The surfaces of rigid bodies (rodmol.meshes): a bad surface is refused naming
what is wrong where, before any property is computed; a good one gives the
analytic mass properties, in any pose and at any scale."""

import meshio
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial import ConvexHull, transform

import rodmol
from rodmol.meshes import check_surface, mesh_properties

# A cube of edge 1 centred on the origin: its six outward square faces, and each split in two.
_CORNERS = np.array([[(i >> 2) & 1, (i >> 1) & 1, i & 1] for i in range(8)], dtype=float) - 0.5
_SQUARES = np.array([[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]])
_CUBE = np.array([t for a, b, c, d in _SQUARES for t in ((a, b, c), (a, c, d))])
_STL_PROBE = pytest.mark.filterwarnings("ignore:overflow encountered:RuntimeWarning")  # meshio's binary-STL probe


def _stl(tmp_path, points, triangles, name="body.stl"):
    path = tmp_path / name
    meshio.write(path, meshio.Mesh(points, [("triangle", np.asarray(triangles))]), binary=False)
    return path


def _refused(tmp_path, points, triangles, *words):
    """The message of from_mesh refusing the surface, checked to name the file and ``words``."""
    path = _stl(tmp_path, points, triangles)
    with pytest.raises(rodmol.ParameterError) as caught:
        rodmol.RigidBody.from_mesh(path, 1000.0)
    message = str(caught.value)
    assert str(path) in message
    for word in words:
        assert word in message
    return message


@_STL_PROBE
def test_a_tenth_of_a_metre_cube_of_water_has_the_analytic_mass_and_inertia(tmp_path):
    body = rodmol.RigidBody.from_mesh(_stl(tmp_path, 0.1 * _CORNERS + (1.0, 2.0, 3.0), _CUBE), 1000.0)
    assert body.mass == pytest.approx(1.0, rel=1e-12) and body.volume == pytest.approx(1e-3, rel=1e-12)
    np.testing.assert_allclose(body.centre_of_mass, (1.0, 2.0, 3.0), rtol=1e-12)
    np.testing.assert_allclose(body.inertia, np.eye(3) * 1.0 * 0.1**2 / 6.0, rtol=1e-10, atol=1e-16)


@_STL_PROBE
def test_a_cube_with_one_face_turned_inwards_is_refused_naming_it(tmp_path):
    turned = _CUBE.copy()
    turned[4:6] = turned[4:6, ::-1]  # the square x = -1/2: before, 0.667 kg instead of 1 kg
    _refused(tmp_path, 0.1 * _CORNERS, turned, "not consistently oriented", "faces 4, 5 are turned")


@_STL_PROBE
def test_a_cube_with_two_triangles_missing_is_refused_as_open(tmp_path):
    message = _refused(tmp_path, 0.1 * _CORNERS, _CUBE[2:], "the surface is open", "borders no other face")
    assert "(4 such edges)" in message  # before: 0.833 kg instead of 1 kg


def test_a_face_index_out_of_range_is_refused_naming_the_face():
    faces = _CUBE.copy()
    faces[7, 1] = 8  # before: a raw IndexError
    with pytest.raises(rodmol.ParameterError, match=r"the given vertices/faces: face 7 \(2, 8, 3\) refers to "
                                                    r"vertex 8, but the vertices are 0 to 7"):
        mesh_properties(_CORNERS, faces)
    faces[7, 1] = -1  # numpy would have taken the last vertex
    with pytest.raises(rodmol.ParameterError, match="face 7 .* vertex -1"):
        mesh_properties(_CORNERS, faces)


@_STL_PROBE
def test_a_non_manifold_surface_is_refused_at_its_edge(tmp_path):
    # Two cubes sharing an edge: four faces on it (before: blamed on `inertia`).
    second = _CORNERS + (1.0, 1.0, 0.0)
    points = np.vstack([_CORNERS, second])
    message = _refused(tmp_path, points, np.vstack([_CUBE, _CUBE + 8]), "not a manifold", "shared by 4 faces")
    assert "(0.5, 0.5, -0.5)" in message and "(0.5, 0.5, 0.5)" in message  # the shared edge's ends


def test_a_non_finite_vertex_is_refused_naming_it():
    points = _CORNERS.copy()
    points[3, 1] = np.nan  # before: "the mesh encloses no volume"
    with pytest.raises(rodmol.ParameterError, match=r"vertex 3 is not finite: \(-0.5, nan, 0.5\)"):
        mesh_properties(points, _CUBE)
    points[3, 1] = np.inf
    with pytest.raises(rodmol.ParameterError, match="vertex 3 is not finite"):
        mesh_properties(points, _CUBE)


@pytest.mark.parametrize("faces, words", [
    (np.vstack([_CUBE[:-1], [[1, 7, 7]]]), "face 11 (1, 7, 7) repeats vertex 7"),
    (_CUBE + 0.5, "must be whole vertex indices, face 0 is [0.5, 2.5, 3.5]"),
    (_CUBE[:, :2], "rows of 3 or more vertex indices"),
    (_CUBE[:0], "there are no faces"),
    (_CUBE.astype(bool), "must be whole vertex indices"),
    (5, "rows of 3 or more vertex indices, an (m, k) array, got shape ()"),
    ([[0, 1, 2], [0, [1, 2]]], "the faces must be rows of vertex indices, face 1 is [0, [1, 2]]"),
])
def test_faces_that_are_not_faces_are_refused(faces, words):
    with pytest.raises(rodmol.ParameterError) as caught:
        mesh_properties(_CORNERS, faces)
    assert words in str(caught.value)


def test_vertices_that_are_not_3d_points_are_refused():
    with pytest.raises(rodmol.ParameterError, match=r"3-D points, an \(n, 3\) array \[m\], got shape \(8, 2\)"):
        mesh_properties(_CORNERS[:, :2], _CUBE)


def test_whole_faces_of_another_number_type_are_taken():
    assert mesh_properties(_CORNERS, _CUBE.astype(float))[0] == pytest.approx(1.0)


def test_a_surface_turned_wholly_inwards_is_taken_turned_outwards():
    outward, inward = mesh_properties(_CORNERS, _CUBE), mesh_properties(_CORNERS, _CUBE[:, ::-1])
    for a, b in zip(outward, inward):
        np.testing.assert_allclose(a, b, rtol=1e-12, atol=1e-15)
    points, triangles = check_surface(_CORNERS, [_CUBE[:, ::-1]])
    a, b, c = (points[triangles[:, i]] for i in range(3))
    assert np.all(np.einsum("ij,ij->i", np.cross(b - a, c - a), a) > 0.0)  # drawn outward too


def test_a_flat_closed_sheet_encloses_no_volume():
    with pytest.raises(rodmol.ParameterError, match="encloses no volume: the closed shell of faces 0, 1 is flat"):
        mesh_properties(_CORNERS, [[0, 1, 2], [0, 2, 1]])


def test_quads_and_polygons_are_faces_from_a_file_and_from_arrays(tmp_path):
    meshio.write(tmp_path / "box.obj", meshio.Mesh(_CORNERS * (0.3, 0.2, 0.1), [("quad", _SQUARES)]))
    body = rodmol.RigidBody.from_mesh(tmp_path / "box.obj", 1000.0)  # before: "has no triangles"
    mass = 1000.0 * 0.3 * 0.2 * 0.1
    np.testing.assert_allclose(body.inertia, mass / 12 * np.diag([0.05, 0.1, 0.13]), rtol=1e-10, atol=1e-15)
    # A hexagonal prism: two hexagons and six quads, as ragged rows.
    angle = np.arange(6) * np.pi / 3
    ring = np.stack([np.cos(angle), np.sin(angle), np.zeros(6)], axis=1)
    points = np.vstack([ring, ring + (0.0, 0.0, 2.0)])
    faces = [list(range(5, -1, -1)), list(range(6, 12))] + [[i, (i + 1) % 6, 6 + (i + 1) % 6, 6 + i] for i in range(6)]
    volume, centre, _ = mesh_properties(points, faces)
    assert volume == pytest.approx(2.0 * 1.5 * np.sqrt(3.0), rel=1e-12)
    np.testing.assert_allclose(centre, (0.0, 0.0, 1.0), atol=1e-12)
    turned = [faces[0]] + [faces[1][::-1]] + faces[2:]
    with pytest.raises(rodmol.ParameterError, match="face 1 is turned against the rest"):
        mesh_properties(points, turned)


def test_an_unread_kind_of_face_or_no_faces_in_a_file_is_refused(tmp_path):
    six = np.hstack([_CUBE, _CUBE])  # (the numbers do not matter: refused before)
    meshio.write(tmp_path / "curved.vtu", meshio.Mesh(_CORNERS, [("triangle6", six)]))
    with pytest.raises(rodmol.ParameterError, match="curved.vtu' has triangle6 faces, which rodmol does not read"):
        rodmol.RigidBody.from_mesh(tmp_path / "curved.vtu", 1000.0)
    meshio.write(tmp_path / "solid.vtu", meshio.Mesh(_CORNERS[:4], [("tetra", np.array([[0, 1, 2, 4 - 1]]))]))
    with pytest.raises(rodmol.ParameterError, match="solid.vtu' has no faces .* it holds tetra cells"):
        rodmol.RigidBody.from_mesh(tmp_path / "solid.vtu", 1000.0)


def test_a_hollow_cube_is_the_outer_cube_less_its_cavity():
    inner = 0.5 * _CORNERS + (0.1, 0.0, 0.0)
    points = np.vstack([_CORNERS, inner])
    volume, centre, inertia = mesh_properties(points, np.vstack([_CUBE, _CUBE[:, ::-1] + 8]))  # cavity: faces in
    assert volume == pytest.approx(1.0 - 0.125, rel=1e-12)
    np.testing.assert_allclose(centre, (-0.125 * 0.1 / 0.875, 0.0, 0.0), atol=1e-14)
    shift = np.diag([0.0, 0.01, 0.01]) * 0.125  # the cavity's parallel-axis term about the origin
    about_origin = np.eye(3) / 6.0 - (0.125 * 0.25 * np.eye(3) / 6.0 + shift)
    moved = centre @ centre * np.eye(3) - np.outer(centre, centre)
    np.testing.assert_allclose(inertia, about_origin - volume * moved, rtol=1e-10, atol=1e-15)


@pytest.mark.parametrize("inner, words", [
    (0.5 * _CORNERS, "faces outwards but lies inside another shell"),  # a cavity with its faces outwards
    (0.5 * _CORNERS + (3.0, 0.0, 0.0), "faces inwards, which bounds a cavity, but lies inside no other shell"),
])
def test_shells_that_do_not_nest_as_a_solids_are_refused(inner, words):
    faces = np.vstack([_CUBE, (_CUBE if "outwards but" in words else _CUBE[:, ::-1]) + 8])
    with pytest.raises(rodmol.ParameterError) as caught:
        mesh_properties(np.vstack([_CORNERS, inner]), faces)
    assert words in str(caught.value) and "faces 12, 13, 14" in str(caught.value)


def _polyhedron(seed):
    """A random closed convex polyhedron (points, outward triangles) around the origin."""
    points = np.random.default_rng(seed).normal(size=(12, 3)) * (1.0, 0.6, 0.3)
    hull = ConvexHull(points)
    triangles = hull.simplices.copy()
    a, b, c = (points[triangles[:, i]] for i in range(3))
    inward = np.einsum("ij,ij->i", np.cross(b - a, c - a), a - points.mean(axis=0)) < 0.0
    triangles[inward] = triangles[inward][:, ::-1]
    return points, triangles, hull.volume


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), scale=st.floats(1e-3, 1e3),
       shift=st.tuples(*[st.floats(-10.0, 10.0)] * 3), turn=st.integers(0, 2**32 - 1))
def test_moved_and_scaled_polyhedra_carry_their_mass_properties_along(seed, scale, shift, turn):
    points, triangles, volume = _polyhedron(seed)
    rotation = transform.Rotation.random(random_state=turn).as_matrix()
    base = mesh_properties(points, triangles)
    assert base[0] == pytest.approx(volume, rel=1e-10)  # scipy's own hull volume
    moved = mesh_properties(scale * points @ rotation.T + np.array(shift), triangles)
    assert moved[0] == pytest.approx(scale**3 * base[0], rel=1e-10)
    size = scale * np.abs(points).max()
    np.testing.assert_allclose(moved[1], scale * rotation @ base[1] + shift, rtol=0, atol=1e-10 * (size + 10.0))
    expected = scale**5 * rotation @ base[2] @ rotation.T
    np.testing.assert_allclose(moved[2], expected, rtol=0, atol=1e-9 * np.abs(expected).max())


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), pick=st.integers(0, 10**6), remove=st.booleans())
def test_any_one_face_turned_or_removed_is_refused(seed, pick, remove):
    points, triangles, _ = _polyhedron(seed)
    face = pick % len(triangles)
    if remove:
        with pytest.raises(rodmol.ParameterError, match="the surface is open"):
            mesh_properties(points, np.delete(triangles, face, axis=0))
    else:
        triangles[face] = triangles[face][::-1]
        with pytest.raises(rodmol.ParameterError, match=f"face {face} is turned against the rest"):
            mesh_properties(points, triangles)
