"""The files of a system's run (several rods and rigid bodies).

A system's run directory (``simulate(system, ..., out=DIR)``,
:func:`rodmol.write_series` of a :class:`~rodmol.system_result.SystemResult`) holds

* ``system.h5``: the index, small, replaced atomically after every chunk:
  the planned output times ``t_out``, the times reached ``t``, the chunk
  files in order (``chunks``, ``chunk_frames``), each body's drawn surface
  (group ``bodies/KEY``: ``surface_points`` [m], body frame, and
  ``surface_triangles``) and, as JSON in the attribute ``info``,
  ``success``, ``message``, ``stats``, ``complete``, the parts' names with
  their keys and their slices of the state (``parts``), and for a run of
  ``simulate`` its ``settings`` (:func:`rodmol._settings.record_system`);
* ``frames/chunk_NNNNNN.h5``: the frames of one chunk: ``t``, the assembled
  ``states`` and each body's ``bodies/KEY/position`` [m] and ``quaternion``
  (body to global), ``velocity`` [m/s] and ``angular_velocity`` [rad/s],
  body frame, and the force [N] and moment [N m] of its contacts
  (``contact_force``, ``contact_moment``: with fixed obstacles;
  ``rod_contact_force``, ``rod_contact_moment``: of the rods touching it;
  about its origin, body frame); in the group ``view``, each body's triangles and its points at
  the shown frames (``KEY_points``, global, single precision); and
  ``frames/chunk_NNNNNN.xmf``, the bodies' grids of its shown frames. Each is
  written under a temporary name and renamed when complete, and never
  changed after (:mod:`rodmol.output.h5result`'s chunk files);
* ``bodies.xdmf``: the bodies for ParaView, one temporal collection each,
  including every chunk's grids, drawn as their mesh
  (:meth:`rodmol.RigidBody.from_mesh`) or, without one, as the ellipsoid of
  uniform density with their mass and inertia, at their pose;
* a folder per rod, named after it: that rod's run directory exactly as a
  single rod's (``result.h5``, ``rod.xdmf``, ``cables.xdmf``, ``markers.xdmf``;
  :mod:`rodmol.output.stream`).

So writing a chunk costs the same at any length of the run. ``simulate(system,
..., out=DIR)`` streams it while the run goes, and :func:`rodmol.write_series`
writes a finished result at once (:mod:`rodmol.output.system_stream`).
:func:`read_system` also reads the single ``system.h5`` of an older rodmol
(every frame in the index).
"""

import json
import re
from pathlib import Path

import numpy as np

from ..errors import ParameterError
from ..meshes import read_surface
from ..system_result import BodyResult, SystemResult
from . import h5result, xdmf
from .run_files import SYSTEM

INDEX, BODIES_VIEW = SYSTEM
FORMAT = "rodmol-system"
#: The body fields stored per frame.
BODY_FIELDS = ("position", "quaternion", "velocity", "angular_velocity")
#: The body's contact forces and moments stored per frame, body frame (none in an older rodmol's files).
CONTACT_FIELDS = ("contact_force", "contact_moment", "rod_contact_force", "rod_contact_moment")
#: A drawn body's surface, body frame: points [m] and triangles (:func:`body_surface`).
SURFACE = ("surface_points", "surface_triangles")
#: Rings and meridians of the drawn ellipsoid.
RINGS, MERIDIANS = 16, 32


def body_surface(body):
    """The surface drawing ``body``: (points (n, 3) [m], body frame; triangles (m, 3)).

    Its mesh file if it has one (:func:`rodmol.meshes.read_surface`); else the ellipsoid of uniform density with
    its mass m and inertia (principal values I_i along the principal axes,
    about the centre of mass): semi-axes a_i = sqrt(5 (I_j + I_k - I_i) / (2 m))
    (a sphere's inertia gives the sphere).
    """
    if body.mesh is not None:
        return read_surface(body.mesh)  # as RigidBody.from_mesh read it: triangles, outward
    values, axes = np.linalg.eigh(body.inertia)
    semi = np.sqrt(np.maximum(2.5 * (values.sum() - 2.0 * values) / body.mass, 1e-30))
    polar = np.linspace(0.0, np.pi, RINGS + 1)[1:-1]
    around = np.linspace(0.0, 2.0 * np.pi, MERIDIANS, endpoint=False)
    ring = np.stack([np.outer(np.sin(polar), np.cos(around)), np.outer(np.sin(polar), np.sin(around)),
                     np.outer(np.cos(polar), np.ones(MERIDIANS))], axis=-1).reshape(-1, 3)
    unit = np.vstack([[0.0, 0.0, 1.0], ring, [0.0, 0.0, -1.0]])
    j = np.arange(MERIDIANS)
    triangles = [np.stack([np.zeros(MERIDIANS, int), 1 + j, 1 + (j + 1) % MERIDIANS], axis=1)]
    for r in range(RINGS - 2):
        a, b = 1 + r * MERIDIANS + j, 1 + r * MERIDIANS + (j + 1) % MERIDIANS
        triangles += [np.stack([a, a + MERIDIANS, b], axis=1), np.stack([b, a + MERIDIANS, b + MERIDIANS], axis=1)]
    last = 1 + (RINGS - 2) * MERIDIANS
    triangles.append(np.stack([last + j, np.full(MERIDIANS, len(unit) - 1), last + (j + 1) % MERIDIANS], axis=1))
    return body.centre_of_mass + (unit * semi) @ axes.T, np.vstack(triangles).astype(np.int64)


