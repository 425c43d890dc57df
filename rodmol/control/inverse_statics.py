"""Inverse statics: the cable tensions whose static equilibrium puts the tip (its
tangent, markers) at a target.

A bounded Levenberg-Marquardt loop over the tensions of the actuated cables.
Each iterate is a static equilibrium (:mod:`rodmol.solve.equilibrium`) warm-
started from the last one; the sensitivities of the tip to the tensions are
exact, from the equilibrium's Jacobian by the implicit-function theorem
(:func:`~rodmol.solve.tension_statics.tension_sensitivity`), not from differences
of whole solves; each step is a bounded linear least-squares problem
(``scipy.optimize.lsq_linear``) with the cables' bounds. Displacement-
controlled cables are solved for their tension too, and the actuator
position that holds it follows exactly from the path length
(:meth:`rodmol.cables.ActuatorTension.position_for`).
"""

from dataclasses import dataclass, field

import numpy as np

from .. import _checks
from ..discretise.hand_tensions import tensions_by_hand
from ..discretise.layout import StateLayout
from ..discretise.schemes import DEFAULT_SCHEME
from ..discretise.system import SemiDiscrete
from ..errors import ParameterError
from ..model import Model
from ..solve.tension_statics import rest_state, tension_sensitivity
from ..systems import System
from ._fitting import (
    REACH_TOLERANCE,
    actuated,
    at_bounds,
    cable_displacements,
    check_bounds,
    levenberg_marquardt,
    out_of_reach,
    verdict,
    with_cables,
)
from ._targets import Targets, check_aims, path_rows
from .system_path import PATH_OPTIONS, fit_system_path
from .system_statics import fit_system


@dataclass(frozen=True)
class StaticFit:
    """What :func:`inverse_statics` found.

    Attributes
    ----------
    tensions : dict
        Cable name -> tension [N] where it leaves the base, every cable of
        the model (the cables not actuated keep their own).
    displacements : dict
        Cable name -> actuator position z [m] holding the found tension, for
        the actuated displacement-controlled cables (at 0 N: the position
        that leaves the tendon just taut).
    state : (size,) array
        The static equilibrium under ``tensions``.
    tip : (3,) array
        Its tip position [m], global frame.
    residual : float
        The weighted residual [m]: sqrt(|tip - target|^2 + (w_d |d - d_target|)^2
        + w_m^2 sum |marker - target|^2), d the tip's tangent (global), w_d the
        ``direction_weight``, w_m the ``marker_weight`` (each term if aimed at).
    tip_error : float or None
        |tip - target| [m].
    direction_error : float or None
        Angle [rad] between the tip's tangent and the target direction.
    marker_errors : dict
        Marker name -> |marker - target| [m], for the markers aimed at.
    reachable : bool
        ``residual <= tol``.
    active : dict
        Cable name -> ``"lower"`` or ``"upper"`` for the actuated cables at a bound.
    message : str
    iterations, equilibria : int
        Accepted steps, and static equilibria solved (trial steps included).
    """

    tensions: dict
    displacements: dict
    state: np.ndarray = field(repr=False)
    tip: np.ndarray
    residual: float
    tip_error: float | None
    direction_error: float | None
    marker_errors: dict
    reachable: bool
    active: dict
    message: str
    iterations: int
    equilibria: int

    def apply(self, model):
        """``model`` with the found inputs: each actuated cable pulls with its
        found tension, or its actuator sits at its found displacement."""
        return with_cables(model, self.tensions, self.displacements)


