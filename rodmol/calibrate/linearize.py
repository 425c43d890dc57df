"""Linearisation for control design: dy/dt ~ A dy + B dT about a state."""

import numpy as np

from ..cables import Cable
from ..discretise.schemes import DEFAULT_SCHEME
from ..discretise.system import SemiDiscrete
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
        feedback law's own dependence on the state is not in A).
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
    # The same model with every cable active and its tension set by hand: a
    # constant nonzero tension keeps each cable in the kernel.
    held = Model(model.rod, model.n_elements, gravity=model.gravity, medium=model.medium,
                 cables=[Cable(c.offset, c.anchor, 1.0, name=c.name, outside_body=c.outside_body)
                         for c in model.cables],
                 base=model.base, drag=model.drag, added_mass=model.added_mass,
                 viscosity=model.viscosity, munk_moment=model.munk_moment, markers=model.markers,
                 loads=model.loads, drag_law=model.drag_law, drag_coefficients=model.drag_coefficients)
    system = SemiDiscrete(held, scheme)
    system.tension_values[:] = tensions
    a = system.jacobian(system.atol_scale(), matrix="dense").dense(t, y)
    b = np.empty((system.size, len(model.cables)))
    for j in range(len(model.cables)):
        system.tension_values[:] = tensions
        system.tension_values[j] += 1.0
        up = system(t, y).copy()
        system.tension_values[j] -= 2.0
        b[:, j] = 0.5 * (up - system(t, y))
    system.tension_values[:] = tensions
    return a, b
