"""The columns a linear model is made of, for a rod on its own or in a system: the tip's
rows, the displacement-controlled cables' and the point loads' input columns, and the
refusal of non-finite matrices (:mod:`rodmol.calibrate.linearize`,
:mod:`rodmol.calibrate.system_linearize`)."""

import numpy as np

from .._differences import central_columns
from ..discretise import load_entries, stencil
from ..discretise.layout import HEADER
from ..errors import ParameterError
from ..loads import PointForce, PointMoment

#: Step [-] of the central differences of the cables' path lengths in the
#: strains (a smooth geometric function: its truncation error is about 1e-14).
_STRAIN_STEP = 1e-7


def refuse_non_finite(t, *matrices):
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


def tip_rows(system, t, y):
    """d tip / d y (3, size): the tip rebuilt from the orientations and strains
    as ``Result.tip`` and ``StateView.tip`` give it (not the integrated position
    u(L), which differs from it by the time discretisation's drift), by central
    differences of that geometric function over the entries it reads: the base
    pose (which moves with a moving base or a system's free body) and the
    orientations and strains."""
    layout = system.layout
    entries = np.concatenate([np.arange(HEADER)] + [field_rows(layout, f).ravel() for f in ("Q", "q", "k")])
    h = _STRAIN_STEP * np.maximum(np.abs(y[entries]), system.atol_scale()[entries])
    rows = np.zeros((3, layout.size))
    rows[:, entries] = central_columns(lambda state: system.state_view(t, state).tip, y, entries, h)
    return rows


def tendons(model, system, t, y, a, b, offset=0):
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
    rows = offset + np.hstack([field_rows(layout, "q"), field_rows(layout, "k")]).ravel()
    out = []
    for j, cable in motors:
        stiffness, gain = cable.tension.slopes(t, lengths[j])
        a[:, rows] += np.outer(b[:, j], stiffness * d_length[:, j])
        out.append((f"{cable.name} displacement [m]", b[:, j] * gain, float(cable.displacement.value(t))))
    return out


def field_rows(layout, name):
    """(N, width) indices of field ``name`` in the state vector."""
    return layout.field(np.arange(layout.size), name)


def point_loads(model, system, t, y, tensions):
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