def inverse_statics(model, tip=None, *, direction=None, markers=None, pose=None, bounds=(0.0, np.inf),
                    cables=None, insertions=None, driven=None, travel=None, t=0.0, tol=REACH_TOLERANCE,
                    direction_weight=None, marker_weight=1.0, start=None, scheme=DEFAULT_SCHEME, max_iter=50):
    """The cable tensions, within bounds, whose static equilibrium puts the tip at
    ``tip`` (its tangent along ``direction``, markers at ``markers``).

    Parameters
    ----------
    model : Model or System
        Its loads (gravity, buoyancy, external loads, contact at ``t``) act;
        the cables not in ``cables`` keep their tensions. A
        :class:`rodmol.System` takes its targets and inputs by rod and body
        name (``pose``, ``insertions``, ``driven`` and ``travel`` are for a
        System only): see :func:`rodmol.control.system_statics.fit_system`,
        which returns a :class:`~rodmol.control.system_fit.SystemFit`.
    tip : (3,) array, optional
        Target tip position [m], global frame.
    direction : (3,) array, optional
        Target direction of the tip's tangent (its local x axis), global
        frame; normalised here.
    markers : dict, optional
        Marker name (one of ``model.markers``) -> target position [m],
        global frame. At least one of ``tip``, ``direction``, ``markers``.
    bounds : (low, high)
        Tension bounds [N], each a number or one per actuated cable (in the
        order of ``cables``); 0 <= low < high (``high`` may be ``inf``).
        Displacement-controlled cables are bounded by their tension too.
    cables : sequence of str, optional
        Names of the actuated cables; default all. The others must not be
        feedback or displacement-controlled (their tension must not read
        the state).
    t : float
        Time [s] at which the other loads are read.
    tol : float
        Reach tolerance [m] on the weighted residual (default 0.1 mm).
    direction_weight : float, optional
        Length w_d [m] weighting the direction error (default: the rod's length).
    marker_weight : float
        Weight w_m [-] of the markers' errors against the tip's.
    start : (n_actuated,) array, optional
        Initial tensions [N]; default the model's tensions at ``t`` (clipped
        to the bounds).
    scheme : str
        The spatial scheme (``rodmol.SCHEMES``).
    max_iter : int
        Most trial steps (0: the equilibrium under ``start``, reported against
        the target: the forward statics).

    Returns
    -------
    StaticFit
        ``reachable`` False (and the bounds that are active) if no tensions
        within the bounds meet the target to ``tol``: the fit is then the
        closest equilibrium the loop found: a local minimum of the residual
        (the loop is local: another ``start`` may reach a target this one
        does not, and with more cables than targets the tensions are one
        solution of many, the one the damped steps reach from ``start``).

    Raises
    ------
    ParameterError
        Bad input, before any work.
    EquilibriumError
        No equilibrium under the initial tensions.
    """
    if isinstance(model, System):
        return fit_system(model, tip, direction=direction, markers=markers, pose=pose, bounds=bounds,
                          cables=cables, insertions=insertions, driven=driven, travel=travel, t=t, tol=tol,
                          direction_weight=direction_weight, marker_weight=marker_weight, start=start,
                          scheme=scheme, max_iter=max_iter)
    _check_model(model)
    _refuse_system_words(pose=pose, insertions=insertions, driven=driven, travel=travel)
    tip, direction, names, positions = check_aims(model, tip, direction, markers)
    tol = _checks.positive("tol", tol, " m")
    max_iter = _checks.integer_at_least("max_iter", max_iter, 0)
    problem = _Problem(model, cables, bounds, t, scheme, (tip is not None, direction is not None, names),
                       direction_weight, marker_weight)
    return problem.fit(problem.targets.aim(tip, direction, positions), problem.start(start), tol, max_iter)


def inverse_statics_path(model, tips=None, *, directions=None, poses=None, **options):
    """:func:`inverse_statics` along a sequence of targets, each warm-started
    from the solution of the one before (its inputs and its equilibrium).

    Parameters
    ----------
    model : Model or System
        A :class:`rodmol.System` takes its targets by rod and body name
        (:func:`rodmol.control.system_path.fit_system_path`) and returns
        one :class:`~rodmol.control.system_fit.SystemFit` per target.
    tips : (n, 3) array
        Target tip positions [m], global frame.
    directions : (n, 3) array, optional
        Target tip tangents, global frame.
    poses : dict, optional
        For a System only: body name -> its n target poses.
    **options
        As for :func:`inverse_statics` (``bounds``, ``cables``, ``tol``, ...);
        ``start`` applies to the first target.

    Returns
    -------
    list of StaticFit
    """
    if isinstance(model, System):
        unknown = set(options) - set(PATH_OPTIONS)
        if unknown:
            raise ParameterError(f"unknown options {sorted(unknown)} for inverse_statics_path of a System "
                                 f"(it takes {', '.join(PATH_OPTIONS)})")
        return fit_system_path(model, tips, directions=directions, poses=poses, **options)
    _check_model(model)
    _refuse_system_words(poses=poses, **{k: options.pop(k) for k in ("insertions", "driven", "travel")
                                          if k in options})
    tips = path_rows("tips", tips)
    if directions is not None:
        directions = path_rows("directions", directions)
        if len(directions) != len(tips):
            raise ParameterError(f"`directions` must have one row per target ({len(tips)}), got {len(directions)}")
    unknown = set(options) - {"bounds", "cables", "t", "tol", "direction_weight", "start", "scheme", "max_iter"}
    if unknown:
        raise ParameterError(f"unknown options {sorted(unknown)} for inverse_statics_path")
    tol = _checks.positive("tol", options.get("tol", REACH_TOLERANCE), " m")
    max_iter = _checks.integer_at_least("max_iter", options.get("max_iter", 50), 1)
    aims = [check_aims(model, p, None if directions is None else d, None)
            for p, d in zip(tips, directions if directions is not None else tips)]
    problem = _Problem(model, options.get("cables"), options.get("bounds", (0.0, np.inf)), options.get("t", 0.0),
                       options.get("scheme", DEFAULT_SCHEME), (True, directions is not None, []),
                       options.get("direction_weight"), 1.0)
    targets = [problem.targets.aim(tip, direction, None) for tip, direction, _, _ in aims]
    tensions = problem.start(options.get("start"))
    fits = []
    for target in targets:
        fit = problem.fit(target, tensions, tol, max_iter)
        tensions = np.array([fit.tensions[problem.names[i]] for i in problem.index])
        fits.append(fit)
    return fits


