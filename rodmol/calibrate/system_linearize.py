"""Linearisation of a :class:`rodmol.System`: dy/dt ~ A dy + B du over the
whole state of its rods and bodies (``Assembly.parts``), about a state.

The inputs are each rod's (:func:`rodmol.linearize`'s, named ``"<rod>/"`` and
the rod's own name: its cables' tensions, its displacement-controlled cables'
actuator positions, its point loads' components) and each driven body's
velocities (its BaseMotion's, body frame), which its pose integrates and its
clamped rods' bases and joints follow. The rates are the Assembly's own: the
rods' cables are held inputs (:class:`rodmol.control.held.Held`, as a stepping
simulator holds them) set around the operating point, the driven bodies'
velocities are offset by held amounts, and the columns are central differences
of the whole system's rates (A coloured over the Assembly's Jacobian pattern).
"""

from dataclasses import replace

import numpy as np

from .. import _checks
from ..base_motion import BaseMotion
from ..cables import Tension
from ..control.held import Held
from ..discretise.assembly import Assembly
from ..discretise.system_jacobian import column_groups
from ..run_arguments import check_state, check_word, initial_state
from .linear_columns import point_loads, refuse_non_finite, tendons, tip_rows
from .linear_model import LinearModel

#: Relative step of A's central differences (times max(|y_j|, the entry's scale)).
STEP = 1e-6
#: Step of a driven velocity's differences, times its scale (the rates are affine in it
#: but for friction, whose law changes over the slip speed, which the scale is then below).
VELOCITY_STEP = 1e-3
#: A driven body's velocity inputs, body frame.
VELOCITY_AXES = ("v x [m/s]", "v y [m/s]", "v z [m/s]", "w x [rad/s]", "w y [rad/s]", "w z [rad/s]")


def linearize_system(system, state, t=0.0, scheme=None):
    """State and input Jacobians of a System's rates at (``state``, ``t``).

    Parameters
    ----------
    system : System
    state : (size,) state vector, ``"equilibrium"`` or ``"straight"``
        As for a rod (:func:`rodmol.linearize`), checked as ``simulate`` checks
        a System's ``initial``; by name the system's static equilibrium at
        ``t`` (its free bodies held to the world) or its rods at rest in their
        rest shapes and its bodies at their initial poses.
    t : float
    scheme : str, optional
        The spatial scheme of every rod (default the system's default).

    Returns
    -------
    LinearModel
        ``A`` (size, size) with every input held (as for a rod: a feedback law
        open, a displacement-controlled cable's actuator position held so its
        tendon's stiffness is in A). ``B`` one column per input, named in
        ``inputs``: ``"<rod>/<cable> tension [N]"``, ``"<rod>/<cable>
        displacement [m]"``, ``"<rod>/<load> x [N]"`` (as a rod's, the rod's
        name first), then ``"<body> v x [m/s]"`` ... ``"<body> w z [rad/s]"``
        for each driven body. Named outputs (:meth:`LinearModel.output`):
        ``"<rod>/tip"`` each rod's tip [m] (as ``Result.tip``) and
        ``"<body>/position"`` each body's origin [m], global.

    Raises
    ------
    ParameterError
        A bad ``state`` (before any work), or rates that are not finite about it.
    """
    t = _checks.finite("t", t)
    check_word("state", state)
    probe = Assembly(system, scheme)
    y = initial_state(probe, state, t) if isinstance(state, str) else check_state("state", state, probe, t)
    knobs = _Knobs(system, probe, t, y)
    assembly = Assembly(knobs.system, scheme)

    def rates(x):
        return assembly(t, x).copy()

    a = _state_columns(assembly, rates, y)
    names, columns, values, pulls = [], [], [], []  # pulls: True for a tension (cables only pull)
    for rod, sd in assembly.rods.items():
        part, model = assembly.parts[rod], system.rods[rod]
        b = np.column_stack([knobs.tension_column(assembly, rod, j, rates, y) for j in range(len(model.cables))]
                            or [np.zeros((assembly.size, 0))])
        names += [f"{rod}/{c.name} tension [N]" for c in model.cables]
        columns.append(b)
        values += list(knobs.tensions[rod])
        pulls += [True] * len(model.cables)
        found = tendons(model, sd, t, y[part], a, b, offset=part.start)
        rates(y)  # each rod's base velocities and joints at y, for its own loads' columns
        for name, column, value in point_loads(model, sd, t, np.ascontiguousarray(y[part]), knobs.tensions[rod]):
            full = np.zeros(assembly.size)  # a rod's loads move its own rates only
            full[part] = column
            found.append((name, full, value))
        for name, column, value in found:
            names.append(f"{rod}/{name}")
            columns.append(column[:, None])
            values.append(value)
            pulls.append(False)
    for body in knobs.driven:
        names += [f"{body} {axis}" for axis in VELOCITY_AXES]
        columns.append(np.column_stack([knobs.velocity_column(body, k, rates, y) for k in range(6)]))
        values += list(np.concatenate(system.bodies[body].motion.velocities(t)))
        pulls += [False] * 6
    b = np.hstack(columns) if columns else np.zeros((assembly.size, 0))
    named = _outputs(assembly, t, y)
    drift = probe(t, y)  # the system's own rates at the operating point
    entries = [assembly.entry_name(i) for i in range(assembly.size)]
    refuse_non_finite(t, ("A", a, entries, entries), ("B", b, entries, names),
                       *((f"the C of {key!r}", c, rows, entries) for key, (c, rows, _) in named.items()),
                       ("f0", drift[:, None], entries, ["t"]))
    bounds = np.array([[0.0, np.inf] if pull else [-np.inf, np.inf] for pull in pulls]).reshape(-1, 2)
    return LinearModel(a, b, inputs=tuple(names), state=y, t=t, named_outputs=named, u0=np.array(values, float),
                       f0=drift, bounds=bounds)


