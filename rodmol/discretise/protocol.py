"""What every discretised system offers the solvers: :class:`Discretised`.

A model the user builds (a :class:`rodmol.Model`, a :class:`rodmol.System`)
is discretised once per run into a method-of-lines system dy/dt = f(t, y);
every backend (:data:`rodmol.solve.backends.BACKENDS`: CVODE, RK23,
generalized-alpha), the per-step checks (:class:`rodmol.solve.watch.Watch`)
and :func:`rodmol.simulate` read that system through this protocol only.
:class:`rodmol.discretise.system.SemiDiscrete` (one rod) and
:class:`rodmol.discretise.assembly.Assembly` (rods and rigid bodies) satisfy
it.
"""

from typing import Protocol, runtime_checkable

import numpy as np

#: The linear solvers of CVODE's Newton systems a discretised system may offer
#: (:meth:`Discretised.linear_solvers`): GMRES preconditioned by the system's
#: own :meth:`Discretised.preconditioner`, SUNDIALS' band LU (its own or
#: LAPACK's) on :meth:`Discretised.bandwidths`, SuperLU_MT on
#: :meth:`Discretised.pattern`, and dense LU.
LINEAR_SOLVERS = ("gmres", "band", "lapackband", "sparse", "dense")
#: Where a direct linear solver's Jacobian comes from: the system's
#: :meth:`Discretised.jacobian` ("compiled"), or SUNDIALS' own differences
#: (scikit-sundae's coloured ones on the pattern for "sparse").
JACOBIANS = ("compiled", "sundials")


