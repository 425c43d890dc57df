"""Closed surfaces bounding a rigid body: read from a mesh file, checked, and the
mass properties of the solid they bound.

Every surface passes :func:`check_surface` before anything is computed from it:
finite vertices; faces of three or more distinct vertices, indexed within the
vertices; closed and manifold (every edge shared by exactly two faces);
consistently oriented (the two faces of an edge run along it in opposite
directions); enclosing a positive volume. A surface whose every face points
inwards is turned outwards (the solid it bounds is unambiguous); a shell with
its faces turned inwards is a cavity only inside another shell. Faces and
vertices are numbered from 0, in the order meshio reads them from the file.
"""

import numpy as np

from . import _checks
from .errors import ParameterError

#: What a surface given as arrays is called in messages.
GIVEN = "the given vertices/faces"
#: meshio's cell types read as faces (other cells, points, lines and volumes, are left out).
FACE_CELLS = ("triangle", "quad", "polygon")
#: Faces named at most in a message.
NAMED = 8
#: Cancellation in the signed volume [relative to the sum of its terms' sizes]
#: below which a shell encloses no volume (a flat, two-sided sheet).
FLAT = 1e-10


def read_surface(path):
    """The checked surface in the mesh file ``path`` (any format meshio reads):
    (points (n, 3) [m], triangles (m, 3), outward); see :func:`check_surface`."""
    import meshio

    source = f"the mesh `path` {str(path)!r}"
    try:
        mesh = meshio.read(path)
    except Exception as exc:  # noqa: BLE001 (any reader failure, named with the file)
        raise ParameterError(f"cannot read {source}: {exc}") from exc
    unread = sorted({b.type for b in mesh.cells if b.type not in FACE_CELLS and getattr(b, "dim", None) == 2})
    if unread:
        raise ParameterError(f"{source} has {', '.join(unread)} faces, which rodmol does not read: "
                             f"give its surface as {', '.join(FACE_CELLS)} cells")
    faces = [b.data for b in mesh.cells if b.type in FACE_CELLS]
    if not faces:
        found = sorted({b.type for b in mesh.cells})
        raise ParameterError(f"{source} has no faces ({', '.join(FACE_CELLS)} cells); it holds "
                             f"{', '.join(found) + ' cells' if found else 'no cells'}")
    return check_surface(mesh.points, faces, source)


def mesh_properties(points, faces):
    """Volume [m^3], centroid (3,) [m] and inertia tensor per unit density
    (3, 3) [m^5] about the centroid of the solid bounded by a closed surface:
    ``points`` (n, 3), ``faces`` (m, k) vertex indices (triangles, k = 3, or
    polygons), checked first (:func:`check_surface`; a surface turned inwards
    is taken turned outwards)."""
    return solid_properties(*check_surface(points, [faces], GIVEN))


def solid_properties(points, triangles):
    """:func:`mesh_properties` of a surface :func:`check_surface` returned.

    By the divergence theorem every integral is a sum over the tetrahedra
    spanned by a reference point and each triangle: det/6 for the volume,
    det/24 (a + b + c) for the first moment, det/120 (sum of v v^T + s s^T,
    s = a + b + c) for the second moment. The reference is the vertices' mean,
    so a body far from the origin loses no digits.
    """
    origin, (a, b, c), det = _tetrahedra(points, triangles)
    volume = det.sum() / 6.0
    s = a + b + c
    centre = (det[:, None] * s).sum(axis=0) / 24.0 / volume
    second = sum(np.einsum("t,ti,tj->ij", det, v, v) for v in (a, b, c, s)) / 120.0
    second -= volume * np.outer(centre, centre)  # about the centroid
    inertia = np.trace(second) * np.eye(3) - second
    return volume, origin + centre, 0.5 * (inertia + inertia.T)


def _tetrahedra(points, triangles):
    """The tetrahedra spanned by the vertices' mean and each triangle: (the mean (3,),
    the corners (a, b, c) relative to it, each (m, 3), six times their signed volumes (m,))."""
    origin = points[np.unique(triangles)].mean(axis=0)
    a, b, c = (points[triangles[:, i]] - origin for i in range(3))
    return origin, (a, b, c), np.einsum("ij,ij->i", a, np.cross(b, c))


