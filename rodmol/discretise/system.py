"""The semi-discrete system dy/dt = f(t, y) of a model, as the solvers see it.

:class:`SemiDiscrete` packs a :class:`rodmol.Model` once for the compiled
scheme, evaluates the time-dependent inputs (tensions, base velocities, load
values) at each call, and owns the structure the solvers need: the state
layout, the Jacobian pattern and bandwidths derived from the scheme's and the
loads' declared dependencies, and factories for the compiled Jacobian and the
block preconditioner. It is a :class:`rodmol.discretise.protocol.Discretised`,
which is all the backends read; the equilibrium solver and the fixed-step
Newton matrix also read its rod's own members (``layout``, ``model``,
``depends``, ``global_coupling``, ``update_inputs``, ``kernel_arguments``).
"""

import numpy as np

from ..inputs import knot_times
from . import external, load_entries, stencil
from .compiling import compile_signatures
from .layout import StateLayout, merge
from .preconditioner import check_structure
from .rod_scales import field_scales, first_bending_frequency, grid_damping_ratio
from .routing import CableRouting
from .sampling import Sampled, cell_properties
from .schemes import DEFAULT_SCHEME, get_scheme
from .state_checks import OK, describe, limits, scan, stall_diagnosis, state_problem, tip_problem
from .state_view import StateView
from .undeformed import undeformed_state

#: Rate [1/s] at which the quaternion norm is pulled back to 1; the exact
#: dynamics keep |Q| = 1, so this only damps integration drift (larger rates
#: did not help: the drift is each step's error, up to the tolerance; the
#: stored states are projected instead, ``StateLayout.project_quaternions``).
QUATERNION_RESTORING_RATE = 1.0
#: Smoothing speed [m/s] of |v| in the drag law, so the implicit solver's
#: Newton iterations see a differentiable right-hand side near v = 0.
DRAG_SMOOTHING_SPEED = 1e-6
#: From this many elements on, CVODE's linsolver="auto" picks the preconditioned GMRES.
GMRES_MIN_ELEMENTS = 50


#: The undeformed state under its former name (the same function: straight unless the rod has rest strains).
straight_state = undeformed_state