def surface_of(result, name):
    """The drawn surface of the body ``name`` of a SystemResult (see :func:`body_surface`)."""
    if result.assembly is not None:
        return body_surface(result.assembly.bodies[name].body)
    return result[name].surface


def chunk_batch(result, frames, shown, surfaces, keys):
    """The datasets of a chunk file (:func:`rodmol.output.h5result.write_chunk`) holding the frames
    ``frames`` (a slice) of the SystemResult ``result``: ``t``, ``states``, each body's fields and,
    for the views, its triangles and its points at the chunk's frames ``shown`` (indices into the
    chunk), placed by its pose; ``surfaces`` and ``keys``: each body's drawn surface and file key."""
    batch = {"t": result.t[frames], "states": result.states[frames]}
    for name, key in keys.items():
        body = result[name]
        for field in BODY_FIELDS + CONTACT_FIELDS:
            batch[f"bodies/{key}/{field}"] = getattr(body, field)[frames]
        points, triangles = surfaces[name]
        position, rotation = body.position[frames][shown], body.rotation[frames][shown]
        batch[f"{h5result.VIEW_GROUP}/{key}_triangles"] = triangles
        batch[f"{h5result.VIEW_GROUP}/{key}_points"] = position[:, None, :] + np.einsum("nij,pj->npi", rotation,
                                                                                         points)
    return batch


def write_views(directory, chunk, t, surfaces, keys, chunks):
    """Write the bodies' grids of the chunk file ``chunk`` at its shown times ``t`` (its ``.xmf``
    fragment), then ``bodies.xdmf`` including the fragments of every chunk in ``chunks``."""
    grids = {key: xdmf.body_grids(chunk, t, key, len(surfaces[name][0]), len(surfaces[name][1]))
             for name, key in keys.items()}
    xdmf.write_fragment(directory / _fragment(chunk), xdmf.fragment(grids))
    write_bodies_view(directory, keys, chunks)


def write_bodies_view(directory, keys, chunks):
    """Write ``bodies.xdmf``: each body's temporal collection, including its grids from the
    fragment of every chunk file in ``chunks``."""
    xdmf.write_collections(directory / BODIES_VIEW, keys, [_fragment(c) for c in chunks])


def _fragment(chunk):
    return chunk[:-3] + ".xmf"


def write_index(directory, t_out, t, chunks, info, surfaces, keys):
    """Replace ``system.h5`` (see the module): planned and reached times [s], the chunk files
    (name -> frames), ``info`` (JSON) and the bodies' drawn ``surfaces`` under their ``keys``."""
    import h5py

    def fill(handle):
        handle.attrs["format"] = FORMAT
        handle.attrs["info"] = json.dumps(dict(info, format=FORMAT))
        handle.create_dataset("t_out", data=np.asarray(t_out, dtype=float))
        handle.create_dataset("t", data=np.asarray(t, dtype=float))
        handle.create_dataset("chunks", data=[c.encode() for c in chunks], dtype=h5py.string_dtype())
        handle.create_dataset("chunk_frames", data=np.asarray(list(chunks.values()), dtype=np.int64))
        for name, key in keys.items():
            for field, value in zip(SURFACE, surfaces[name]):
                handle.create_dataset(f"bodies/{key}/{field}", data=value)

    h5result.atomic_h5(Path(directory) / INDEX, fill)
    return Path(directory) / INDEX


def read_info(directory):
    """The index ``system.h5`` in ``directory``: dict of ``info``, ``t``, ``t_out`` (None if it
    has none), ``chunks`` (name -> frames; None for an older rodmol's index, which holds every
    frame) and the bodies' ``surfaces`` (key -> (points, triangles)); a damaged file: a ParameterError."""
    import h5py

    path = Path(directory) / INDEX
    try:
        with h5py.File(path, "r") as handle:
            info = json.loads(handle.attrs["info"])
            if info.get("format") != FORMAT:
                raise ParameterError(f"{str(path)!r} is not the index of a system's run")
            index = dict(info=info, t=handle["t"][()], t_out=handle["t_out"][()] if "t_out" in handle else None,
                         chunks=None)
            if "chunks" in handle:
                names = [c.decode() if isinstance(c, bytes) else str(c) for c in handle["chunks"][()]]
                index["chunks"] = dict(zip(names, handle["chunk_frames"][()].tolist()))
            index["surfaces"] = {key: tuple(handle[f"bodies/{key}/{f}"][()] for f in SURFACE)
                                 for key in info["bodies"].values() if f"bodies/{key}/{SURFACE[0]}" in handle}
            if index["chunks"] is None:  # an older rodmol's index: the frames are in it
                index["frames"] = dict(states=handle["states"][()], **{
                    f"bodies/{key}/{f}": handle[f"bodies/{key}/{f}"][()]
                    for key in info["bodies"].values() for f in BODY_FIELDS})
    except (OSError, KeyError, ValueError) as exc:
        raise h5result.damaged(path, exc) from exc
    return index


