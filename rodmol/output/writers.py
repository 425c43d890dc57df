"""VTK time series for ParaView: ``.pvd`` collections of ``.vtp`` PolyData frames.

A series directory holds

* ``rod.pvd``: the centreline as one polyline per frame, with the point arrays
  listed in :data:`ROD_ARRAYS` (``radius [m]`` lets ParaView's Tube filter draw
  the true tapered body);
* ``cables.pvd``: each cable as a polyline at its true position ``u + R p``
  from the base to its anchor, with ``tension [N]``;
* ``markers.pvd``: the markers as points;
* ``vtk/``: the frame files (``rod_000012.vtp``, ...).

Each frame file is written completely before the ``.pvd`` that lists it is
extended (:mod:`rodmol.output.pvd`: valid at every moment, at a cost
proportional to the frames added), so an interrupted run leaves valid series
of the frames done. Vectors carry the Result's frames: strains, velocities and stresses in
local (material) components; positions, the frame vectors and the external
load densities (``external force [N/m]``, ``external moment [N m/m]``: point
and distributed loads and contact, see :mod:`rodmol.loads`) in global ones;
``velocity (global) [m/s]`` is the velocity in global components, for glyphs.
"""

import time
from pathlib import Path

import numpy as np

from .._files import claim, output_directory, refuse_directories
from ..discretise.rotations import rotate
from ..errors import ParameterError
from . import run_files
from .parts import PARTS, ROD_ARRAYS, cable_points, view_step
from .pvd import Collection, read_pvd, write_pvd  # noqa: F401  (read_pvd, write_pvd: of the series)

SUBDIRECTORY = run_files.SERIES


def polydata(points, lines=(), vertices=False, point_data=None, cell_data=None, field_data=None):
    """A pyvista PolyData built straight through VTK (several times faster than
    pyvista's setters, which matters when writing thousands of frames).

    ``lines`` is a list of point-index arrays, one polyline each; ``vertices``
    makes one vertex cell per point. Arrays are float (n,) or (n, 3); field
    data may also be lists of strings.
    """
    import pyvista as pv
    from vtkmodules.util.numpy_support import numpy_to_vtk, numpy_to_vtkIdTypeArray
    from vtkmodules.vtkCommonCore import vtkPoints, vtkStringArray
    from vtkmodules.vtkCommonDataModel import vtkCellArray, vtkPolyData

    def cells(groups):
        sizes = [len(g) for g in groups]
        offsets = np.concatenate([[0], np.cumsum(sizes)]).astype(np.int64)
        ids = np.concatenate(groups).astype(np.int64) if groups else np.zeros(0, np.int64)
        array = vtkCellArray()
        array.SetData(numpy_to_vtkIdTypeArray(offsets, deep=True), numpy_to_vtkIdTypeArray(ids, deep=True))
        return array

    def add(target, name, values):
        if len(values) and isinstance(values[0], str):
            array = vtkStringArray()
            for v in values:
                array.InsertNextValue(v)
        else:
            array = numpy_to_vtk(np.ascontiguousarray(values, dtype=float), deep=True)
        array.SetName(name)
        target.AddArray(array)

    mesh = vtkPolyData()
    vtk_points = vtkPoints()
    vtk_points.SetData(numpy_to_vtk(np.ascontiguousarray(points, dtype=float).reshape(-1, 3), deep=True))
    mesh.SetPoints(vtk_points)
    if len(lines):
        mesh.SetLines(cells([np.asarray(line) for line in lines]))
    if vertices:
        mesh.SetVerts(cells([[i] for i in range(len(points))]))
    for target, arrays in ((mesh.GetPointData(), point_data), (mesh.GetCellData(), cell_data),
                           (mesh.GetFieldData(), field_data)):
        for name, values in (arrays or {}).items():
            add(target, name, values)
    return pv.wrap(mesh)


def rod_mesh(result, k):
    """The centreline at frame ``k`` as a polyline (pyvista PolyData) with its point arrays."""
    rotation = result.rotations[k]
    data = {"s [m]": result.s, "radius [m]": result.radius}
    data.update({name: getattr(result, attribute)[k] for name, (attribute, _) in ROD_ARRAYS.items()})
    data["velocity (global) [m/s]"] = rotate(rotation[None], result.velocity[k][None])[0]
    data.update({f"frame {axis} [-]": rotation[:, :, i] for i, axis in enumerate("xyz")})
    return polydata(result.positions[k], lines=[np.arange(len(result.s))], point_data=data,
                    field_data={"time [s]": [float(result.t[k])]})


