"""What can be wrong with one rod's state, found by one compiled scan, and said in words.

:func:`scan` (one pass, about a microsecond) finds non-finite entries,
elements inverted or collapsed (axial stretch q1 <= :data:`MIN_STRETCH`),
stretched beyond :data:`MAX_STRETCH` or turning by more than :data:`MAX_TURN`
rad over one element (the grid no longer resolves the curvature: the schemes
and the chord formula break down near half a turn per element), and
orientations whose quaternion norm left 1 (the solution blew up).
:func:`state_problem` says what it found; :func:`tip_problem` checks the tip
section against the pull of the cables anchored there, which no element of
the state shows; :func:`stall_diagnosis` describes a state where a run
stalled. A rod's system (:class:`rodmol.discretise.system.SemiDiscrete`)
offers them as its own checks (``state_problem``, ``step_problem``,
``describe_stall``: :mod:`rodmol.discretise.protocol`), a system of rods each
rod's on its part.
"""

import math

import numba
import numpy as np

from .layout import BLOCK, HEADER, QUAT, K, Q

#: Axial stretch q1 at or below which an element counts as inverted or collapsed.
MIN_STRETCH = 0.05
#: Axial stretch q1 above which an element counts as torn apart (a linear
#: elastic law means nothing there).
MAX_STRETCH = 10.0
#: Largest rotation [rad] of the cross-section over one element, |k| ds.
MAX_TURN = 0.5 * math.pi
#: Largest departure of a quaternion's norm from 1 inside the integration
#: (which keeps it within about its tolerance; the stored states are projected
#: back to |Q| = 1, see ``StateLayout.project_quaternions``).
MAX_QUATERNION_DRIFT = 0.1

#: Codes returned by :func:`scan`.
OK, NON_FINITE, INVERTED, STRETCHED, TURNED, QUATERNION = range(6)


@numba.njit(cache=True, nogil=True)
def scan(y, n, ds, min_stretch, max_stretch, max_turn, max_drift):
    """(code, element or entry index, value) of the first problem in state ``y``.

    Also returns the extremes for a diagnosis when all is well: the code is
    then OK and (index, value) are the element with the smallest q1 and q1.
    """
    for i in range(y.size):
        if not np.isfinite(y[i]):
            return NON_FINITE, i, y[i]
    worst, worst_q1 = 0, np.inf
    for b in range(n):
        o = HEADER + b * BLOCK
        q1 = y[o + Q]
        if q1 <= min_stretch:
            return INVERTED, b, q1
        if q1 > max_stretch:
            return STRETCHED, b, q1
        if q1 < worst_q1:
            worst, worst_q1 = b, q1
        turn = ds * math.sqrt(y[o + K] ** 2 + y[o + K + 1] ** 2 + y[o + K + 2] ** 2)
        if turn > max_turn:
            return TURNED, b, turn
        norm = math.sqrt(y[o + QUAT] ** 2 + y[o + QUAT + 1] ** 2 + y[o + QUAT + 2] ** 2
                         + y[o + QUAT + 3] ** 2)
        if abs(norm - 1.0) > max_drift:
            return QUATERNION, b, norm
    return OK, worst, worst_q1


@numba.njit(cache=True, nogil=True)
def scan_parts(y, starts, ns, dss, rest, min_stretch, max_stretch, max_turn, max_drift):
    """:func:`scan` of each rod's part of a system's state ``y`` (rod r's state from ``starts[r]``,
    ``ns[r]`` elements of length ``dss[r]``) and the finiteness of ``y[rest:]`` (the bodies'),
    in one call: (part, code, index, value) of the first problem, the part r, or ``len(starts)``
    for the bodies' (index from ``rest``); part -1 and OK when all is well."""
    for r in range(starts.size):
        n = ns[r]
        part = y[starts[r]:starts[r] + HEADER + n * BLOCK]
        code, i, value = scan(part, n, dss[r], min_stretch, max_stretch, max_turn, max_drift)
        if code != OK:
            return r, code, i, value
    for i in range(rest, y.size):
        if not np.isfinite(y[i]):
            return starts.size, NON_FINITE, i - rest, y[i]
    return -1, OK, 0, 0.0


#: :func:`scan`'s limits, its last arguments.
LIMITS = (MIN_STRETCH, MAX_STRETCH, MAX_TURN, MAX_QUATERNION_DRIFT)


def limits(n_elements, ds):
    """:func:`scan`'s arguments after the state, of a rod of ``n_elements`` of length ``ds`` [m]."""
    return n_elements, ds, *LIMITS


def state_problem(layout, ds, t, y):
    """A sentence naming what is wrong with the rod's state ``y`` at time ``t`` [s], or None
    (``layout``: its :class:`~rodmol.discretise.layout.StateLayout`, ``ds`` [m] its elements' length)."""
    y = np.ascontiguousarray(y, dtype=float)
    return describe(layout, ds, t, *scan(y, *limits(layout.n_elements, ds)))