@runtime_checkable
class Discretised(Protocol):
    """A discretised system dy/dt = f(t, y) of any kind of model, as the solvers see it.

    To add a new kind of model: write its discretised system (a class with
    the members below; state entries in one flat vector), one
    :class:`rodmol.run_kinds.RunKind` naming the user's class, this system
    and its result, and check it against this protocol (``isinstance(system,
    Discretised)`` and a call of each member, as
    ``tests/discretise/test_protocol.py`` does for a rod and a system). The
    backends, the per-step checks, the failure messages, chunked output and
    resuming then work unchanged.

    Attributes
    ----------
    size : int
        Number of state entries.
    scheme : rodmol.discretise.schemes.Scheme
        The spatial scheme (what a run records and a resumed run checks).
    inputs_vary : bool
        True if the inputs (cable tensions, loads, base motion) are
        evaluated at each call and must be read again at the frames kept
        after a failure (:func:`rodmol.solve.outputs.keep_before_failure`);
        the system then also has ``update_inputs(t, y)``, which raises where
        a user's function fails. False: the run's own calls are the check.
    lightly_damped : bool
        True if some mode of the grid is not damped by the material: CVODE's
        ``max_order="auto"`` is then 2 (BDF2 is A-stable) and a stalled run
        says so.

    Methods
    -------
    __call__(t, y, out=None)
        The rates dy/dt at time ``t`` [s] and state ``y`` (size,), written
        into ``out`` if given (CVODE's in-place ``yp``), returned. May raise
        only where a user's function fails (an input's callable).
    undeformed_state()
        The state at rest in its rest shape, unloaded (``initial="straight"``).
    atol_scale()
        Typical magnitude of each entry (size,): ``atol = rtol * atol_scale()``
        by default, and CVODE's Jacobian and preconditioner steps scale by it.
    entry_name(index)
        A readable name of state entry ``index`` for messages
        (``"k[2] of element 7"``, ``"rod 'arm' (v[0] of element 3)"``).
    project_quaternions(y)
        Scale every orientation quaternion of the states ``y`` (..., size) to
        unit norm, in place (the frames a run keeps).
    knot_times()
        The times [s] where the inputs have kinks (``rodmol.inputs.Knots``):
        CVODE stops its steps there rather than stride over a short ramp.
    bending_period()
        The period [s] of the first bending mode (of a system of rods, its
        rods' shortest): the time scale of the motion (generalized-alpha's
        ``dt="auto"`` is a hundredth of it).
    linear_solvers()
        The linear solvers CVODE may use on this system, names from
        :data:`LINEAR_SOLVERS`, each mapped to where its Jacobian comes from
        under ``jacobian="auto"`` (a name from :data:`JACOBIANS`; "compiled"
        for "gmres" means :meth:`preconditioner`): an ordered dict whose
        first entry is what ``linsolver="auto"`` picks. Any other is refused
        naming these.
    pattern()
        The structural Jacobian pattern, bool (size, size), dense or scipy
        sparse: where df_i/dy_j may be nonzero ("sparse", colourings).
    bandwidths()
        (lower, upper) half-bandwidths of the pattern ("band").
    jacobian(scale, matrix)
        The compiled Jacobian (scikit-sundae's ``jacfn``: ``jac(t, y, fy,
        JJ)``, with ``sparsity`` if ``matrix == "sparse"``) of the kind
        ``matrix`` ("band", "sparse", "dense"); ``scale`` (size,): typical
        magnitude of each entry. Raises ValueError for a kind it has not.
    preconditioner(scale)
        The preconditioner of CVODE's Newton matrix I - gamma J for GMRES:
        ``setup(t, y, fy, jok, jnew, gamma)`` and ``solve(t, y, fy, r, z,
        gamma, delta, lr)`` as scikit-sundae calls them, and the counts
        ``jac_evals``, ``setups``, ``solves`` for the run's statistics.
        Raises ValueError if the system has none for its structure.
    state_problem(t, y)
        A sentence naming what is wrong with state ``y`` at ``t`` [s]
        (non-finite, an element inverted or torn, a quaternion off unit
        norm, ... naming the part and entry), or None: a user's initial
        state and an equilibrium are refused with it.
    step_problem(t, y)
        The same check after an accepted step of a run, with the checks that
        only a run's state needs (a rod's tip section crushed by the cables
        anchored there): a run stops with the sentence.
    describe_stall(y)
        What the state ``y`` of a run that stalled says about why (a rod's
        most compressed element and largest turn), one or two sentences.

    A system may also offer ``jacobian_times(scale)``: scikit-sundae's
    ``jactimes.solvefn`` ``(t, y, fy, v, Jv)``, CVODE's GMRES then takes its
    products J v instead of its own differences (a system with
    sensitivities, :class:`rodmol.discretise.sensitivity_system.SensitivitySystem`).
    """

    size: int
    scheme: object
    inputs_vary: bool
    lightly_damped: bool

    def __call__(self, t: float, y: np.ndarray, out: np.ndarray = None) -> np.ndarray: ...

    def undeformed_state(self) -> np.ndarray: ...

    def atol_scale(self) -> np.ndarray: ...

    def entry_name(self, index: int) -> str: ...

    def project_quaternions(self, y: np.ndarray) -> None: ...

    def knot_times(self) -> np.ndarray: ...

    def bending_period(self) -> float: ...

    def linear_solvers(self) -> dict: ...

    def pattern(self): ...

    def bandwidths(self) -> tuple: ...

    def jacobian(self, scale: np.ndarray, matrix: str): ...

    def preconditioner(self, scale: np.ndarray): ...

    def state_problem(self, t: float, y: np.ndarray) -> str | None: ...

    def step_problem(self, t: float, y: np.ndarray) -> str | None: ...

    def describe_stall(self, y: np.ndarray) -> str: ...


def pattern_bandwidths(pattern):
    """(lower, upper) half-bandwidths of a Jacobian ``pattern`` (bool, dense or scipy sparse)."""
    from scipy import sparse

    rows, cols = sparse.coo_matrix(pattern).nonzero()
    if not len(rows):
        return 0, 0
    return int(max(0, np.max(rows - cols))), int(max(0, np.max(cols - rows)))
