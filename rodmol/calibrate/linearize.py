"""Linearisation for control design: dy/dt ~ A dy + B dT about a state."""

import numpy as np

from ..discretise.schemes import DEFAULT_SCHEME
from ..discretise.system import SemiDiscrete, tensions_by_hand
from ..errors import ParameterError
from ..model import Model


def linearize(model, state, t=0.0, scheme=DEFAULT_SCHEME):
    """State and input Jacobians of the semi-discrete system at (``state``, ``t``).

    Parameters
    ----------
    model : Model
    state : (size,) state vector (e.g. ``rodmol.equilibrium(model, t)``) or
        ``"equilibrium"`` for the static equilibrium under the loads at ``t``.
    t : float
        Time [s] at which the inputs (tensions, base motion, loads) are read.
    scheme : str
        The spatial scheme (``rodmol.SCHEMES``), as given to ``simulate``.

    Returns
    -------
    A : (size, size) d f / d y, from the system's compiled Jacobian, with the
        cable tensions held at their values at (state, t) (open loop: a
        feedback law's or an actuator's own dependence on the state is not in
        A). With friction, whose factors along each cable depend on the
        sliding of its whole path, A comes from central differences instead.
    B : (size, n_cables) d f / d T [per N], one column per cable in the
        model's order. The right-hand side is affine in the tensions (the
        cable loads are T times a function of the state), so B is exact up
        to rounding, slack cables included.
    """
    if not isinstance(model, Model):
        raise ParameterError(f"`model` must be a rodmol.Model, got {model!r}")
    if isinstance(state, str) and state == "equilibrium":
        from ..solve.equilibrium import equilibrium

        state = equilibrium(model, t, scheme=scheme)
    y = np.asarray(state, dtype=float)
    probe = SemiDiscrete(model, scheme)
    layout_size = probe.size
    if y.shape != (layout_size,) or not np.all(np.isfinite(y)):
        raise ParameterError(f"`state` must be {layout_size} finite numbers (the state size), got shape {y.shape}")
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
    return a, b
