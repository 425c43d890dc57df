"""Measured data in and out: multi-column tension logs, 3-D marker tracks,
2-D pixel tracks per camera and control points.

All are CSV tables in the style of :func:`rodmol.inputs.read_table`: an
optional header line (the first row that is not all numbers), ``#`` starts a
comment line, blank lines are skipped, and every error names the file and
the line. Columns (SI units, global frame for positions):

* tension log: ``t, <cable>, <cable>, ...`` [s, N], one column per cable,
  named in the header (``cable 11`` or ``11`` for the paper's arm);
* marker tracks: ``t, <m>.x, <m>.y, <m>.z, ...`` [s, m], three per marker;
* pixel tracks (one file per camera): ``t, <m>.u, <m>.v, ...`` [s, px];
* control points (one file per camera): ``x, y, z, u, v`` [m, px].

In tracks, an empty cell or ``nan`` is a missing sample (an occluded
marker); elsewhere every value is required.
"""

import csv
import io
import math
import os
from dataclasses import dataclass

import numpy as np

from .._files import claim, write_atomically
from ..errors import ParameterError
from ..inputs import Knots


@dataclass(frozen=True)
class MarkerTracks:
    """Marker positions ``xyz`` (n_t, n_markers, 3) [m], global frame, at times
    ``t`` (n_t,) [s]; NaN where a marker was not seen.

    ``part`` says what they are in a system's run (:mod:`rodmol.calibrate.targets`):
    the markers of a rod (its name, ``"arm1"``), a rod's tip (``"arm1.tip"``)
    or a body's origin (its name, ``"head"``); None: a single rod's markers."""

    t: np.ndarray
    xyz: np.ndarray
    names: tuple
    part: str | None = None

    def until(self, t_end):
        """The samples at times up to ``t_end`` [s] (inclusive): e.g. to fit
        or compare only the first seconds of a recording."""
        keep = self.t <= t_end
        if not keep.any():
            raise ParameterError(f"`t_end` = {t_end!r} s is before the first sample (t = {self.t[0]} s)")
        return MarkerTracks(self.t[keep], self.xyz[keep], self.names, self.part)


@dataclass(frozen=True)
class PixelTracks:
    """Image coordinates ``uv`` (n_t, n_markers, 2) [px] of markers seen by one
    camera at times ``t`` [s]; NaN where a marker was occluded."""

    t: np.ndarray
    uv: np.ndarray
    names: tuple


@dataclass(frozen=True)
class TensionLog:
    """Cable tensions ``values`` (n_t, n_cables) [N] at times ``t`` [s], one
    column per cable named in ``names``."""

    t: np.ndarray
    values: np.ndarray
    names: tuple

    def inputs(self):
        """{cable name: tension input (knots)}."""
        return {name: Knots(self.t, self.values[:, i], source=f"tension log column {name!r}")
                for i, name in enumerate(self.names)}

    def overrides(self, rod=None):
        """Dotted overrides (``tension.<cable>``) that drive a scenario's cables by
        this log; a system's rod ``rod``'s (``rods.<rod>.tension.<cable>``)."""
        prefix = "tension." if rod is None else f"rods.{rod}.tension."
        return {prefix + name: value for name, value in self.inputs().items()}


def as_tracks(measured, times=None):
    """MarkerTracks from MarkerTracks, a CSV path or an array (n_t, n_markers, 3) with ``times``."""
    if isinstance(measured, MarkerTracks):
        return measured
    if isinstance(measured, (str, os.PathLike)):
        return read_marker_tracks(measured)
    xyz = np.asarray(measured, dtype=float)
    if times is None or xyz.ndim != 3 or xyz.shape[-1] != 3 or len(times) != len(xyz):
        raise ParameterError("measured markers must be MarkerTracks, a CSV path, or an array "
                             "(n_t, n_markers, 3) with `times` (n_t,)")
    return MarkerTracks(np.asarray(times, dtype=float), xyz, tuple(f"marker {i + 1}" for i in range(xyz.shape[1])))


def read_tension_log(path, clip_negative=False):
    """Read a multi-column tension log (see the module docstring).

    Negative tensions are errors naming the line, unless ``clip_negative``
    (sensor noise around zero on a slack cable), which sets them to 0.
    """
    header, rows, lines = _read(path, "tension", group=1, time=True)
    names = _names(header, rows.shape[1] - 1, 1, lambda i: f"cable {i + 1}")
    values = rows[:, 1:]
    bad = np.flatnonzero(np.any(values < 0.0, axis=1))
    if len(bad) and not clip_negative:
        i = int(bad[0])
        raise ParameterError(f"{os.fspath(path)}:{lines[i]}: negative tension {float(values[i].min())!r} N "
                             "(pass clip_negative=True for sensor noise around zero)")
    return TensionLog(rows[:, 0], np.maximum(values, 0.0), names)


def read_marker_tracks(path, part=None):
    """Read 3-D marker tracks (see the module docstring); ``part``: what they
    are in a system's run (see :class:`MarkerTracks`)."""
    header, rows, _ = _read(path, "marker position", group=3, time=True, missing=True)
    n = (rows.shape[1] - 1) // 3
    return MarkerTracks(rows[:, 0], rows[:, 1:].reshape(len(rows), n, 3),
                        _names(header, n, 3, lambda i: f"marker {i + 1}"), part)


