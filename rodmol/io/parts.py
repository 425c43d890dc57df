"""What the two output formats (the streamed XDMF views and the per-frame
VTK series) draw of a frame: the parts, the rod's point arrays and the cable
paths."""

import numpy as np

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
    paths = []
    for cable in meta.get("cables", []):
        # The routing p(s) (local y, z) at the nodes; a constant offset in older results.
        offsets = np.broadcast_to(np.asarray(cable.get("node_offsets", [cable["offset"]]), dtype=float),
                                  (len(s_nodes), 2))
        anchor = min(float(cable["anchor"]), float(s_nodes[-1]))
        on_path = int(np.count_nonzero(s_nodes < anchor))  # the nodes below the anchor come first
        s = np.append(s_nodes[:on_path], anchor)
        j = min(int(np.searchsorted(s_nodes, anchor, side="right")) - 1, len(s_nodes) - 2)
        used = slice(0, max(on_path, j + 2))
        points = (positions[:, used] + offsets[used, 0, None] * rotations[:, used, :, 1]
                  + offsets[used, 1, None] * rotations[:, used, :, 2])
        w = (anchor - s_nodes[j]) / (s_nodes[j + 1] - s_nodes[j])
        at_anchor = (1.0 - w) * points[:, j] + w * points[:, j + 1]
        paths.append((s, np.concatenate([points[:, :on_path], at_anchor[:, None]], axis=1)))
    return paths