def check_surface(points, faces, source=GIVEN):
    """``points`` (n, 3) and ``faces`` (a list of blocks, each (m_i, k_i) vertex
    indices, k_i >= 3) checked to bound a solid (see the module); returns
    (points (n, 3) float, triangles (m, 3) int64), the polygons split into
    triangles and every face outward. A :class:`ParameterError` names ``source``
    and the first problem with its face, edge or vertex."""
    points = _points(points, source)
    blocks = _blocks(faces, len(points), source)
    pairs = _shared(points, blocks, source)
    triangles = np.vstack([_fan(block) for block in blocks])
    owner = np.concatenate([np.repeat(np.arange(len(block)) + first, block.shape[1] - 2)
                            for first, block in _numbered(blocks)])
    return points, _outward(points, triangles, owner, pairs, source)


def _points(points, source):
    try:
        points = np.asarray(points, dtype=float)
    except (TypeError, ValueError) as exc:
        raise ParameterError(f"{source}: the vertices must be numbers, an (n, 3) array [m]: {exc}") from None
    if points.ndim != 2 or points.shape[1] != 3 or not len(points):
        raise ParameterError(f"{source}: the vertices must be 3-D points, an (n, 3) array [m], "
                             f"got shape {points.shape}")
    bad = np.flatnonzero(~np.all(np.isfinite(points), axis=1))
    if len(bad):
        raise ParameterError(f"{source}: vertex {bad[0]} is not finite: {tuple(points[bad[0]].tolist())}"
                             f"{_more(bad, 'vertices')}")
    return points


def _blocks(faces, n, source):
    """The faces as (m_i, k_i) int64 arrays of k_i >= 3 distinct vertex indices below ``n``;
    a block of faces of several sizes is split by size (the faces' numbers kept)."""
    blocks, first = [], 0
    for given in faces:
        try:
            array = np.asarray(given)
        except ValueError:  # ragged: faces of several sizes
            array = None
        for block in _by_size(given, first, source) if array is None or array.dtype == object else [array]:
            block = _indices(block, first, source)
            if block.ndim != 2 or block.shape[1] < 3:
                raise ParameterError(f"{source}: the faces must be rows of 3 or more vertex indices, an (m, k) "
                                     f"array, got shape {block.shape} from face {first}")
            blocks.append(block)
            first += len(block)
    if not first:
        raise ParameterError(f"{source}: there are no faces")
    for first, block in _numbered(blocks):
        outside = np.flatnonzero(np.any((block < 0) | (block >= n), axis=1))
        if len(outside):
            face = block[outside[0]]
            index = face[(face < 0) | (face >= n)][0]
            raise ParameterError(f"{source}: face {first + outside[0]} {tuple(face.tolist())} refers to vertex "
                                 f"{index}, but the vertices are 0 to {n - 1}{_more(outside, 'faces')}")
        ordered = np.sort(block, axis=1)
        repeats = np.flatnonzero(np.any(ordered[:, 1:] == ordered[:, :-1], axis=1))
        if len(repeats):
            face = block[repeats[0]].tolist()
            twice = next(v for v in face if face.count(v) > 1)
            raise ParameterError(f"{source}: face {first + repeats[0]} {tuple(face)} repeats vertex {twice}: "
                                 f"a face needs distinct corners{_more(repeats, 'faces')}")
    return blocks


def _by_size(rows, first, source):
    """Runs of rows (faces ``first``, ...) of one length, each as an array (the rows' order kept)."""
    runs = []
    for i, row in enumerate(rows):
        try:
            row = np.asarray(row)
        except ValueError:
            raise ParameterError(f"{source}: the faces must be rows of vertex indices, face {first + i} is "
                                 f"{_checks.short(row)}") from None
        if runs and runs[-1][-1].shape == row.shape:
            runs[-1].append(row)
        else:
            runs.append([row])
    return [np.stack(run) for run in runs]


