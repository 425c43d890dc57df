"""Linearisation for control design: dy/dt ~ A dy + B du + f0 about a state.

The inputs u are the cable tensions, the actuator positions of
displacement-controlled cables and the components of point loads; the
result is a :class:`~rodmol.calibrate.linear_model.LinearModel`, which also
gives the output of the tip, a reduced form and the zero-order-hold
discretisation for model-predictive control.
"""

import numpy as np

from .. import _checks
from .._differences import central_columns
from ..discretise import load_entries, stencil
from ..discretise.layout import HEADER
from ..discretise.schemes import DEFAULT_SCHEME
from ..discretise.system import SemiDiscrete, tensions_by_hand
from ..errors import ParameterError
from ..loads import PointForce, PointMoment
from ..model import Model
from ..simulate import check_state, check_word, initial_state
from ..systems import System
from .linear_model import LinearModel

#: Step [-] of the central differences of the cables' path lengths in the
#: strains (a smooth geometric function: its truncation error is about 1e-14).
_STRAIN_STEP = 1e-7


def linearize(model, state, t=0.0, scheme=DEFAULT_SCHEME):
    """State and input Jacobians of the semi-discrete system at (``state``, ``t``).

    Parameters
    ----------
    model : Model or System
        A :class:`rodmol.System`: see
        :func:`rodmol.calibrate.system_linearize.linearize_system`.
    state : (size,) state vector, ``"equilibrium"`` or ``"straight"``
        A state (e.g. ``rodmol.equilibrium(model, t)``, ``Result.states[k]``),
        checked as ``simulate`` checks its ``initial`` (finite, each element
        neither inverted nor torn, each quaternion's norm within 0.1 of 1);
        or, by name, the static equilibrium under the loads at ``t`` or the
        rod at rest in its rest shape.
    t : float
        Time [s] at which the inputs (tensions, base motion, loads) are read.
    scheme : str
        The spatial scheme (``rodmol.SCHEMES``), as given to ``simulate``.

    Returns
    -------
    LinearModel
        ``A`` (size, size) d f / d y with every input held: the tension of a
        tension-driven cable (open loop: a feedback law's own dependence on
        the state is not in A), the actuator position of a displacement-
        controlled cable (so the tendon's stiffness, its tension's dependence
        on the path length, is in A). With friction, whose factors along each
        cable depend on the sliding of its whole path, A comes from central
        differences instead of the compiled Jacobian.
        ``B`` (size, n_inputs), one column per input, named in ``inputs``:

        - ``"<cable> tension [N]"``, every cable in the model's order: d f / d T,
          a tension added to the cable's own (slack cables included). The
          right-hand side is affine in the tensions, so these are exact up
          to rounding.
        - ``"<cable> displacement [m]"``, each displacement-controlled cable:
          d f / d z of its actuator position (0 where the tendon is slack).
        - ``"<load> x|y|z [N]"`` (``[N m]`` for a moment), three per point
          force or moment, the components in the load's own frame (global for
          ``frame="global"``, the section's for ``"local"``): exact as well.

        It unpacks as before: ``A, B = linearize(...)``. It carries its operating
        point: ``state``, ``t``, the inputs' values ``u0`` there (the tensions,
        actuator positions and load components, in the order of ``inputs``), the
        tip there (``output("tip").y0``), the inputs' ``bounds`` (tensions >= 0 N)
        and the drift ``f0``, the rates at ``state`` (zero at an equilibrium), so
        dy/dt ~ A dy + B du + f0 holds about a state in motion too.

    Raises
    ------
    ParameterError
        A bad ``state`` (named, before any work), or rates that are not finite
        about it (A, B or the tip's C would hold non-finite entries).
    """
    if isinstance(model, System):
        from .system_linearize import linearize_system  # it builds on this module's parts

        return linearize_system(model, state, t, scheme)
    if not isinstance(model, Model):
        raise ParameterError(f"`model` must be a rodmol.Model or a rodmol.System, got {model!r}")
    t = _checks.finite("t", t)
    check_word("state", state)
    probe = SemiDiscrete(model, scheme)
    y = initial_state(probe, state, t) if isinstance(state, str) else check_state("state", state, probe, t)
    tensions = model.tensions(t, probe.state_view(t, y) if model.feedback else None)
    system = SemiDiscrete(tensions_by_hand(model), scheme)

    def rates(x, cable_tensions):
        return system.rest_rates(t, x, np.empty(system.size), tensions=cable_tensions)

    if system.global_coupling:  # friction couples each cable's whole path: no band to colour
        step = 1e-6 * system.atol_scale()
        a = np.column_stack([(rates(y + e, tensions) - rates(y - e, tensions)) / (2 * h)
                             for e, h in zip(np.diag(step), step)])
    else:
        system.tension_values[:] = tensions
        a = system.jacobian(system.atol_scale(), matrix="dense").dense(t, y)
    b = np.empty((system.size, len(model.cables)))
    for j, unit in enumerate(np.eye(len(model.cables))):
        b[:, j] = 0.5 * (rates(y, tensions + unit) - rates(y, tensions - unit))
    names = [f"{c.name} tension [N]" for c in model.cables]
    columns, values = [b], [np.asarray(tensions, dtype=float)]
    bounds = [np.tile([0.0, np.inf], (len(model.cables), 1))]  # cables only pull
    for found in (_tendons(model, system, t, y, a, b), _point_loads(model, system, t, y, tensions)):
        if found:
            names += [name for name, _, _ in found]
            columns.append(np.column_stack([column for _, column, _ in found]))
            values.append(np.array([value for _, _, value in found]))
            bounds.append(np.tile([-np.inf, np.inf], (len(found), 1)))
    tip = (_tip_rows(system, t, y), ("tip x [m]", "tip y [m]", "tip z [m]"), probe.state_view(t, y).tip)
    columns = np.hstack(columns)
    drift = probe(t, y)  # the model's own rates at the operating point
    entries = [system.entry_name(i) for i in range(system.size)]
    _refuse_non_finite(t, ("A", a, entries, entries), ("B", columns, entries, names),
                       ("the tip's C", tip[0], tip[1], entries), ("f0", drift[:, None], entries, ["t"]))
    return LinearModel(a, columns, inputs=tuple(names), state=y, t=t, named_outputs={"tip": tip},
                       u0=np.concatenate(values), f0=drift, bounds=np.vstack(bounds))