def tip_problem(t, pull, stiffness):
    """The tip section crushed at ``t`` [s] by the ``pull`` [N] of the cables anchored there
    against its axial ``stiffness`` EA [N] (the Result's tip strain 1 - T / EA at or below
    :data:`MIN_STRETCH`), as a sentence, or None."""
    q1 = 1.0 - pull / stiffness
    if q1 > MIN_STRETCH:
        return None
    return (f"the tip section is crushed at t = {t:.6g} s: the cables anchored at the tip pull "
            f"with {pull:.3g} N against its axial stiffness EA = {stiffness:.3g} N "
            f"(tip strain q1 = {q1:.3g}): the load is beyond what the rod can carry")


def stall_diagnosis(layout, ds, y):
    """Where the rod's state ``y`` of a stalled run is at its worst: its most compressed
    element and its largest turn over an element, with the likely causes."""
    q1 = layout.field(y, "q")[:, 0]
    worst = int(np.argmin(q1))
    turns = ds * np.linalg.norm(layout.field(y, "k"), axis=1)
    b = int(np.argmax(turns))
    return (f"Most compressed element {worst} (q1 = {q1[worst]:.3g}), largest turn {turns[b]:.3g} rad "
            f"over element {b}: the load may be beyond what the rod can carry (collapse, "
            "buckling, whirling), or the grid too coarse for the motion")


def least_stretch(layout, y):
    """The smallest axial stretch q1 of the rod's state ``y`` (which rod of a system stalled)."""
    return float(np.min(layout.field(y, "q")[:, 0]))


def describe(layout, ds, t, code, i, value):
    """:func:`scan`'s finding (``code``, ``i``, ``value``) at ``t`` [s] as a sentence (None if OK)."""
    at = f"at t = {t:.6g} s"
    if code == NON_FINITE:
        return (f"the state became non-finite {at} ({layout.entry_name(i)} = {value!r}): the "
                "solution blew up; the load may be beyond what the rod can carry")
    if code == INVERTED:
        what = "inverted" if value <= 0.0 else "collapsed"
        return (f"element {i} {what} {at} (axial stretch q1 = {value:.3g}): the grid is too coarse "
                "for this curvature, or the load is beyond what the rod can carry")
    if code == STRETCHED:
        return (f"element {i} stretched to {value:.3g} times its length {at}: the load is beyond "
                "what the rod can carry (check E and the loads)")
    if code == TURNED:
        return (f"element {i} turns by {value:.3g} rad over its length ds = {ds:.3g} m {at} "
                f"(more than {MAX_TURN:.3g} rad): the grid is too coarse for this curvature (use "
                "more elements), or the load is beyond what the rod can carry")
    if code == QUATERNION:
        return (f"the orientation of node {i + 1} lost its unit norm (|Q| = {value:.3g}) {at}: "
                "the solution blew up")
    return None


def parts_problem(assembly, check, t, y):
    """What a system's ``check`` (``"state_problem"``) finds in each rod's part of ``y`` (the
    message names the rod), else a body's non-finite entries; or None."""
    for name, sd in assembly.rods.items():
        problem = getattr(sd, check)(t, y[assembly.parts[name]])
        if problem:
            return f"rod {name!r}: {problem}"
    for name, part in assembly.bodies.items():
        if not np.all(np.isfinite(y[part.slice])):
            return f"the state of body {name!r} became non-finite at t = {t:.6g} s: the solution blew up"
    return None


def parts_step_problem(assembly, t, y):
    """:func:`parts_problem` after a step of a run, and each rod's tip section
    (``SemiDiscrete.tip_problem``). The rods' scans and the bodies' entries are one compiled
    call (:func:`scan_parts`, its arguments kept on the assembly): this runs at every step."""
    if assembly.scan_arguments is None:
        rods = list(assembly.rods.values())
        assembly.scan_arguments = (np.array([assembly.parts[name].start for name in assembly.rods], dtype=np.int64),
                          np.array([sd.model.n_elements for sd in rods], dtype=np.int64),
                          np.array([sd.model.ds for sd in rods]),
                          min((p.slice.start for p in assembly.bodies.values()), default=assembly.size), *LIMITS)
    part, code, i, value = scan_parts(y, *assembly.scan_arguments)
    if code != OK:
        if part < len(assembly.rods):
            name = list(assembly.rods)[part]
            sd = assembly.rods[name]
            return f"rod {name!r}: {describe(sd.layout, sd.model.ds, t, code, i, value)}"
        return parts_problem(assembly, "state_problem", t, y)  # a body's: named as the state check names it
    for name, sd in assembly.rods.items():
        if sd.tip_anchored:
            problem = sd.tip_problem(t, y[assembly.parts[name]])
            if problem:
                return f"rod {name!r}: {problem}"
    return None