def cable_paths(result, k):
    """Each cable's points at frame ``k``: a list of (s [m] (n,), points [m] (n, 3), global)."""
    frame = slice(k, k + 1)
    return [(s, points[0]) for s, points in
            cable_points(result.s, result.positions[frame], result.rotations[frame], result.meta)]


def cables_mesh(result, k):
    """The cables at frame ``k`` as polylines (one cell each) with ``tension [N]``."""
    paths = cable_paths(result, k)
    sizes = [len(s) for s, _ in paths]
    starts = np.concatenate([[0], np.cumsum(sizes)])
    tension = result.tensions[k].reshape(-1)
    names = [c["name"] for c in result.meta.get("cables", [])]
    point_data = cell_data = None
    if paths:
        point_data = {"tension [N]": np.repeat(tension, sizes),
                      "s [m]": np.concatenate([s for s, _ in paths]),
                      "cable index [-]": np.repeat(np.arange(len(paths)), sizes)}
        cell_data = {"tension [N]": tension, "cable index [-]": np.arange(len(paths))}
    field_data = {"time [s]": [float(result.t[k])]}
    if names:
        field_data["cable names"] = names
    return polydata(np.vstack([pts for _, pts in paths]) if paths else np.zeros((0, 3)),
                    lines=[np.arange(a, b) for a, b in zip(starts[:-1], starts[1:])],
                    point_data=point_data, cell_data=cell_data, field_data=field_data)


def markers_mesh(result, k):
    """The markers at frame ``k`` as points, with ``s [m]`` and ``marker index [-]``."""
    info = result.meta.get("markers", [])
    point_data = {"s [m]": [float(m["s"]) for m in info], "marker index [-]": np.arange(len(info))}
    field_data = {"time [s]": [float(result.t[k])]}
    if info:
        field_data["marker names"] = [m["name"] for m in info]
    return polydata(np.asarray(result.markers[k], dtype=float).reshape(-1, 3), vertices=True,
                    point_data=point_data if info else None, field_data=field_data)


def save_vtp(mesh, path):
    """Write a PolyData with VTK's XML writer (raw appended binary, uncompressed: fastest)."""
    from vtkmodules.vtkIOXML import vtkXMLPolyDataWriter

    writer = vtkXMLPolyDataWriter()
    writer.SetFileName(str(path))
    writer.SetInputData(mesh)
    writer.SetDataModeToAppended()
    writer.EncodeAppendedDataOff()
    writer.SetCompressorTypeToNone()
    if not writer.Write():
        raise OSError(f"VTK could not write {str(path)!r}")


MESHES = {"rod": rod_mesh, "cables": cables_mesh, "markers": markers_mesh}