def _refuse_non_finite(t, *matrices):
    """Raise a ParameterError if one of ``matrices``, (name, matrix, row names, column
    names), has a non-finite entry: the rates are not finite about this state (a velocity
    so large that the drag overflows, say), and a controller designed on them would be too."""
    for name, matrix, rows, columns in matrices:
        bad = ~np.isfinite(matrix)
        if bad.any():
            i, j = np.argwhere(bad)[0]
            first = f"d {rows[i]} / d {columns[j]} = {float(matrix[i, j])!r}"
            raise ParameterError(f"linearize: {name} has {int(bad.sum())} non-finite entries about this "
                                 f"`state` at t = {t:.6g} s (the first: {first}); the model's rates are "
                                 "not finite there")


def _tip_rows(system, t, y):
    """d tip / d y (3, size): the tip rebuilt from the orientations and strains
    as ``Result.tip`` and ``StateView.tip`` give it (not the integrated position
    u(L), which differs from it by the time discretisation's drift), by central
    differences of that geometric function over the entries it reads: the base
    pose (which moves with a moving base or a system's free body) and the
    orientations and strains."""
    layout = system.layout
    entries = np.concatenate([np.arange(HEADER)] + [_field_rows(layout, f).ravel() for f in ("Q", "q", "k")])
    h = _STRAIN_STEP * np.maximum(np.abs(y[entries]), system.atol_scale()[entries])
    rows = np.zeros((3, layout.size))
    rows[:, entries] = central_columns(lambda state: system.state_view(t, state).tip, y, entries, h)
    return rows


def _tendons(model, system, t, y, a, b, offset=0):
    """The displacement-controlled cables: their tendon law's dependence on the
    path length is added to ``a`` in place; returns their (name, d f / d z, z [m]) columns.
    ``y`` is the rod's state, whose entries start at column ``offset`` of ``a`` (a
    rod in a system); ``b`` holds the rod's tension columns over ``a``'s rows."""
    motors = [(j, c) for j, c in enumerate(model.cables) if c.actuated]
    if not motors:
        return []
    layout, n = system.layout, model.n_elements
    strains = np.hstack([layout.field(y, "q"), layout.field(y, "k")])  # the path lengths read only q and k
    lengths = system.routing.lengths(strains[:, :3], strains[:, 3:])
    typical = np.tile([1.0] * 3 + [1.0 / model.rod.length] * 3, (n, 1))  # q ~ 1, k ~ 1/L
    h = _STRAIN_STEP * np.maximum(np.abs(strains), typical)
    d_length = np.empty((n, 6, len(model.cables)))
    both = np.empty((2, n, 6))
    for element, c in np.ndindex(n, 6):
        both[:] = strains
        both[0, element, c] += h[element, c]
        both[1, element, c] -= h[element, c]
        moved = system.routing.lengths(both[..., :3], both[..., 3:])
        d_length[element, c] = (moved[0] - moved[1]) / (2 * h[element, c])
    d_length = d_length.reshape(6 * n, -1)
    rows = offset + np.hstack([_field_rows(layout, "q"), _field_rows(layout, "k")]).ravel()
    out = []
    for j, cable in motors:
        stiffness, gain = cable.tension.slopes(t, lengths[j])
        a[:, rows] += np.outer(b[:, j], stiffness * d_length[:, j])
        out.append((f"{cable.name} displacement [m]", b[:, j] * gain, float(cable.displacement.value(t))))
    return out


def _field_rows(layout, name):
    """(N, width) indices of field ``name`` in the state vector."""
    return layout.field(np.arange(layout.size), name)


def _point_loads(model, system, t, y, tensions):
    """(name, d f / d component, the component's value) of the point forces and moments: the
    kernel's load values moved by one unit, central (the right-hand side is affine in them)."""
    out, start = [], 0
    system.update_inputs(t, y, tensions)
    values = system.entry_values
    held = values.copy()
    rates = np.empty((2, system.size))
    for load in model.loads:
        count = load_entries.count(load, model.s_nodes)
        rows = slice(start, start + count)
        start += count
        if not isinstance(load, (PointForce, PointMoment)):
            continue
        unit = "N" if isinstance(load, PointForce) else "N m"
        vector = np.asarray(getattr(load, load._what).value(t), dtype=float)  # in the load's frame
        for c, axis in enumerate("xyz"):
            for side, sign in enumerate((1.0, -1.0)):
                values[rows, c] = held[rows, c] + sign
                stencil.rhs(y, rates[side], *system.kernel_arguments())
                values[rows, c] = held[rows, c]
            out.append((f"{load.name} {axis} [{unit}]", 0.5 * (rates[0] - rates[1]), float(vector[c])))
    return out