def _indices(block, first, source):
    """``block`` (faces ``first``, ...) as int64 indices: whole numbers, of any number type."""
    block = np.asarray(block)
    if _whole(block):
        return block.astype(np.int64)
    rows = block.reshape(len(block), -1) if block.ndim else block.reshape(1, 1)
    bad = next((i for i, row in enumerate(rows) if not _whole(row)), 0)
    raise ParameterError(f"{source}: the faces must be whole vertex indices, face {first + bad} is "
                         f"{rows[bad].tolist()!r}")


def _whole(values):
    if values.dtype.kind in "iu":
        return True
    return values.dtype.kind == "f" and bool(np.all(np.isfinite(values)) and np.all(values == np.rint(values)))


def _numbered(blocks):
    """(number of its first face, block) of each block."""
    starts = np.cumsum([0] + [len(b) for b in blocks[:-1]])
    return list(zip(starts.tolist(), blocks))


def _shared(points, blocks, source):
    """The two faces meeting at each edge, (e, 2), once every edge is found shared by
    exactly two faces running along it in opposite directions."""
    tails = np.concatenate([b.ravel() for b in blocks])
    heads = np.concatenate([np.roll(b, -1, axis=1).ravel() for b in blocks])
    owners = np.concatenate([np.repeat(np.arange(len(b)) + first, b.shape[1]) for first, b in _numbered(blocks)])
    low, high = np.minimum(tails, heads), np.maximum(tails, heads)
    order = np.lexsort((owners, high, low))
    low, high, tails, heads, owners = (v[order] for v in (low, high, tails, heads, owners))
    starts = np.flatnonzero(np.r_[True, (low[1:] != low[:-1]) | (high[1:] != high[:-1])])
    counts = np.diff(np.r_[starts, len(low)])

    def edge(i):
        return f"the edge between {_vertex(points, low[starts[i]])} and {_vertex(points, high[starts[i]])}"

    crowded = np.flatnonzero(counts > 2)
    if len(crowded):
        i = crowded[0]
        faces = owners[starts[i]:starts[i] + counts[i]]
        raise ParameterError(f"{source}: the surface is not a manifold: {edge(i)} is shared by {counts[i]} "
                             f"faces ({_list(faces)}), where a closed surface has two{_more(crowded, 'edges')}")
    lone = np.flatnonzero(counts == 1)
    if len(lone):
        i = lone[0]
        raise ParameterError(f"{source}: the surface is open: {edge(i)} of face {owners[starts[i]]} borders no "
                             f"other face{_more(lone, 'edges')}: a hole or a missing face; a body needs a closed "
                             "surface")
    pairs = np.stack([owners[starts], owners[starts + 1]], axis=1)
    same = tails[starts] == tails[starts + 1]
    if np.any(same):
        i = np.flatnonzero(same)[0]
        turned = _turned(pairs, same)
        what = ("the surface cannot be oriented (it is one-sided)" if turned is None else
                f"face{_s(turned)} {_list(turned)} {'are' if len(turned) > 1 else 'is'} turned against the "
                "rest (listed with its vertices the other way round)")
        raise ParameterError(f"{source}: the faces are not consistently oriented: faces {pairs[i, 0]} and "
                             f"{pairs[i, 1]} both run from {_vertex(points, tails[starts[i]])} to "
                             f"{_vertex(points, heads[starts[i]])}, where the two faces of an edge run "
                             f"along it opposite ways; {what}")
    return pairs


def _turned(pairs, same):
    """The faces to turn to orient the surface consistently (in each connected part, the
    fewer of its two sides), or None if it cannot be oriented. Only for messages: a loop
    over the faces."""
    from scipy.sparse.csgraph import breadth_first_order, connected_components

    graph = _adjacency(pairs)
    n_parts, part = connected_components(graph, directed=False)
    flips = {}
    for (f, g), flip in zip(pairs.tolist(), same.tolist()):
        flips[f, g] = flips[g, f] = flip
    side = np.zeros(graph.shape[0], dtype=bool)  # True: turned against the part's first face
    for k in range(n_parts):
        order, before = breadth_first_order(graph, int(np.argmax(part == k)), directed=False)
        for face in order[1:].tolist():
            side[face] = side[before[face]] ^ flips[int(before[face]), face]
    if np.any((side[pairs[:, 0]] ^ side[pairs[:, 1]]) != same):
        return None
    turned = []
    for k in range(n_parts):
        members = np.flatnonzero(part == k)
        one, other = members[side[members]], members[~side[members]]
        turned.extend((one if len(one) <= len(other) else other).tolist())
    return sorted(turned)


