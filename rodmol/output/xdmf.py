"""XDMF3 views of the streamed frames, for ParaView (``Xdmf3ReaderS``).

``rod.xdmf``, ``cables.xdmf`` and ``markers.xdmf`` are temporal collections
with moving geometry. They hold no data: each includes (XInclude) the grids
of every chunk from ``frames/chunk_NNNNNN.xmf``, and every grid points into
its chunk's HDF5 file (the group ``view``, in single precision) with XDMF3's compact hyperslab form
``file.h5:/name|start:stride:count:dimensions`` (one frame of a time-first
dataset; the nested ``ItemType="HyperSlab"`` form gave empty grids in
ParaView 5.11). So a view is small, is replaced atomically after each chunk,
and the writing stays linear in the number of frames.

The rod is one polyline cell with the point arrays of
:data:`rodmol.output.parts.ROD_ARRAYS` plus ``s [m]``, ``radius [m]`` (for the
Tube filter), ``velocity (global) [m/s]`` and the frame vectors
``frame x/y/z [-]`` (columns of the rotation, global). The cables are
two-point segments with ``tension [N]`` (point and cell data), ``s [m]`` and
``cable index [-]``; the markers are vertices with ``s [m]`` and
``marker index [-]``. ParaView reads these as unstructured grids: apply
*Extract Surface* before *Tube*.
"""

import html
from pathlib import Path

import numpy as np

from .._files import write_atomically
from ..discretise.rotations import rotate
from . import h5result
from .h5result import VIEW, VIEW_GROUP
from .parts import PARTS, ROD_ARRAYS, cable_arc_lengths, cable_point_array

VIEWS = PARTS  # one view per drawn part
HEADER = '<?xml version="1.0" encoding="utf-8"?>\n<Xdmf Version="3.0"{ns}>\n<Domain>\n'
FOOTER = "</Domain>\n</Xdmf>\n"
XI = ' xmlns:xi="http://www.w3.org/2001/XInclude"'
#: The number type of every floating view array.
FLOAT = f'NumberType="Float" Precision="{np.dtype(VIEW).itemsize}"'

#: Placeholders of a grid's frame index and time in a grid template.
K, T = "@K@", "@T@"


def _frames(template, t):
    """The grid ``template`` (one text for all frames) at each frame of the chunk's views: encoded
    lines."""
    pieces = [part.split(K.encode()) for part in (template + "\n").encode().split(T.encode())]  # joined: fastest
    return [repr(float(tk)).encode().join(str(k).encode().join(piece) for piece in pieces) for k, tk in enumerate(t)]


def _item(h5, name, dims, n_frames=None, integer=False):
    """A DataItem of the view array ``name`` in ``h5``: static (floating or ``integer``), or with
    ``n_frames`` the frame K of a time-first floating array (floats: :data:`h5result.VIEW`)."""
    kind = 'NumberType="Int" Precision="8"' if integer else FLOAT
    where = f"{h5}:/{VIEW_GROUP}/{name}"
    if n_frames is not None:
        rank = len(dims) + 1
        start = " ".join([K] + ["0"] * (rank - 1))
        stride = " ".join(["1"] * rank)
        count = " ".join(["1"] + [str(c) for c in dims])
        where += f"|{start}:{stride}:{count}:{' '.join(str(d) for d in (n_frames, *dims))}"
    return f'<DataItem Dimensions="{" ".join(str(d) for d in dims)}" {kind} Format="HDF">{where}</DataItem>'


def _attribute(name, item, vector=False, center="Node"):
    kind = ' AttributeType="Vector"' if vector else ""
    return f'<Attribute Name="{name}"{kind} Center="{center}">{item}</Attribute>'