class SeriesWriter:
    """Writes frames of results into ParaView series, one frame at a time.

    Parameters
    ----------
    directory : path
        Created if needed. Series files of an earlier run there
        (``rod.pvd``, ``vtk/rod_*.vtp``, ...) are kept: refused unless
        ``overwrite``, which removes them first (:func:`rodmol._files.claim`).
    parts : sequence of str
        Which series to write: any of ``"rod"``, ``"cables"``, ``"markers"``.
    flush_interval : float
        The frames written are added to the collections after a frame if
        this many seconds [s, wall time] have passed since the last time (0:
        after every frame), and by :meth:`flush` / :meth:`close`; each time
        costs what it adds (:class:`rodmol.output.pvd.Collection`), so a long
        series is written in O(frames). The collections only ever list frames
        whose files are complete, and are valid at every moment.
    overwrite : bool
        Replace an earlier series in ``directory`` (False: refuse it).

    Every part starts as an empty collection; :meth:`write` adds one frame.
    Use it as a context manager, or call :meth:`close` at the end.
    """

    def __init__(self, directory, parts=PARTS, flush_interval=0.5, overwrite=False):
        unknown = [p for p in parts if p not in MESHES]
        if unknown:
            raise ParameterError(f"unknown `parts` {unknown}; valid are {list(PARTS)}")
        self.directory = output_directory(directory, "directory")
        self.parts = tuple(parts)
        series = [self.pvd(part) for part in PARTS] + run_files.numbered(self.directory, SUBDIRECTORY)
        claim(series, overwrite)
        (self.directory / SUBDIRECTORY).mkdir(exist_ok=True)
        self.frames, self.flush_interval = 0, float(flush_interval)
        self.collections = {part: Collection(self.pvd(part)) for part in self.parts}
        self.flushed = time.monotonic()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    @classmethod
    def for_result(cls, result, directory, **options):
        """A writer with the parts a result has (no cables or markers: no such series)."""
        parts = ["rod"] + (["cables"] if result.meta.get("cables") else []) \
            + (["markers"] if result.meta.get("markers") else [])
        return cls(directory, parts, **options)

    def pvd(self, part="rod"):
        """Path of the collection of ``part``."""
        return self.directory / f"{part}.pvd"

    def write(self, result, k):
        """Write frame ``k`` of ``result`` (all parts), then list it in the collections."""
        index, files = self.frames, {}
        for part in self.parts:
            relative = Path(SUBDIRECTORY) / f"{part}_{index:06d}.vtp"
            save_vtp(MESHES[part](result, k), self.directory / relative)
            files[part] = relative
        for part in self.parts:
            self.collections[part].add(result.t[k], files[part].as_posix())
        self.frames += 1
        if time.monotonic() - self.flushed >= self.flush_interval:
            self.flush()

    def flush(self):
        """Add every frame written so far to the collections."""
        for collection in self.collections.values():
            collection.flush()
        self.flushed = time.monotonic()

    def close(self):
        """Flush, and leave the collections without the room kept for more frames."""
        for collection in self.collections.values():
            collection.close()


def frame_indices(n_frames, every=None):
    """Indices of every ``every``-th frame (:func:`view_step`), always including the last."""
    if n_frames == 0:
        return []
    return sorted(set(range(0, n_frames, view_step(n_frames, every))) | {n_frames - 1})


def write_vtp(result, directory, every=None, overwrite=False):
    """The ``"vtp"`` format of :func:`rodmol.write_series`: ``result.npz`` and the
    ``.pvd``/``.vtp`` series of a finished Result; an earlier run there is kept unless
    ``overwrite`` (:func:`rodmol.output.run_files.claim`); returns the path of ``rod.pvd``."""
    directory = output_directory(directory, "directory")
    run_files.claim(directory, overwrite)  # all of it: load_result would read a stale result.h5 first
    result.save(directory / run_files.NPZ)
    with SeriesWriter.for_result(result, directory) as writer:
        for k in frame_indices(len(result.t), every):
            writer.write(result, k)
    return writer.pvd("rod")


def before_run(directory, options):
    """Before a run written in the ``"vtp"`` format: refuse a directory where ``result.npz``
    goes, and clear an earlier run (its result.h5 would be read instead of result.npz)."""
    refuse_directories([directory / run_files.NPZ] if options.npz else [])
    run_files.clear(directory)


def write_run(result, options, directory, stopped):
    """Write result.npz (if ``options.npz``), then the VTK frames; stop between frames
    once ``stopped()``.

    A file that cannot be written (a full disk, a directory in its place) ends
    the writing with ``written["error"]`` saying which and why; what was
    written before stays valid (files are replaced atomically, the series
    list only complete frames).
    """
    written = {}
    if options.npz:
        try:
            result.save(directory / run_files.NPZ)
            written["result"] = directory / run_files.NPZ
        except OSError as exc:  # the series may still fit (a directory in its place)
            written["error"] = run_files.cannot_write(directory / run_files.NPZ, exc)
    if options.vtk:
        indices = frame_indices(len(result.t), options.every)
        writer = None
        try:
            with SeriesWriter.for_result(result, directory) as writer:
                for k in indices:
                    if stopped():
                        break
                    writer.write(result, k)
        except OSError as exc:
            problem = run_files.cannot_write(directory / SUBDIRECTORY, exc)
            written["error"] = f"{written['error']}\nrodmol: {problem}" if "error" in written else problem
            if writer is None:
                return written
        written.update(pvd=writer.pvd("rod"), parts=writer.parts, frames=writer.frames,
                       all_frames=len(indices))
    return written
