"""What the two output formats (the streamed XDMF views and the per-frame
VTK series) draw of a frame: the parts, the rod's point arrays and the cable
paths."""

import numpy as np

from ..discretise import centreline

#: The drawn parts, one view or series each.
PARTS = ("rod", "cables", "markers")
#: Frames a view or series shows at most when ``every`` is not given: ParaView
#: 5.11 takes about a second per thousand frames to open an XDMF view
#: (docs/performance.md), and the result file keeps every frame anyway.
MAX_SHOWN = 6000


def view_step(n_frames, every=None):
    """Show every ``every``-th of ``n_frames`` output frames; by default all of
    them up to :data:`MAX_SHOWN`, else the smallest step that keeps within it."""
    return int(every) if every is not None else max(1, -(-int(n_frames) // MAX_SHOWN))


#: Point arrays of the centreline: VTK name -> (Result attribute, frame).
ROD_ARRAYS = {
    "linear strain [-]": ("linear_strain", "local"),
    "curvature [1/m]": ("curvature", "local"),
    "velocity [m/s]": ("velocity", "local"),
    "angular velocity [rad/s]": ("angular_velocity", "local"),
    "internal force [N]": ("internal_force", "local"),
    "internal moment [N m]": ("internal_moment", "local"),
    "external force [N/m]": ("external_force", "global"),
    "external moment [N m/m]": ("external_moment", "global"),
}


def cable_points(s_nodes, positions, rotations, meta):
    """Each cable's points at every frame given: a list of (s [m] (n,), points [m] (n_t, n, 3), global).

    The nodes with s below the anchor, then the anchor itself, with ``u + R p``
    interpolated linearly in s between the nodes around it.
    """
    points = cable_point_array(s_nodes, positions, rotations, meta)
    paths = cable_arc_lengths(s_nodes, meta)
    ends = np.cumsum([len(s) for s in paths])
    return [(s, points[:, end - len(s):end]) for s, end in zip(paths, ends)]


def cable_point_array(s_nodes, positions, rotations, meta, dtype=float):
    """The points of :func:`cable_points` of all cables in one array (n_t, n_points, 3) [m] of
    ``dtype``, global, cable after cable."""
    plan = _cable_plan(np.asarray(s_nodes, dtype=float), meta)
    if not plan:
        return np.empty((len(positions), 0, 3), dtype=dtype)
    return centreline.section_points(positions, rotations, *(np.concatenate([p[i] for p in plan]) for i in (1, 2, 3)),
                                     dtype=dtype)


def cable_arc_lengths(s_nodes, meta):
    """The arc lengths s [m] of each cable's points (those of :func:`cable_points`)."""
    return [plan[0] for plan in _cable_plan(np.asarray(s_nodes, dtype=float), meta)]


def _cable_plan(s_nodes, meta):
    """Per cable: (s of its points, the two nodes (n, 2) each point lies between, their
    weights (n, 2), the cable's offsets (local y, z) at those nodes (n, 2, 2))."""
    plan = []
    for cable in meta.get("cables", []):
        # The routing p(s) (local y, z) at the nodes; a constant offset in older results.
        offsets = np.broadcast_to(np.asarray(cable.get("node_offsets", [cable["offset"]]), dtype=float),
                                  (len(s_nodes), 2))
        anchor = min(float(cable["anchor"]), float(s_nodes[-1]))
        on_path = int(np.count_nonzero(s_nodes < anchor))  # the nodes below the anchor come first
        j, w = centreline.bracket(s_nodes, anchor)
        nodes = np.array([[i, i] for i in range(on_path)] + [[j, j + 1]], dtype=np.int64).reshape(-1, 2)
        weights = np.array([[1.0, 0.0]] * on_path + [[1.0 - w, w]]).reshape(-1, 2)
        plan.append((np.append(s_nodes[:on_path], anchor), nodes, weights, offsets[nodes]))
    return plan