def rod_grids(h5, t, n_nodes):
    """Grids of the rod at the chunk's view frames, at times ``t``."""
    n, frames = n_nodes, len(t)
    parts = [f'<Grid Name="rod" GridType="Uniform"><Time Value="{T}"/>',
             f'<Topology TopologyType="Polyline" NodesPerElement="{n}" NumberOfElements="1">'
             f'{_item(h5, "rod_cells", (1, n), integer=True)}</Topology>',
             f'<Geometry GeometryType="XYZ">{_item(h5, "positions", (n, 3), frames)}</Geometry>',
             _attribute("s [m]", _item(h5, "s", (n,))), _attribute("radius [m]", _item(h5, "radius", (n,)))]
    for label, (attribute, _) in ROD_ARRAYS.items():
        parts.append(_attribute(label, _item(h5, attribute, (n, 3), frames), vector=True))
    parts.append(_attribute("velocity (global) [m/s]", _item(h5, "velocity_global", (n, 3), frames), vector=True))
    for i, axis in enumerate("xyz"):  # column i of the rotation: a one-wide hyperslab
        item = (f'<DataItem Dimensions="{n} 3" {FLOAT} Format="HDF">'
                f"{h5}:/{VIEW_GROUP}/rotations|{K} 0 0 {i}:1 1 1 1:1 {n} 3 1:{frames} {n} 3 3</DataItem>")
        parts.append(_attribute(f"frame {axis} [-]", item, vector=True))
    parts.append("</Grid>")
    return _frames("".join(parts), t)


def cable_grids(h5, t, n_points, n_segments):
    """Grids of the cables (two-point segments) at the chunk's view frames."""
    frames = len(t)
    grid = (f'<Grid Name="cables" GridType="Uniform"><Time Value="{T}"/>'
            f'<Topology TopologyType="Polyline" NodesPerElement="2" NumberOfElements="{n_segments}">'
            f'{_item(h5, "cable_cells", (n_segments, 2), integer=True)}</Topology>'
            f'<Geometry GeometryType="XYZ">{_item(h5, "cable_points", (n_points, 3), frames)}</Geometry>'
            + _attribute("s [m]", _item(h5, "cable_s", (n_points,)))
            + _attribute("cable index [-]", _item(h5, "cable_index", (n_points,), integer=True))
            + _attribute("cable index [-]", _item(h5, "cable_cell_index", (n_segments,), integer=True),
                         center="Cell")
            + _attribute("tension [N]", _item(h5, "cable_point_tension", (n_points,), frames))
            + _attribute("tension [N]", _item(h5, "cable_cell_tension", (n_segments,), frames), center="Cell")
            + "</Grid>")
    return _frames(grid, t)


def marker_grids(h5, t, n_markers):
    """Grids of the markers (vertices) at the chunk's view frames."""
    static = (f'<Topology TopologyType="Polyvertex" NodesPerElement="1" NumberOfElements="{n_markers}">'
              f'{_item(h5, "marker_cells", (n_markers, 1), integer=True)}</Topology>'
              + _attribute("s [m]", _item(h5, "marker_s", (n_markers,)))
              + _attribute("marker index [-]", _item(h5, "marker_index", (n_markers,), integer=True)))
    grid = (f'<Grid Name="markers" GridType="Uniform"><Time Value="{T}"/>{static}<Geometry GeometryType="XYZ">'
            f'{_item(h5, "markers", (n_markers, 3), len(t))}</Geometry></Grid>')
    return _frames(grid, t)


def body_grids(h5, t, key, n_points, n_triangles):
    """Grids of a rigid body (a triangulated surface, the view arrays ``KEY_points``,
    time-first, global, and ``KEY_triangles``) at the frames ``t``."""
    grid = (f'<Grid Name="{key}" GridType="Uniform"><Time Value="{T}"/>'
            f'<Topology TopologyType="Triangle" NumberOfElements="{n_triangles}">'
            f'{_item(h5, f"{key}_triangles", (n_triangles, 3), integer=True)}</Topology>'
            f'<Geometry GeometryType="XYZ">{_item(h5, f"{key}_points", (n_points, 3), len(t))}</Geometry></Grid>')
    return _frames(grid, t)


def fragment(views):
    """A chunk's grids, ``views`` (view name -> list of encoded grid lines), as an XDMF file's
    text (a list of encoded pieces: megabytes, not copied into one)."""
    text = [HEADER.format(ns="").encode()]
    for name, grids in views.items():
        text += [f'<Grid Name="{name}" GridType="Collection" CollectionType="Temporal">\n'.encode(), *grids,
                 b"</Grid>\n"]
    text.append(FOOTER.encode())
    return text


def rod_fragment(h5, t, fixed):
    """The XDMF text (:func:`fragment`) of a rod's chunk file ``h5`` (its path relative to the
    views) at times ``t``: the rod, and its cables and markers if ``fixed`` (:func:`static_views`)
    has them."""
    views = {"rod": rod_grids(h5, t, len(fixed["s"]))}
    if "cable_s" in fixed:
        views["cables"] = cable_grids(h5, t, len(fixed["cable_s"]), len(fixed["cable_cells"]))
    if "marker_s" in fixed:
        views["markers"] = marker_grids(h5, t, len(fixed["marker_s"]))
    return fragment(views)


