"""Linearisation for control design: dy/dt ~ A dy + B du + f0 about a state.

The inputs u are the cable tensions, the actuator positions of
displacement-controlled cables and the components of point loads; the
result is a :class:`~rodmol.calibrate.linear_model.LinearModel`, which also
gives the output of the tip, a reduced form and the zero-order-hold
discretisation for model-predictive control.
"""

import numpy as np

from .. import _checks
from ..discretise.hand_tensions import tensions_by_hand
from ..discretise.schemes import DEFAULT_SCHEME
from ..discretise.system import SemiDiscrete
from ..errors import ParameterError
from ..model import Model
from ..run_arguments import check_state, check_word, initial_state
from ..systems import System
from .linear_columns import point_loads, refuse_non_finite, tendons, tip_rows
from .linear_model import LinearModel
from .system_linearize import linearize_system


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
    for found in (tendons(model, system, t, y, a, b), point_loads(model, system, t, y, tensions)):
        if found:
            names += [name for name, _, _ in found]
            columns.append(np.column_stack([column for _, column, _ in found]))
            values.append(np.array([value for _, _, value in found]))
            bounds.append(np.tile([-np.inf, np.inf], (len(found), 1)))
    tip = (tip_rows(system, t, y), ("tip x [m]", "tip y [m]", "tip z [m]"), probe.state_view(t, y).tip)
    columns = np.hstack(columns)
    drift = probe(t, y)  # the model's own rates at the operating point
    entries = [system.entry_name(i) for i in range(system.size)]
    refuse_non_finite(t, ("A", a, entries, entries), ("B", columns, entries, names),
                       ("the tip's C", tip[0], tip[1], entries), ("f0", drift[:, None], entries, ["t"]))
    return LinearModel(a, columns, inputs=tuple(names), state=y, t=t, named_outputs={"tip": tip},
                       u0=np.concatenate(values), f0=drift, bounds=np.vstack(bounds))