def read_pixel_tracks(path):
    """Read one camera's 2-D pixel tracks (see the module docstring)."""
    header, rows, _ = _read(path, "pixel coordinate", group=2, time=True, missing=True)
    n = (rows.shape[1] - 1) // 2
    return PixelTracks(rows[:, 0], rows[:, 1:].reshape(len(rows), n, 2),
                       _names(header, n, 2, lambda i: f"marker {i + 1}"))


def read_control_points(path):
    """Read control points: returns (xyz (n, 3) [m], uv (n, 2) [px])."""
    _, rows, _ = _read(path, "control point", group=5, time=False)
    if rows.shape[1] != 5:
        raise ParameterError(f"{os.fspath(path)}: control points need 5 columns x, y, z, u, v, "
                             f"got {rows.shape[1]}")
    return rows[:, :3], rows[:, 3:]


# Each writer keeps a file already at ``path`` unless ``overwrite`` (rodmol._files.claim).

def write_tension_log(path, log, overwrite=False):
    _write(path, ["t"] + list(log.names), np.column_stack([log.t, log.values]), overwrite)


def write_marker_tracks(path, tracks, overwrite=False):
    heads = [f"{n}.{c}" for n in tracks.names for c in "xyz"]
    _write(path, ["t"] + heads, np.column_stack([tracks.t, tracks.xyz.reshape(len(tracks.t), -1)]), overwrite)


def write_pixel_tracks(path, tracks, overwrite=False):
    heads = [f"{n}.{c}" for n in tracks.names for c in "uv"]
    _write(path, ["t"] + heads, np.column_stack([tracks.t, tracks.uv.reshape(len(tracks.t), -1)]), overwrite)


def write_control_points(path, xyz, uv, overwrite=False):
    _write(path, ["x", "y", "z", "u", "v"], np.column_stack([xyz, uv]), overwrite)


# --------------------------------------------------------------------------- CSV engine

def _write(path, header, rows, overwrite):
    """Write a CSV file (under a temporary name, renamed when complete), unless one is there
    and not ``overwrite``."""
    claim([path], overwrite, remove=False)

    def write(handle):
        text = io.TextIOWrapper(handle, encoding="utf-8", newline="")
        out = csv.writer(text)
        out.writerow(header)
        for row in rows:
            out.writerow(["" if math.isnan(x) else f"{x:.10g}" for x in row])
        text.flush()
        text.detach()

    write_atomically(path, write)


def _names(header, count, group, default):
    """Names of ``count`` column groups of width ``group`` from the header
    (``L1.x, L1.y, L1.z`` -> ``L1``), or defaults."""
    if header is None:
        return tuple(default(i) for i in range(count))
    cells = header[1:]
    names = []
    for i in range(count):
        cell = cells[i * group]
        names.append(cell.rsplit(".", 1)[0] if group > 1 and "." in cell else cell or default(i))
    return tuple(names)


def _number(cell):
    try:
        return float(cell)
    except ValueError:
        return None


def _read(path, what, group, time, missing=False):
    """(header cells or None, rows (n, columns) with NaN for missing cells,
    line numbers): every row as wide as the first, times increasing."""
    path = os.fspath(path)
    try:
        with open(path, newline="", encoding="utf-8") as handle:
            lines = list(enumerate(csv.reader(handle), start=1))
    except (OSError, ValueError) as exc:
        reason = getattr(exc, "strerror", None) or str(exc)
        raise ParameterError(f"cannot read {what} table {path!r}: {reason}") from None
    header, rows, numbers = None, [], []
    for lineno, row in lines:
        cells = [c.strip() for c in row]
        if not any(cells) or cells[0].startswith("#"):
            continue
        values = [_number(c) if c else math.nan for c in cells]
        if not rows and header is None and any(v is None for v in values):
            header = cells
            continue
        width = len(header) if header is not None else len(rows[0]) if rows else len(cells)
        first = 1 if time else 0
        if len(cells) != width or (width - first) % group or width <= first:
            need = f"t and groups of {group}" if time else f"{group}"
            raise ParameterError(f"{path}:{lineno}: expected {width} columns ({need} {what} values), "
                                 f"got {len(cells)} in {row!r}")
        bad = [c for c, v in zip(cells, values) if v is None or (isinstance(v, float) and math.isinf(v))]
        if bad:
            raise ParameterError(f"{path}:{lineno}: not a number {bad[0]!r} in {row!r}")
        gaps = [i for i, v in enumerate(values) if math.isnan(v)]
        if gaps and (not missing or (time and 0 in gaps)):
            name = "time" if time and gaps[0] == 0 else f"{what} (column {gaps[0] + 1})"
            raise ParameterError(f"{path}:{lineno}: missing {name} in {row!r}")
        if time and rows and values[0] <= rows[-1][0]:
            raise ParameterError(f"{path}:{lineno}: time {values[0]!r} s does not increase "
                                 f"(previous {rows[-1][0]!r} s)")
        rows.append(values)
        numbers.append(lineno)
    if not rows:
        raise ParameterError(f"{path}: no {what} rows found")
    return header, np.array(rows, dtype=float), numbers