class SemiDiscrete:
    """The method-of-lines system of a :class:`rodmol.Model`.

    Parameters
    ----------
    model : Model
    scheme : str or Scheme
        A name from ``rodmol.SCHEMES``: ``"centred"`` (second order, default)
        or ``"upwind"`` (the paper's).

    Attributes
    ----------
    cells : tuple of (N, 3) arrays
        Kl, Kth, Vl, Vth of the cells, sampled where the scheme says.
    node_lengths : (N,) array
        Length of rod [m] each velocity node 1..N stands for.
    lightly_damped : bool
        True if even the grid's fastest mode oscillates (see
        :func:`grid_damping_ratio`), so that no mode is damped by the
        material: time integrators must then not add or remove energy.
    """

    def __init__(self, model, scheme=DEFAULT_SCHEME):
        self.model = model
        self.scheme = get_scheme(scheme)
        self.lightly_damped = bool(grid_damping_ratio(model) < 1.0)
        self.layout = StateLayout(model.n_elements)
        self._limits = limits(model.n_elements, model.ds)
        self.size = self.layout.size
        # Feedback and displacement-controlled tensions and friction read the whole state.
        self._friction = model.friction  # a property over the cables: read once, not per call
        self.global_coupling = model.feedback or self._friction
        m = model
        s_cells = self.scheme.cell_points(m.s_nodes)
        self.node_lengths = self.scheme.node_lengths(m.n_elements, m.ds)
        self.sampled = sampled = Sampled(m)
        self.cells = cell_properties(m, s_cells)
        self._undeformed = undeformed_state(m, self.scheme)
        #: The rest strains (q*, k*) of the cells, each (N, 3), local frame [-, 1/m].
        self.rest = tuple(self.layout.field(self._undeformed, f) for f in ("q", "k"))
        self._params = stencil.pack_params(*self.cells, sampled.mass, sampled.inertia, sampled.net_mass,
                                           sampled.drag_coefficient, sampled.added, *self.rest)
        self._consts = np.zeros(stencil.N_CONSTS)
        self._consts[:7] = (m.ds, QUATERNION_RESTORING_RATE, DRAG_SMOOTHING_SPEED**2,
                            1.0 if m.munk_moment else 0.0, *m.gravity)
        self._consts[stencil.SCHEME] = self.scheme.kernel
        self._consts[stencil.COMPONENTWISE_DRAG] = 1.0 if m.drag_law == "componentwise" else 0.0
        self._work = np.zeros((m.n_elements, stencil.WORK_COLUMNS))
        self.base_velocities = np.zeros(6)
        self._fixed_base = m.base.fixed
        self._setup_cables(s_cells)
        self._setup_loads()
        self.depends = merge(self.scheme.depends, external.dependency_table(set(self._kinds)))
        self._inputs_vary = bool(self.global_coupling or self._timed or self.grid_loads.values
                                 or not self._fixed_base)
        # The kernel's arguments: arrays whose contents update_inputs refreshes in place.
        self._compiled = False  # kernel_arguments waits for the compiler once
        self._args = (self._params, self._consts, self._offsets, self._weights, self.tension_values,
                      self.base_velocities, self._kinds, self._nodes, self._entry_weights,
                      self._entry_params, self.entry_values, self._work)

    def __reduce__(self):
        return SemiDiscrete, (self.model, self.scheme.name)

    def read_base_velocities_from(self, row):
        """Keep the base velocities (v0, w0) in ``row`` (6,) from now on: a view of the rows a
        body writes for all the rods clamped to it in one product (``BodyPart.move_bases``)."""
        row[:] = self.base_velocities
        old, self.base_velocities = self.base_velocities, row
        self._args = tuple(row if a is old else a for a in self._args)

    # ------------------------------------------------------------------ inputs

    def _setup_cables(self, s_cells):
        """Sort the cables by how their tension is evaluated, once: constant
        tensions are read here (slack ones are left out of the kernel), the
        time-dependent ones at each call; feedback laws read the state, so
        then every cable is evaluated at each call."""
        m = self.model
        constant = [c.tension.constant for c in m.cables]
        if self.global_coupling:
            active = list(range(len(m.cables)))
        else:
            active = [i for i, value in enumerate(constant) if value != 0.0]
        self._active = np.array(active, dtype=int)
        self.routing = CableRouting(m, s_cells)
        # The tip section carries the pull of the cables anchored there: a pull near its axial
        # stiffness EA crushes it (the Result's tip strain 1 - T / EA turns negative) though no
        # element of the state shows it (:meth:`step_problem`). The share of the last cell is 1
        # up to round-off (anchor / ds).
        self._tip_cables = np.flatnonzero(np.isclose(self.routing.weights[:, -1], 1.0, rtol=0.0, atol=1e-9))
        self._tip_stiffness = float(m.rod.stiffness(m.rod.length)[0][0]) if len(self._tip_cables) else None
        self._offsets = np.ascontiguousarray(self.routing.geometry[self._active]).reshape(
            len(active), m.n_elements, 6)
        self._path_weights = np.ascontiguousarray(self.routing.weights[self._active]).reshape(
            len(active), m.n_elements)
        self._weights = self._path_weights.copy()  # times the friction factors, refreshed
        self.tension_values = np.array([constant[i] or 0.0 for i in active])
        timed = [(j, m.cables[i]) for j, i in enumerate(active) if constant[i] is None]
        # Tensions held over a step (rodmol.control.Simulator) are read by read_held, not per call.
        self._held = [(j, cable) for j, cable in timed if cable.tension.held]
        self._timed = [(j, cable) for j, cable in timed if not cable.tension.held]
        self.read_held(0.0)

    def _setup_loads(self):
        entries = load_entries.of_model(self.model, self._undeformed)
        (self._kinds, self._nodes, self._entry_weights, self._entry_params, self.entry_values,
         self._hold_entries, self._reaction_entries) = load_entries.kernel_rows(entries, self.model, self.node_lengths)
        self.grid_loads = entries

    @property
    def entry_params(self):
        """The load entries' parameter rows (E, ``N_PARAMS``): the kernel's own
        array (a system's penalty joints write their held points into it)."""
        return self._entry_params

    @property
    def inputs_vary(self):
        """True if an input changes with time or state: :meth:`update_inputs` then
        runs at every evaluation (else the inputs were read once)."""
        return self._inputs_vary

    def update_inputs(self, t, y=None, tensions=None):
        """Evaluate the time-dependent inputs at t, in place: the tensions of
        the cables the kernel sees, the base velocities (v0, w0) and the
        values of time-dependent loads. ``y`` is read by feedback tensions;
        ``tensions`` (n_cables,) [N], if given, are used instead of the inputs."""
        m = self.model
        if not self._fixed_base:
            v0, w0 = m.base.velocities(t)
            self.base_velocities[:3], self.base_velocities[3:] = v0, w0
        if tensions is not None:
            self.tension_values[:] = np.asarray(tensions, dtype=float)[self._active]
        elif self.global_coupling:
            state = self.state_view(t, y) if y is not None else None
            self.tension_values[:] = m.tensions(t, state)
        else:
            for j, cable in self._timed:
                self.tension_values[j] = cable.tension_at(t)
        if self._friction:
            self._weights[:] = self._path_weights * self.friction_factors(y)[self._active]
        self.grid_loads.fill(t, self.entry_values)

    def read_held(self, t):
        """Read the held tensions (time inputs with ``held = True``: a stepping simulator's
        zero-order hold) at t into the kernel's arguments; the right-hand side then treats
        them as constants until the next call."""
        for j, cable in self._held:
            self.tension_values[j] = cable.tension_at(t)

    def tensions(self, t, y=None):
        """Tensions of all cables at (t, y) where they leave the base, shape (n_cables,) [N]."""
        state = self.state_view(t, y) if self.global_coupling and y is not None else None
        return self.model.tensions(t, state)

    def tension_history(self, t, states):
        """Tensions (n_t, n_cables) [N] of all cables at the frames ``states`` (n_t, size) at
        times ``t`` (n_t,), as :meth:`tensions` gives them one frame at a time (a constant
        tension is read once)."""
        cables = self.model.cables
        out = np.empty((len(t), len(cables)))
        varying = []
        for c, cable in enumerate(cables):
            if cable.tension.constant is None:
                varying.append(c)
            else:
                out[:, c] = cable.tension_at(0.0)
        if varying and self.global_coupling:
            for i, (ti, yi) in enumerate(zip(np.asarray(t, dtype=float), states)):
                out[i, varying] = [cables[c].tension_at(ti, self.state_view(ti, yi)) for c in varying]
        elif varying:  # functions of time alone: once per distinct time (a gradient's moved frames share one)
            times, at = np.unique(np.asarray(t, dtype=float), return_inverse=True)
            values = np.array([[cables[c].tension_at(ti) for c in varying] for ti in times]).reshape(-1, len(varying))
            out[:, varying] = values[at.reshape(-1)]
        return out

    def state_view(self, t, y):
        """A :class:`StateView` of ``y`` at t, with the cables' path lengths."""
        return StateView(self.layout, t, y, self.model.ds, self.routing, self.model)

    def friction_factors(self, y):
        """Tension along each cable over its tension at the base, (n_cables, N),
        for the state ``y`` (all ones at rest or without friction; reads the
        base velocities of the last :meth:`update_inputs`)."""
        if y is None or not self._friction:
            return np.ones((len(self.model.cables), self.model.n_elements))
        lay = self.layout
        return self.routing.friction_factors_of(lay.field(y, "q"), lay.field(y, "k"), lay.field(y, "v"),
                                                lay.field(y, "w"), self.base_velocities)

    def kernel_arguments(self):
        """Arguments of :func:`rodmol.discretise.stencil.rhs` after (y, out):
        the packed model, the inputs :meth:`update_inputs` refreshes, scratch.
        The first call of a process waits for the compiler (or its disk cache):
        building a system compiles nothing, so arguments are checked against it
        first (``rodmol.simulate``)."""
        if not self._compiled:
            compile_signatures()
            self._compiled = True
        return self._args

    def entry_name(self, index):
        """A readable name of state entry ``index`` (the layout's)."""
        return self.layout.entry_name(index)

    def undeformed_state(self):
        """The unloaded rod at rest in its rest shape, on this system's cells (:func:`undeformed_state`)."""
        return self._undeformed.copy()

    def project_quaternions(self, y):
        """Scale the quaternions of the states ``y`` (..., size) to unit norm, in place (the layout's)."""
        self.layout.project_quaternions(y)

    def knot_times(self):
        """The times [s] of the kinks of the model's inputs (:func:`rodmol.inputs.knot_times`)."""
        return knot_times(self.model)

    def bending_period(self):
        """The period [s] of the first bending mode (:func:`first_bending_frequency`)."""
        return 2.0 * np.pi / first_bending_frequency(self.model)

    # ------------------------------------------------------------------ checks

    def state_problem(self, t, y):
        """What is wrong with the state ``y`` at ``t`` [s], or None
        (:func:`rodmol.discretise.state_checks.state_problem`)."""
        return state_problem(self.layout, self.model.ds, t, y)

    def step_problem(self, t, y):
        """:meth:`state_problem`, and the tip section crushed by the cables anchored there
        (:func:`rodmol.discretise.state_checks.tip_problem`), of the state ``y`` at ``t`` [s]
        after a step of a run, or None."""
        # Compiled scan with its arguments kept: this runs at every step of a run.
        code, i, value = scan(y, *self._limits)
        if code != OK:
            return describe(self.layout, self.model.ds, t, code, i, value)
        return self.tip_problem(t, y)

    @property
    def tip_anchored(self):
        """True if cables are anchored at the tip (:meth:`tip_problem` then checks its section)."""
        return self._tip_stiffness is not None

    def tip_problem(self, t, y):
        """The tip section crushed at ``t`` [s] by the cables anchored there
        (:func:`rodmol.discretise.state_checks.tip_problem`), or None."""
        if self._tip_stiffness is None:
            return None
        return tip_problem(t, float(np.sum(self.tensions(t, y)[self._tip_cables])), self._tip_stiffness)

    def describe_stall(self, y):
        """The most compressed element and the largest turn of the state ``y`` of a stalled run."""
        return stall_diagnosis(self.layout, self.model.ds, y)

    # ------------------------------------------------------------------ evaluation

    def __call__(self, t, y, out=None):
        """dy/dt at (t, y); writes into ``out`` if given (CVODE's ``yp``)."""
        if out is None:
            out = np.empty(self.size)
        if self._inputs_vary:
            self.update_inputs(t, y)
        stencil.rhs(y, out, *(self._args if self._compiled else self.kernel_arguments()))
        return out

    def rest_rates(self, t, y, out, load_factor=1.0, tensions=None, held_factor=None):
        """dy/dt at (t, y) with every applied load (gravity, tensions, external
        load values but a system's rod contacts) scaled by ``load_factor`` and the held points'
        displacements from rest (rodmol.Hold) by ``held_factor`` (default:
        ``load_factor``), for the equilibrium's continuation. ``tensions``
        (n_cables,) [N] replace the cables' inputs (the equilibrium of a
        feedback law iterates on them)."""
        self.update_inputs(t, y, tensions)
        scaled = (self.tension_values, self._consts[4:7], self.entry_values)  # views, in place
        saved = [inputs.copy() for inputs in scaled]
        for inputs in scaled:
            inputs *= load_factor
        if held_factor is not None:  # a hold's value is its held displacement
            self.entry_values[self._hold_entries] = saved[2][self._hold_entries] * held_factor
        self.entry_values[self._reaction_entries] = saved[2][self._reaction_entries]
        try:
            stencil.rhs(y, out, *self.kernel_arguments())
        finally:
            for inputs, value in zip(scaled, saved):
                inputs[:] = value
        return out

    def rates(self, t, states):
        """dy/dt at each of the frames ``states`` (n_t, size) at times ``t`` (n_t,)."""
        states = np.asarray(states, dtype=float)
        out = np.empty_like(states)
        for i, (ti, yi) in enumerate(zip(np.asarray(t, dtype=float), states)):
            self(float(ti), yi, out[i])
        return out

    def frames(self, t, states):
        """Per-frame sectional stresses and external loads, from the same kernel.

        Returns (stress (n_t, N, 6): Kelvin-Voigt N, M at the strain nodes
        [N, N m]; loads (n_t, N, 6): external force and moment densities at the
        velocity nodes 1..N [N/m, N m/m]), local frame.
        """
        states = np.asarray(states, dtype=float)
        n_t, n = len(states), self.model.n_elements
        stress, loads = np.empty((n_t, n, 6)), np.empty((n_t, n, 6))
        out = np.empty(self.size)
        for i, (ti, yi) in enumerate(zip(np.asarray(t, dtype=float), states)):
            self(float(ti), yi, out)
            stress[i] = self._work[:, stencil.WORK_STRESS:stencil.WORK_STRESS + 6]
            loads[i] = self._work[:, stencil.WORK_LOADS:stencil.WORK_LOADS + 6]
        return stress, loads

    # ------------------------------------------------------------------ structure

    def pattern(self):
        """Structural Jacobian pattern (bool, size x size). Feedback tensions
        are global couplings and are not in it (see ``global_coupling``)."""
        return self.layout.pattern(self.depends, self.layout.header_pattern())

    def bandwidths(self):
        """(lower, upper) half-bandwidths of :meth:`pattern`."""
        return self.layout.bandwidths(self.depends)

    def linear_solvers(self):
        """CVODE's linear solvers on one rod, each with its Jacobian under ``jacobian="auto"``
        (:meth:`rodmol.discretise.protocol.Discretised.linear_solvers`); ``"auto"`` picks
        "gmres" from :data:`GMRES_MIN_ELEMENTS` elements on or when the system has a global
        coupling (feedback tensions), if the block preconditioner solves its structure, else
        "band". GMRES's Jacobian-vector products are differences of the full right-hand side,
        so they carry the global coupling that any banded Jacobian leaves out (20x fewer
        steps on a P controller, N = 12). The compiled Jacobian is measured fastest with
        "sparse"; with the band solvers, whose ``jacfn`` template is a dense (n, n) array,
        SUNDIALS' own differences are (``docs/performance.md``)."""
        solvers = {"gmres": "compiled", "band": "sundials", "lapackband": "sundials", "sparse": "compiled",
                   "dense": "sundials"}
        big = self.layout.n_blocks >= GMRES_MIN_ELEMENTS
        if not ((big or self.global_coupling) and _block_solvable(self.depends)):
            solvers = {"band": solvers.pop("band"), **solvers}
        return solvers

    def atol_scale(self):
        """Typical magnitude of each state entry (see :func:`field_scales`)."""
        return self.layout.scales(field_scales(self.model))

    def jacobian(self, scale, matrix="band"):
        """The compiled finite-difference Jacobian (scikit-sundae ``jacfn``)."""
        from .jacobian import CompiledJacobian

        return CompiledJacobian(self, scale, matrix)

    def preconditioner(self, scale):
        """The exact block preconditioner of CVODE's Newton matrix."""
        from .preconditioner import BlockPreconditioner

        return BlockPreconditioner(self, scale)


def _block_solvable(depends):
    """True if the block preconditioner solves the structure of the dependency table ``depends`` exactly."""
    try:
        check_structure(depends)
    except ValueError:
        return False
    return True