def _adjacency(pairs):
    """The faces' graph: the two faces of each edge joined."""
    from scipy.sparse import coo_matrix

    n = int(pairs.max()) + 1
    return coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(n, n)).tocsr()


def _fan(block):
    """The triangles of the faces of ``block``, face after face (a fan from each one's first vertex)."""
    corners = [[0, j, j + 1] for j in range(1, block.shape[1] - 1)]
    return block[:, corners].reshape(-1, 3)


def _outward(points, triangles, owner, pairs, source):
    """``triangles`` all outward, once each closed shell is found to enclose a volume, facing
    out of the solid (a shell facing in bounds a cavity inside another shell). ``owner``: the
    face of each triangle; ``pairs``: the two faces of each edge."""
    from scipy.sparse.csgraph import connected_components

    n_shells, shell = connected_components(_adjacency(pairs), directed=False)
    det = _tetrahedra(points, triangles)[2]
    of = shell[owner]  # each triangle's shell
    volumes = np.bincount(of, det, n_shells) / 6.0
    sizes = np.bincount(of, np.abs(det), n_shells) / 6.0
    flat = np.flatnonzero(np.abs(volumes) <= FLAT * sizes)
    if len(flat):
        faces = np.flatnonzero(shell == flat[0])
        raise ParameterError(f"{source}: the surface encloses no volume: the closed shell of face{_s(faces)} "
                             f"{_list(faces)} is flat (two sides of one sheet?)")
    if volumes.sum() < 0.0:  # every face points in: the solid is still the one bounded
        triangles, volumes = triangles[:, ::-1], -volumes
    if n_shells > 1:
        _nested(points, triangles, of, shell, volumes, source)
    return triangles


def _nested(points, triangles, of, shell, volumes, source):
    """Refuse shells that do not nest as a solid's do: the other shells wind around a shell
    facing out 0 times (it bounds a piece of the solid) and one facing in once (a cavity)."""
    for k, volume in enumerate(volumes):
        own = triangles[of == k]
        probe = points[own[0]].mean(axis=0)  # a point of the shell only (shells may share a vertex)
        winding = _winding(points, triangles[of != k], probe)
        expected = 0 if volume > 0.0 else 1
        if round(winding) != expected:
            faces = np.flatnonzero(shell == k)
            if volume > 0.0:
                what = "faces outwards but lies inside another shell (overlapping shells?)"
            else:
                what = ("faces inwards, which bounds a cavity, but lies inside no other shell: list its faces' "
                        "vertices the other way round")
            raise ParameterError(f"{source}: the closed shell of face{_s(faces)} {_list(faces)} {what}")


def _winding(points, triangles, probe):
    """How many times the oriented ``triangles`` wind around the point ``probe`` (their
    solid angle over 4 pi, Van Oosterom and Strackee's formula)."""
    a, b, c = (points[triangles[:, i]] - probe for i in range(3))
    la, lb, lc = (np.linalg.norm(v, axis=1) for v in (a, b, c))
    det = np.einsum("ij,ij->i", a, np.cross(b, c))
    div = la * lb * lc + np.einsum("ij,ij->i", a, b) * lc + np.einsum("ij,ij->i", b, c) * la
    div += np.einsum("ij,ij->i", c, a) * lb
    return float(np.sum(2.0 * np.arctan2(det, div)) / (4.0 * np.pi))


def _vertex(points, i):
    return f"vertex {int(i)} ({', '.join(f'{x:.6g}' for x in points[int(i)])})"


def _list(faces):
    faces = [int(f) for f in faces]
    shown = ", ".join(map(str, faces[:NAMED]))
    return shown + (f", ... ({len(faces)} in all)" if len(faces) > NAMED else "")


def _more(found, what):
    """`` (N such <what>)`` when more than one was ``found``."""
    return f" ({len(found)} such {what})" if len(found) > 1 else ""


def _s(items):
    return "s" if len(items) > 1 else ""