def write_fragment(path, text):
    """Write a chunk's :func:`fragment` ``text`` to ``path``, atomically."""
    Path(path).parent.mkdir(parents=True, exist_ok=True)
    write_atomically(path, lambda handle: handle.writelines(text), buffering=1 << 20)  # few system calls


def write_view(path, name, fragments):
    """Write the view ``name`` including its grids from each fragment (relative paths), atomically."""
    write_collections(path, {name: name}, fragments)


def write_collections(path, collections, fragments):
    """Write a view file of several temporal collections, atomically: ``collections`` maps
    each collection's name (XML-escaped here) to the name of the collection in each
    fragment (relative paths) whose grids it includes (a plain name: it goes into an XPath)."""
    lines = [HEADER.format(ns=XI)]
    for name, included in collections.items():
        lines.append(f'<Grid Name="{html.escape(name, quote=True)}" GridType="Collection" '
                     'CollectionType="Temporal">\n')
        for fragment in fragments:
            lines.append(f'<xi:include href="{Path(fragment).as_posix()}" '
                         f"xpointer=\"xpointer(//Xdmf/Domain/Grid[@Name='{included}']/Grid)\"/>\n")
        lines.append("</Grid>\n")
    data = "".join(lines + [FOOTER]).encode()
    write_atomically(path, lambda handle: handle.write(data))


def static_views(static, meta):
    """The views' arrays that do not change in time, from the Result's ``static`` arrays
    and ``meta`` (the cables' and markers' arc lengths and cells)."""
    s = static["s"]
    fixed = {"s": s, "radius": static["radius"], "rod_cells": np.arange(len(s), dtype=np.int64)[None]}
    paths = cable_arc_lengths(s, meta)
    if paths:
        sizes = [len(path) for path in paths]
        starts = np.concatenate([[0], np.cumsum(sizes)])
        fixed.update(
            cable_s=np.concatenate(paths), cable_index=np.repeat(np.arange(len(sizes)), sizes),
            cable_cells=np.concatenate([np.stack([np.arange(a, b - 1), np.arange(a + 1, b)], axis=1)
                                        for a, b in zip(starts[:-1], starts[1:])]),
            cable_cell_index=np.concatenate([np.full(n - 1, i) for i, n in enumerate(sizes)]))
    markers = meta.get("markers", [])
    if markers:
        fixed.update(marker_cells=np.arange(len(markers), dtype=np.int64)[:, None],
                     marker_s=np.array([float(m["s"]) for m in markers]),
                     marker_index=np.arange(len(markers), dtype=np.int64))
    return fixed


def view_batches(fixed, s, meta, shown):
    """The views' arrays of the Result ``shown`` (the frames they show), in batches of
    :func:`h5result.write_chunk`: functions returning the rod's pose, the cables', the
    markers' arrays, and those that need the loads (:data:`rodmol.result.LOADS`): the
    rod's strains, velocities and loads. ``fixed``: :func:`static_views`; ``s``: the
    nodes' arc lengths [m]."""

    def pose():
        arrays = {key: fixed[key] for key in ("s", "radius", "rod_cells")}
        return h5result.views(dict(arrays, positions=shown.positions, rotations=shown.rotations))

    def cables():
        tension = np.asarray(shown.tensions, dtype=VIEW).reshape(len(shown.t), -1)
        points = cable_point_array(s, shown.positions, shown.rotations, meta, VIEW)
        arrays = {key: fixed[key] for key in ("cable_s", "cable_index", "cable_cells", "cable_cell_index")}
        return h5result.views(dict(arrays, cable_points=points, cable_point_tension=tension[:, fixed["cable_index"]],
                          cable_cell_tension=tension[:, fixed["cable_cell_index"]]))

    def markers():
        arrays = {key: fixed[key] for key in ("marker_cells", "marker_s", "marker_index")}
        return h5result.views(dict(arrays, markers=shown.markers))

    def motion():
        arrays = {attribute: getattr(shown, attribute) for attribute, _ in ROD_ARRAYS.values()}
        return h5result.views(dict(arrays, velocity_global=rotate(shown.rotations, shown.velocity)))

    return [pose] + ([cables] if "cable_s" in fixed else []) + ([markers] if "marker_s" in fixed else []), [motion]
