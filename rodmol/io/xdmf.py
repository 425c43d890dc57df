"""XDMF3 views of the streamed frames, for ParaView (``Xdmf3ReaderS``).

``rod.xdmf``, ``cables.xdmf`` and ``markers.xdmf`` are temporal collections
with moving geometry. They hold no data: each includes (XInclude) the grids
of every chunk from ``frames/chunk_NNNNNN.xmf``, and every grid points into
its chunk's HDF5 file with XDMF3's compact hyperslab form
``file.h5:/name|start:stride:count:dimensions`` (one frame of a time-first
dataset; the nested ``ItemType="HyperSlab"`` form gave empty grids in
ParaView 5.11). So a view is small, is replaced atomically after each chunk,
and the writing stays linear in the number of frames.

The rod is one polyline cell with the point arrays of
:data:`rodmol.io.parts.ROD_ARRAYS` plus ``s [m]``, ``radius [m]`` (for the
Tube filter), ``velocity (global) [m/s]`` and the frame vectors
``frame x/y/z [-]`` (columns of the rotation, global). The cables are
two-point segments with ``tension [N]`` (point and cell data), ``s [m]`` and
``cable index [-]``; the markers are vertices with ``s [m]`` and
``marker index [-]``. ParaView reads these as unstructured grids: apply
*Extract Surface* before *Tube*.
"""

from pathlib import Path

from .._files import write_atomically
from .parts import PARTS, ROD_ARRAYS

VIEWS = PARTS  # one view per drawn part
HEADER = '<?xml version="1.0" encoding="utf-8"?>\n<Xdmf Version="3.0"{ns}>\n<Domain>\n'
FOOTER = "</Domain>\n</Xdmf>\n"
XI = ' xmlns:xi="http://www.w3.org/2001/XInclude"'


#: Placeholders of a grid's frame index and time in a grid template.
K, T = "@K@", "@T@"


def _frames(template, t, frames):
    """The grid ``template`` (one text for all frames) at each chunk frame ``frames``."""
    return [template.replace(K, str(k)).replace(T, repr(float(t[k]))) for k in frames]


def _item(h5, name, dims, k=None, full=None, integer=False, single=False):
    """A DataItem of dataset ``name`` in ``h5``; with ``k``, the frame k of a time-first dataset
    (``single``: float32, the views' own arrays, see :data:`rodmol.io.stream.VIEW`)."""
    kind = 'NumberType="Int" Precision="8"' if integer else \
        f'NumberType="Float" Precision="{4 if single else 8}"'
    where = f"{h5}:/{name}"
    if k is not None:
        tail, rank = dims, len(full)
        start = " ".join([str(k)] + ["0"] * (rank - 1))
        stride = " ".join(["1"] * rank)
        count = " ".join(["1"] + [str(c) for c in tail])
        where += f"|{start}:{stride}:{count}:{' '.join(str(d) for d in full)}"
    return f'<DataItem Dimensions="{" ".join(str(d) for d in dims)}" {kind} Format="HDF">{where}</DataItem>'


def _attribute(name, item, vector=False, center="Node"):
    kind = ' AttributeType="Vector"' if vector else ""
    return f'<Attribute Name="{name}"{kind} Center="{center}">{item}</Attribute>'


def rod_grids(h5, t, frames, n_nodes, n_frames):
    """Grids of the rod at chunk frames ``frames`` (indices into the chunk of ``n_frames`` frames)."""
    n, full3 = n_nodes, (n_frames, n_nodes, 3)
    parts = [f'<Grid Name="rod" GridType="Uniform"><Time Value="{T}"/>',
             f'<Topology TopologyType="Polyline" NodesPerElement="{n}" NumberOfElements="1">'
             f'{_item(h5, "rod_cells", (1, n), integer=True)}</Topology>',
             f'<Geometry GeometryType="XYZ">{_item(h5, "positions", (n, 3), K, full3)}</Geometry>',
             _attribute("s [m]", _item(h5, "s", (n,))), _attribute("radius [m]", _item(h5, "radius", (n,)))]
    for label, (attribute, _) in ROD_ARRAYS.items():
        parts.append(_attribute(label, _item(h5, attribute, (n, 3), K, full3), vector=True))
    parts.append(_attribute("velocity (global) [m/s]", _item(h5, "velocity_global", (n, 3), K, full3, single=True),
                            vector=True))
    for i, axis in enumerate("xyz"):  # column i of the rotation: a one-wide hyperslab
        item = (f'<DataItem Dimensions="{n} 3" NumberType="Float" Precision="8" Format="HDF">'
                f"{h5}:/rotations|{K} 0 0 {i}:1 1 1 1:1 {n} 3 1:{n_frames} {n} 3 3</DataItem>")
        parts.append(_attribute(f"frame {axis} [-]", item, vector=True))
    parts.append("</Grid>")
    return _frames("".join(parts), t, frames)