class _Knobs:
    """The System with its inputs held: each rod's cables' tensions and each driven body's
    velocity offsets, set from outside between evaluations of the rates."""

    def __init__(self, system, probe, t, y):
        self.t = t
        self.tensions = {name: sd.tensions(t, y[probe.parts[name]]) for name, sd in probe.rods.items()}
        self.held, rods = {}, {}
        for name, model in system.given_rods.items():
            self.held[name] = [Held(float(value), 1) for value in self.tensions[name]]
            rods[name] = model.replace(cables=[
                replace(c, tension=Tension(knob), displacement=None, compliance=None, base_to_actuator=0.0,
                        rest_length=None) for c, knob in zip(model.cables, self.held[name])])
        self.driven = [name for name, body in system.bodies.items() if body.driven]
        self.offsets, bodies = {}, {}
        for name in self.driven:
            body = system.bodies[name]
            self.offsets[name] = offset = np.zeros(6)
            motion = BaseMotion(_Offset(body.motion, offset, 0), _Offset(body.motion, offset, 1),
                                body.motion.position, body.motion.rotation)
            bodies[name] = replace(body, motion=motion, position=None, rotation=None)
        self.system = system.replace(rods=rods, bodies=bodies)
        scales = probe.body_scales()
        self.scale = np.array([scales["v"]] * 3 + [scales["w"]] * 3)

    def tension_column(self, assembly, rod, j, rates, y):
        """d f / d T_j of rod ``rod``: the held tension one newton up, less the rates at y
        (affine in it: exact; not down, a cable's tension is never negative)."""
        knob, sd = self.held[rod][j], assembly.rods[rod]
        sides = []
        for step in (1.0, 0.0):
            knob.current = self.tensions[rod][j] + step
            sd.read_held(self.t)
            sides.append(rates(y))
        return sides[0] - sides[1]

    def velocity_column(self, body, k, rates, y):
        """d f / d (v, w)_k of a driven body, body frame, by central differences."""
        h = VELOCITY_STEP * self.scale[k]
        offset, sides = self.offsets[body], []
        for sign in (1.0, -1.0):
            offset[k] = sign * h
            sides.append(rates(y))
        offset[k] = 0.0
        return (sides[0] - sides[1]) / (2 * h)


class _Offset:
    """A driven body's velocity (``which`` 0) or angular velocity (1) [body frame]: its
    motion's plus the held ``offset``'s part."""

    def __init__(self, motion, offset, which):
        self.motion, self.offset, self.which = motion, offset, which

    def __call__(self, t):
        return self.motion.velocities(t)[self.which] + self.offset[3 * self.which:3 * self.which + 3]


def _state_columns(assembly, rates, y):
    """A = d f / d y by central differences: coloured over the Assembly's pattern, or every
    column alone where a rod's rates read its whole state (cable friction)."""
    size = assembly.size
    h = STEP * np.maximum(np.abs(y), assembly.atol_scale())
    if any(sd.global_coupling for sd in assembly.rods.values()):
        a = np.empty((size, size))
        for j in range(size):
            up, down = y.copy(), y.copy()
            up[j] += h[j]
            down[j] -= h[j]
            a[:, j] = (rates(up) - rates(down)) / (2 * h[j])
        return a
    pattern = assembly.pattern()
    pattern.sort_indices()
    a = np.zeros((size, size))
    for group in column_groups(pattern):
        up, down = y.copy(), y.copy()
        up[group] += h[group]
        down[group] -= h[group]
        difference = rates(up) - rates(down)
        for j in group:
            rows = pattern.indices[pattern.indptr[j]:pattern.indptr[j + 1]]
            a[rows, j] = difference[rows] / (2 * h[j])
    return a


def _outputs(assembly, t, y):
    """{"<rod>/tip": (C (3, size), names, the tip at y [m]), "<body>/position": ...} over the
    whole state."""
    named = {}
    for rod, sd in assembly.rods.items():
        part = assembly.parts[rod]
        rod_state = np.ascontiguousarray(y[part])
        c = np.zeros((3, assembly.size))
        c[:, part] = tip_rows(sd, t, rod_state)
        named[f"{rod}/tip"] = (c, tuple(f"{rod}/tip {axis} [m]" for axis in "xyz"),
                               sd.state_view(t, rod_state).tip)
    for body, part in assembly.bodies.items():
        c = np.zeros((3, assembly.size))
        c[np.arange(3), np.arange(part.fields["x"].start, part.fields["x"].stop)] = 1.0
        named[f"{body}/position"] = (c, tuple(f"{body}/position {axis} [m]" for axis in "xyz"), c @ y)
    return named