def read_series(directory, index, name):
    """The dataset ``name`` of every frame listed in the ``index`` (:func:`read_info`), in time order."""
    if index["chunks"] is None:
        return index["frames"][name]
    if not index["chunks"]:
        return np.zeros((0,))
    return h5result.read_series(directory, list(index["chunks"]), name)


def read_system(directory):
    """The :class:`SystemResult` of a system's run directory (the arrays of its rods and bodies read on
    first access; every rod's files found first, :func:`_rods`)."""
    directory = Path(directory)
    index = read_info(directory)
    info, t = index["info"], index["t"]
    states = read_series(directory, index, "states")
    rods = {name: (lambda rod=rod: rod) for name, rod in _rods(directory, info["rods"]).items()}
    bodies = {name: (lambda key=key: _body(t, {f: read_series(directory, index, f"bodies/{key}/{f}")
                                               for f in BODY_FIELDS + _stored(directory, index, key)},
                                           index["surfaces"].get(key)))
              for name, key in info["bodies"].items()}
    message = info["message"]
    if not info.get("complete", True):
        message = (f"the run was stopped before it finished (killed?): {len(t)} frames up to t = "
                   f"{t[-1] if len(t) else 0.0:.6g} s were kept; resume it with simulate(..., out=DIR, resume=True)")
    return SystemResult(None, t, states, info["success"] and info.get("complete", True), message, info["stats"],
                        saved=(rods, bodies))


def _rods(directory, keys):
    """Each rod's Result ({name: file key} ``keys``; its arrays read on first access), once its
    files are found: a rod whose folder, index or chunk files are missing or unreadable is a
    ParameterError naming the rod and the file, before the SystemResult is made."""
    rods = {}
    for name, key in keys.items():
        path = directory / key / h5result.INDEX
        try:
            rods[name] = h5result.read_result(path)
        except FileNotFoundError:
            raise ParameterError(f"cannot read the rod {name!r} of the system's run {str(directory)!r}: its "
                                 f"result file {str(path)!r} is missing (the run's {INDEX} lists the rod: a run "
                                 "directory copied in part?)") from None
        except ParameterError as exc:
            raise ParameterError(f"cannot read the rod {name!r} of the system's run {str(directory)!r}: "
                                 f"{exc}") from exc
    return rods


def _stored(directory, index, key):
    """The :data:`CONTACT_FIELDS` the run's files hold for the body of file key ``key``
    (those of an older rodmol, none)."""
    import h5py

    if not index["chunks"]:
        return ()
    with h5py.File(Path(directory) / next(iter(index["chunks"])), "r") as handle:
        return tuple(f for f in CONTACT_FIELDS if f"bodies/{key}/{f}" in handle)


def _body(t, fields, surface):
    contact, rods = (np.hstack([fields[f"{kind}_force"], fields[f"{kind}_moment"]]) if f"{kind}_force" in fields
                     else None for kind in ("contact", "rod_contact"))
    body = BodyResult(t, *(fields[f] for f in BODY_FIELDS), contact, rods)
    body.surface = surface
    return body


def is_system(path):
    """True if ``path`` is a system's run directory or its ``system.h5``."""
    path = Path(path)
    return (path / INDEX).is_file() if path.is_dir() else path.name == INDEX


def _keys(names, kind):
    """{name: key}: a file name for each part: its own name if that is a plain one
    and not the run's own files' (``system.h5``, ``bodies.xdmf``, ``frames``), else ``kind_i``
    (i its index), made unique against every other key."""
    reserved = (*SYSTEM, h5result.FRAMES)
    plain = [n for n in names if re.fullmatch(r"[A-Za-z0-9_][A-Za-z0-9_.-]*", n) and n not in reserved]
    keys, taken = {}, set(plain) | set(reserved)
    for i, name in enumerate(names):
        if name in plain and name not in keys.values():
            keys[name] = name
            continue
        key = f"{kind}_{i}"
        while key in taken:
            key += "_"
        keys[name] = key
        taken.add(key)
    return keys


def _plain(stats):
    """``stats`` with numpy numbers made plain (JSON)."""
    return {k: (v.item() if isinstance(v, np.generic) else v) for k, v in dict(stats).items()
            if isinstance(v, (int, float, str, bool, np.generic))}
