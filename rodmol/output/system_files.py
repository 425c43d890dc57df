"""The files of a system's run (several rods and rigid bodies), written once it ended.

A system's run directory (``simulate(system, ..., out=DIR)``,
:func:`rodmol.write_series` of a :class:`~rodmol.system_result.SystemResult`) holds

* ``system.h5``: the output times ``t``, the assembled ``states``, each
  body's frames (group ``bodies/KEY``: ``position`` [m] and ``quaternion``
  (body to global), ``velocity`` [m/s] and ``angular_velocity`` [rad/s],
  body frame) and, as JSON in the attribute ``info``, ``success``,
  ``message``, ``stats`` and the parts' names with their keys; in the group
  ``view``, each body's drawn surface (``KEY_triangles``) and its points at
  the shown frames (``KEY_points``, global);
* ``bodies.xdmf``: the bodies for ParaView, one temporal collection each,
  drawn as their mesh (:meth:`rodmol.RigidBody.from_mesh`) or, without one, as
  the ellipsoid of uniform density with their mass and inertia, at their pose;
* a folder per rod, named after it: that rod's run directory exactly as a
  single rod's (``result.h5``, ``rod.xdmf``, ``cables.xdmf``, ``markers.xdmf``;
  :mod:`rodmol.output.stream`).

``simulate(system, ..., out=DIR)`` streams it while the run goes
(:mod:`rodmol.output.system_stream`); :func:`write_system` writes a finished
result at once.
"""

import html
import json
import re
from pathlib import Path

import numpy as np

from .._files import output_directory
from ..errors import ParameterError
from ..system_result import BodyResult, SystemResult
from . import h5result, stream, xdmf
from .parts import view_step
from .run_files import SYSTEM

INDEX, BODIES_VIEW = SYSTEM
FORMAT = "rodmol-system"
#: The body fields stored per frame.
BODY_FIELDS = ("position", "quaternion", "velocity", "angular_velocity")
#: A drawn body's surface, body frame: points [m] and triangles (:func:`body_surface`).
SURFACE = ("surface_points", "surface_triangles")
#: Rings and meridians of the drawn ellipsoid.
RINGS, MERIDIANS = 16, 32


def body_surface(body):
    """The surface drawing ``body``: (points (n, 3) [m], body frame; triangles (m, 3)).

    Its mesh file if it has one; else the ellipsoid of uniform density with
    its mass m and inertia (principal values I_i along the principal axes,
    about the centre of mass): semi-axes a_i = sqrt(5 (I_j + I_k - I_i) / (2 m))
    (a sphere's inertia gives the sphere).
    """
    if body.mesh is not None:
        import meshio

        mesh = meshio.read(body.mesh)
        triangles = np.concatenate([block.data for block in mesh.cells if block.type == "triangle"])
        return np.asarray(mesh.points, dtype=float)[:, :3], triangles.astype(np.int64)
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


def write_system(result, directory, every=None):
    """Write a finished :class:`SystemResult` into ``directory`` (see the module),
    replacing an earlier run there; returns the path of ``system.h5``.
    ``every``: show every n-th frame in the views (and the last)."""
    directory = output_directory(directory, "directory")
    rods = _keys(result.rods, "rod")
    for name, key in rods.items():
        stream.write_xdmf(result[name], directory / key, every)
    return write_index(directory, result, view_step(len(result.t), every))