def cable_grids(h5, t, frames, n_points, n_segments, n_frames):
    """Grids of the cables (two-point segments) at chunk frames ``frames``."""
    grid = (f'<Grid Name="cables" GridType="Uniform"><Time Value="{T}"/>'
            f'<Topology TopologyType="Polyline" NodesPerElement="2" NumberOfElements="{n_segments}">'
            f'{_item(h5, "cable_cells", (n_segments, 2), integer=True)}</Topology>'
            f'<Geometry GeometryType="XYZ">'
            f'{_item(h5, "cable_points", (n_points, 3), K, (n_frames, n_points, 3), single=True)}</Geometry>'
            + _attribute("s [m]", _item(h5, "cable_s", (n_points,)))
            + _attribute("cable index [-]", _item(h5, "cable_index", (n_points,), integer=True))
            + _attribute("cable index [-]", _item(h5, "cable_cell_index", (n_segments,), integer=True),
                         center="Cell")
            + _attribute("tension [N]", _item(h5, "cable_point_tension", (n_points,), K, (n_frames, n_points), single=True))
            + _attribute("tension [N]", _item(h5, "cable_cell_tension", (n_segments,), K,
                                              (n_frames, n_segments), single=True), center="Cell")
            + "</Grid>")
    return _frames(grid, t, frames)


def marker_grids(h5, t, frames, n_markers, n_frames):
    """Grids of the markers (vertices) at chunk frames ``frames``."""
    static = (f'<Topology TopologyType="Polyvertex" NodesPerElement="1" NumberOfElements="{n_markers}">'
              f'{_item(h5, "marker_cells", (n_markers, 1), integer=True)}</Topology>'
              + _attribute("s [m]", _item(h5, "marker_s", (n_markers,)))
              + _attribute("marker index [-]", _item(h5, "marker_index", (n_markers,), integer=True)))
    grid = (f'<Grid Name="markers" GridType="Uniform"><Time Value="{T}"/>{static}<Geometry GeometryType="XYZ">'
            f'{_item(h5, "markers", (n_markers, 3), K, (n_frames, n_markers, 3))}</Geometry></Grid>')
    return _frames(grid, t, frames)


def write_fragment(path, views):
    """Write a chunk's grids, ``views`` (view name -> list of grid texts), atomically."""
    text = [HEADER.format(ns="")]
    for name, grids in views.items():
        text.append(f'<Grid Name="{name}" GridType="Collection" CollectionType="Temporal">\n')
        text.extend(g + "\n" for g in grids)
        text.append("</Grid>\n")
    text.append(FOOTER)
    data = "".join(text).encode()
    write_atomically(path, lambda handle: handle.write(data))


def write_view(path, name, fragments):
    """Write the view ``name`` including its grids from each fragment (relative paths), atomically."""
    lines = [HEADER.format(ns=XI),
             f'<Grid Name="{name}" GridType="Collection" CollectionType="Temporal">\n']
    for fragment in fragments:
        lines.append(f'<xi:include href="{Path(fragment).as_posix()}" '
                     f"xpointer=\"xpointer(//Xdmf/Domain/Grid[@Name='{name}']/Grid)\"/>\n")
    lines.append("</Grid>\n" + FOOTER)
    data = "".join(lines).encode()
    write_atomically(path, lambda handle: handle.write(data))