def _refuse_system_words(**given):
    """A System's words (its bodies' poses, its rods' insertions) given for a Model: refused."""
    for name, value in given.items():
        if value is not None:
            raise ParameterError(f"`{name}` is for a rodmol.System (its bodies and rods' bases), got "
                                 f"{_checks.short(value)} for a Model")


def _check_model(model):
    if not isinstance(model, Model):
        raise ParameterError(f"`model` must be a rodmol.Model or a rodmol.System, got {_checks.short(model)}")


class _Problem:
    """The aimed-at outputs of the equilibrium as functions of the actuated tensions."""

    def __init__(self, model, cables, bounds, t, scheme, aims, direction_weight, marker_weight):
        self.model, self.t = model, _checks.finite("t", t)
        self.names = [c.name for c in model.cables]
        if cables is None and not self.names:
            raise ParameterError("the model has no cables to actuate")
        self.index = actuated(self.names, cables)
        self.low, self.high = check_bounds("bounds", bounds, len(self.index), "actuated cable", "N", lowest=0.0)
        weight = (model.rod.length if direction_weight is None
                  else _checks.positive("direction_weight", direction_weight, " m"))
        self.targets = Targets(model, StateLayout(model.n_elements), *aims, weight,
                               _checks.positive("marker_weight", marker_weight))
        held = np.setdiff1d(np.arange(len(model.cables)), self.index)
        for i in held:
            if model.cables[i].tension.feedback:
                raise ParameterError(f"cable {self.names[i]!r} reads the state (feedback or displacement "
                                     "control): list it in `cables` to solve for it")
        self.tensions = np.zeros(len(model.cables))
        self.tensions[held] = [model.cables[i].tension_at(self.t) for i in held]
        self.system = SemiDiscrete(tensions_by_hand(model), scheme)
        self._tip = self.system.layout.tip_slice("u")
        self.warm, self.equilibria = None, 0

    def start(self, start):
        if start is None:
            values = np.array([self.model.cables[i].tension_at(self.t) for i in self.index])
        else:
            values = _checks.floats(start)
            if values is None or values.shape != (len(self.index),) or not np.all(np.isfinite(values)):
                raise ParameterError(f"`start` must be {len(self.index)} finite tensions [N] (one per actuated "
                                     f"cable), got {_checks.short(start)}")
        return np.clip(values, self.low, self.high)

    def all_tensions(self, actuated):
        out = self.tensions.copy()
        out[self.index] = actuated
        return out

    def rest(self, actuated):
        """The equilibrium under the actuated tensions, warm-started from the last one."""
        self.equilibria += 1
        y = rest_state(self.system, self.all_tensions(actuated), self.t, start=self.warm)
        self.warm = y
        return y

    def values(self, y):
        return self.targets.values(y)

    def jacobian(self, y, actuated):
        """d outputs / d actuated tensions [m/N], exact up to the equilibrium's tolerance."""
        d_y = tension_sensitivity(self.system, y, self.all_tensions(actuated), self.t)[:, self.index]
        return self.targets.rows(y) @ d_y[self.targets.entries]

    def fit(self, target, tensions, tol, max_iter):
        """The bounded least squares from ``tensions``, reported."""
        tensions, y, r, accepted = levenberg_marquardt(self, target, tensions, tol, max_iter)
        return self._report(target, tensions, y, r, tol, accepted)

    def _report(self, target, tensions, y, r, tol, iterations):
        residual = float(np.linalg.norm(r))
        tip_error, angle, marker_errors = self.targets.errors(y, target)
        names = [self.names[i] for i in self.index]
        active = at_bounds(tensions, self.low, self.high, names)
        displacements = cable_displacements(self.model, self.system.state_view(self.t, y), self.index, tensions)
        base = self.model.base
        far = (out_of_reach("the tip", base.position, target[:3], self.model.rod.length)
               if self.targets.tip and base.fixed else None)
        message = verdict(residual, tol, iterations, self.equilibria, active,
                          {n: f"{h:.4g} N" for n, h in zip(names, self.high)}, [far] if far else [])
        return StaticFit(dict(zip(self.names, self.all_tensions(tensions).tolist())), displacements, y,
                         y[self._tip].copy(), residual, tip_error, angle, marker_errors, residual <= tol, active,
                         message, iterations, self.equilibria)