def write_index(directory, result, step, **extra):
    """Write ``system.h5`` and ``bodies.xdmf`` of the SystemResult ``result`` (with its
    assembly) into ``directory``, the views showing every ``step``-th frame and the last;
    ``extra`` goes into the index's ``info`` (a streamed run's plan and settings).
    Returns the path of ``system.h5``."""
    rods, bodies = _keys(result.rods, "rod"), _keys(result.bodies, "body")
    t = result.t
    shown = sorted(set(range(0, len(t), step)) | {len(t) - 1})
    surfaces = {name: surface_of(result, name) for name in result.bodies}
    info = dict(format=FORMAT, success=bool(result.success), message=str(result.message),
                stats=_plain(result.stats), rods=rods, bodies=bodies, shown=shown, **extra)

    def fill(handle):
        handle.attrs["format"] = FORMAT
        handle.attrs["info"] = json.dumps(info)
        handle.create_dataset("t", data=t)
        handle.create_dataset("states", data=result.states)
        for name, key in bodies.items():
            body = result[name]
            for field in BODY_FIELDS:
                handle.create_dataset(f"bodies/{key}/{field}", data=getattr(body, field))
            if name in surfaces:
                points, triangles = surfaces[name]
                handle.create_dataset(f"bodies/{key}/{SURFACE[0]}", data=points)
                handle.create_dataset(f"bodies/{key}/{SURFACE[1]}", data=triangles)
                placed = body.position[shown, None, :] + np.einsum("nij,pj->npi", body.rotation[shown], points)
                handle.create_dataset(f"{h5result.VIEW_GROUP}/{key}_triangles", data=triangles)
                handle.create_dataset(f"{h5result.VIEW_GROUP}/{key}_points", data=placed, dtype=h5result.VIEW)

    h5result.atomic_h5(directory / INDEX, fill)
    grids = {html.escape(name, quote=True): xdmf.body_grids(INDEX, t[shown], key, len(surfaces[name][0]),
                                                           len(surfaces[name][1]))
             for name, key in bodies.items()}
    xdmf.write_fragment(directory / BODIES_VIEW, xdmf.fragment(grids))
    return directory / INDEX


def read_info(directory):
    """(info, t, states) of the index ``system.h5`` in ``directory`` (a damaged file: a ParameterError)."""
    import h5py

    path = Path(directory) / INDEX
    try:
        with h5py.File(path, "r") as handle:
            info = json.loads(handle.attrs["info"])
            if info.get("format") != FORMAT:
                raise ParameterError(f"{str(path)!r} is not the index of a system's run")
            return info, handle["t"][()], handle["states"][()]
    except (OSError, KeyError, ValueError) as exc:
        raise h5result.damaged(path, exc) from exc


def read_system(directory):
    """The :class:`SystemResult` of a system's run directory (its rods read on first access)."""
    import h5py

    directory = Path(directory)
    path = directory / INDEX
    try:
        with h5py.File(path, "r") as handle:
            info = json.loads(handle.attrs["info"])
            if info.get("format") != FORMAT:
                raise ParameterError(f"{str(path)!r} is not the index of a system's run")
            t, states = handle["t"][()], handle["states"][()]
            fields = {key: {f: handle[f"bodies/{key}/{f}"][()] for f in BODY_FIELDS + SURFACE
                            if f"bodies/{key}/{f}" in handle}
                      for key in info["bodies"].values()}
    except (OSError, KeyError, ValueError) as exc:
        raise h5result.damaged(path, exc) from exc
    rods = {name: (lambda key=key: h5result.read_result(directory / key / h5result.INDEX))
            for name, key in info["rods"].items()}
    bodies = {name: (lambda key=key: _body(t, fields[key])) for name, key in info["bodies"].items()}
    message = info["message"]
    if not info.get("complete", True):
        message = (f"the run was stopped before it finished (killed?): {len(t)} frames up to t = "
                   f"{t[-1] if len(t) else 0.0:.6g} s were kept; resume it with simulate(..., out=DIR, resume=True)")
    return SystemResult(None, t, states, info["success"] and info.get("complete", True), message, info["stats"],
                        saved=(rods, bodies))


def _body(t, fields):
    body = BodyResult(t, *(fields[f] for f in BODY_FIELDS))
    if SURFACE[0] in fields:
        body.surface = (fields[SURFACE[0]], fields[SURFACE[1]])
    return body


def is_system(path):
    """True if ``path`` is a system's run directory or its ``system.h5``."""
    path = Path(path)
    return (path / INDEX).is_file() if path.is_dir() else path.name == INDEX


def _keys(names, kind):
    """{name: key}: a file name for each part: its own name if that is a plain one
    and not the run's own files' (``system.h5``, ``bodies.xdmf``), else ``kind_i``
    (i its index), made unique against every other key."""
    plain = [n for n in names if re.fullmatch(r"[A-Za-z0-9_][A-Za-z0-9_.-]*", n) and n not in SYSTEM]
    keys, taken = {}, set(plain) | set(SYSTEM)
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
