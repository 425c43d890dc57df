"""What measured markers are in a run, and the run's markers that match them.

A single rod's measurement is its markers, in order (or its tip alone,
``part="tip"``). A system's names the part of each MarkerTracks
(``MarkerTracks.part``, or ``{part: tracks}``):

* ``"<rod>"``: the markers of that rod, in the order of its Model's markers;
* ``"<rod>.tip"``: that rod's tip (one marker);
* ``"<body>"``: the origin of that body (one marker).

Several parts share one recording: their tracks must have the same times,
and are compared as one set of markers, in the order given (the last one is
the "tip" of eq. 15). Distances are in fractions of the longest rod's length.
"""

import os
from dataclasses import dataclass, replace

import numpy as np

from .. import _checks
from ..errors import ParameterError
from ..model import Model
from ..result import Result
from .measured import MarkerTracks, as_tracks, read_marker_tracks

TIP = "tip"


@dataclass(frozen=True)
class Targets:
    """The parts a measurement sees, in its markers' order: ``parts`` ((name or
    None, kind, count), ...) with kind ``"markers"``, ``"tip"`` or ``"body"``;
    ``length`` [m] the normalising length (the rod's, or the longest rod's)."""

    parts: tuple
    length: float

    def markers(self, result):
        """The run's markers (n_t, n_markers, 3) [m] that the measurement sees."""
        out = []
        for name, kind, _ in self.parts:
            part = result if name is None else result[name]
            out.append(part.markers if kind == "markers" else (part.tip if kind == TIP else part.position)[:, None])
        return np.concatenate(out, axis=1)

    def view(self, result):
        """``result`` as eq. (15) reads it (``t``, ``markers``, ``tensions``,
        ``meta["length"]``): the result itself for a single rod's markers."""
        if self.parts == ((None, "markers", self.parts[0][2]),):
            return result
        rods = [result] if isinstance(result, Result) else [result[r] for r in result.rods]
        tensions = np.concatenate([r.tensions.reshape(len(result.t), -1) for r in rods], axis=1)
        return _View(result.t, self.markers(result), tensions, {"length": self.length})


@dataclass(frozen=True)
class _View:
    t: np.ndarray
    markers: np.ndarray
    tensions: np.ndarray
    meta: dict


def of_spec(spec, measured, times=None):
    """(MarkerTracks, Targets) of ``measured`` in the run ``spec`` (a RunSpec)."""
    return _targets(measured, times, *_catalogue(spec.model))


def of_part(spec, part=None):
    """The Targets of one ``part`` of the run ``spec`` (None: a single rod's markers)."""
    system, rods, bodies, length = _catalogue(spec.model)
    return Targets((_resolve(part, system, rods, bodies),), float(length))


def _catalogue(model):
    """(None or "system", {rod or None: its number of markers}, body names, normalising length [m]) of a model."""
    if isinstance(model, Model):
        return None, {None: len(model.markers)}, (), model.rod.length
    rods = {name: len(m.markers) for name, m in model.given_rods.items()}
    return "system", rods, tuple(model.given_bodies), max(m.rod.length for m in model.given_rods.values())


def of_result(result, measured, times=None):
    """(MarkerTracks, Targets) of ``measured`` in a run's ``result`` (a Result or a SystemResult)."""
    if isinstance(result, Result):
        return _targets(measured, times, None, {None: result.markers.shape[1]}, (), result.meta.get("length"))
    rods = {name: result[name].markers.shape[1] for name in result.rods}
    length = max(result[name].meta["length"] for name in result.rods)
    return _targets(measured, times, "system", rods, tuple(result.bodies), length)


def _targets(measured, times, system, rods, bodies, length):
    """One MarkerTracks (the parts' markers side by side) and the Targets; every part checked."""
    pieces = _pieces(measured, times, system)
    parts = []
    for tracks in pieces:
        name, kind, count = _resolve(tracks.part, system, rods, bodies)
        if tracks.xyz.shape[1] != count:
            what = "the run" if name is None else f"{kind if kind != 'markers' else 'rod'} {name!r}"
            raise ParameterError(f"the measurement{'' if name is None else f' of {tracks.part!r}'} has "
                                 f"{tracks.xyz.shape[1]} markers, {what} {count}")
        parts.append((name, kind, count))
    first = pieces[0]
    for tracks in pieces[1:]:
        if tracks.t.shape != first.t.shape or not np.allclose(tracks.t, first.t, rtol=0.0, atol=1e-9):
            raise ParameterError(f"the measurements of {first.part!r} and {tracks.part!r} have different "
                                 "times: the parts of one recording share its frames")
    if len(pieces) == 1:
        combined = replace(first, part=None)
    else:
        names = tuple(f"{t.part}.{n}" for t in pieces for n in t.names)
        combined = MarkerTracks(first.t, np.concatenate([t.xyz for t in pieces], axis=1), names)
    return combined, Targets(tuple(parts), float(length))


def _pieces(measured, times, system):
    """The MarkerTracks of ``measured``, each with its part: one, a list, or {part: tracks or path}."""
    if isinstance(measured, dict):
        if not measured:
            raise ParameterError("`measured` is an empty dict: give {part: marker tracks}")
        return [replace(as_tracks(read_marker_tracks(v) if isinstance(v, (str, os.PathLike)) else v, times),
                        part=part) for part, v in measured.items()]
    if isinstance(measured, (list, tuple)) and measured and all(isinstance(m, MarkerTracks) for m in measured):
        pieces = list(measured)
    else:
        pieces = [as_tracks(measured, times)]
    if system is not None and any(p.part is None for p in pieces):
        raise ParameterError("a system's measurement must say which part it sees: MarkerTracks(..., part="
                             "'arm1') (a rod's markers, 'arm1.tip' its tip, 'head' a body's origin), or "
                             "{'arm1': tracks}")
    return pieces


def _resolve(part, system, rods, bodies):
    """(name, kind, count) of the target ``part``."""
    if system is None:
        if part is None:
            return None, "markers", rods[None]
        if part == TIP:
            return None, TIP, 1
        raise ParameterError(f"a single rod's measurement is its markers (part None) or its tip ('tip'), "
                             f"got part {part!r}")
    if part in rods:
        if not rods[part]:
            raise ParameterError(f"rod {part!r} has no markers: measure its tip, part '{part}.{TIP}', or give "
                                 "it markers")
        return part, "markers", rods[part]
    if isinstance(part, str) and part.endswith("." + TIP) and part[: -len(TIP) - 1] in rods:
        return part[: -len(TIP) - 1], TIP, 1
    if part in bodies:
        return part, "body", 1
    valid = list(rods) + [f"{r}.{TIP}" for r in rods] + list(bodies)
    raise ParameterError(f"the measurement's part {part!r} is no rod or body of the system"
                         f"{_checks.did_you_mean(part, valid)}; parts: {', '.join(valid)}")
