"""The model: a rod, its grid, the medium, the cables, the loads and the
base; the system samples its sectional quantities on the staggered grid
(:mod:`rodmol.discretise.sampling`).

Grid (section IV-C of the paper): N elements, ds = L/N, nodes s_i = i ds.
Strains q, k and the stresses live on the *strain nodes* i = 0..N-1; pose u, R
and velocities v, w on the *velocity nodes* i = 1..N. The base (node 0) has
prescribed velocities, the tip (node N) a vanishing total stress.
"""

import pickle

import numpy as np

from . import _checks
from . import loads as load_types
from .base_motion import BaseMotion
from .cables import Cable
from .errors import ParameterError
from .markers import Marker, marker_offsets
from .parameters import Medium
from .rod import Rod

#: Most elements a Model accepts (memory, not accuracy, is the limit: a run at
#: N = 1e4 already takes minutes per simulated second).
MAX_ELEMENTS = 100_000
class Model:
    """A semi-discretised Cosserat rod with its loads.

    Parameters
    ----------
    rod : Rod
    n_elements : int
        Number of elements N (>= 2); the grid has N + 1 nodes.
    gravity : (3,) float, keyword-only
        Gravitational acceleration G [m/s^2], global frame.
    medium : Medium, str or None
        The surrounding fluid: a :class:`Medium`, a preset name (``"water"``,
        ``"air"``) or None (no fluid, unless ``medium_density`` is given).
    medium_density : float
        Shortcut for a fluid that only gives buoyancy [kg/m^3].
    cables : sequence of Cable
    base : BaseMotion or None
        Base motion; None is a fixed clamp at the origin.
    loads : sequence of loads
        External loads (:mod:`rodmol.loads`): point and distributed forces
        and moments, contact with planes, spheres and capsules.
    drag, added_mass, viscosity : bool
        Switches to drop a load (the paper's worsened models, Table V):
        ``viscosity=False`` sets mu = 0.
    munk_moment : bool
        Add the Munk moment of the added-mass model (off in the paper).
    markers : sequence of Marker
        Surface points whose trajectories the result carries.
    drag_law : str
        ``"morison"`` (default): the paper's -rho_w |v| D v from the medium's
        coefficients (eq. 8); ``"componentwise"``: -C v|v| per local
        component, C = ``drag_coefficients`` (Till's tendon robot), in place
        of the medium's drag.
    drag_coefficients : (float, float, float)
        C [kg/m^2] of the componentwise law, local frame (axial, y, z); force
        per unit length.

    ``s_nodes`` (N + 1,) [m] are the grid's nodes (read-only); the sectional
    quantities are sampled on them once, by the system
    (``SemiDiscrete.sampled``, :mod:`rodmol.discretise.sampling`).
    """

    def __init__(self, rod, n_elements, *, gravity=(0.0, -9.81, 0.0), medium=None,
                 medium_density=0.0, cables=(), base=None, drag=True, added_mass=True,
                 viscosity=True, munk_moment=False, markers=(), loads=(), drag_law="morison",
                 drag_coefficients=None):
        if not isinstance(rod, Rod):
            raise ParameterError(f"`rod` must be a rodmol.Rod, got {rod!r}")
        self.rod = rod
        self.n_elements = _checks.integer_at_least("n_elements", n_elements, 2)
        if self.n_elements > MAX_ELEMENTS:  # refused before the grid is allocated
            raise ParameterError(f"`n_elements` must be <= {MAX_ELEMENTS}, got {self.n_elements}")
        self.gravity = _checks.vector3("gravity", gravity)
        self.medium = _medium(medium, medium_density)
        self.cables = _checks.items("cables", cables, Cable, "a rodmol.Cable")
        self.base = BaseMotion() if base is None else base
        if not isinstance(self.base, BaseMotion):
            raise ParameterError(f"`base` must be a rodmol.BaseMotion or None, got {base!r}")
        self.drag, self.added_mass = _checks.flag("drag", drag), _checks.flag("added_mass", added_mass)
        self.viscosity = _checks.flag("viscosity", viscosity)
        self.munk_moment = _checks.flag("munk_moment", munk_moment)
        self.drag_law, self.drag_coefficients = _drag_law(drag_law, drag_coefficients)
        self._check_cables()
        # Displacement-controlled cables measure their default rest length on this rod's rest shape.
        self.cables = tuple(c.on_rod(rod) for c in self.cables)
        names = ", ".join(t.__name__ for t in load_types.LOAD_TYPES)
        self.loads = _checks.items("loads", loads, load_types.LOAD_TYPES, f"one of rodmol's loads ({names})")
        names = [c.name for c in self.cables]
        duplicate = next((n for n in names if names.count(n) > 1), None)
        if duplicate is not None:
            raise ParameterError(f"two cables are named {duplicate!r}: cable names must be unique")
        for load in self.loads:
            load.check_within(rod.length)
        self.markers = _checks.items("markers", markers, Marker, "a rodmol.Marker")
        self.marker_offsets = marker_offsets(self.markers, rod)
        self._grid()
        for load in self.loads:
            load.check_grid(self.s_nodes)

    def options(self):
        """The keyword arguments this model was built with (after checking)."""
        return dict(gravity=tuple(self.gravity), medium=self.medium, cables=self.cables,
                    base=self.base, drag=self.drag, added_mass=self.added_mass,
                    viscosity=self.viscosity, munk_moment=self.munk_moment,
                    markers=self.markers, loads=self.loads, drag_law=self.drag_law,
                    drag_coefficients=self.drag_coefficients)

    def replace(self, *, rod=None, n_elements=None, **changes):
        """A new Model with ``changes`` (any argument of the constructor); the others as here."""
        return type(self)(self.rod if rod is None else rod,
                          self.n_elements if n_elements is None else n_elements,
                          **{**self.options(), **changes})

    def __reduce__(self):
        # Rebuilt from its arguments on unpickling: the grid follows from them.
        _check_no_inline_functions(self)
        return (_rebuild, (type(self), self.rod, self.n_elements, self.options()))

    def __repr__(self):
        return (f"Model(L={self.rod.length} m, N={self.n_elements}, medium rho={self.medium.rho} "
                f"kg/m^3, {len(self.cables)} cables)")

    @property
    def ds(self):
        """Element length [m]."""
        return self.rod.length / self.n_elements

    @property
    def feedback(self):
        """True if a cable tension reads the state."""
        return any(c.tension.feedback for c in self.cables)

    @property
    def friction(self):
        """True if a cable rubs on the body (``Cable(friction=...)`` > 0)."""
        return any(c.friction > 0.0 for c in self.cables)

    def _check_cables(self):
        L = self.rod.length
        for c in self.cables:
            if c.anchor > L * (1 + 1e-12):
                raise ParameterError(
                    f"cable {c.name!r}: `anchor` must lie in (0, L = {L!r} m], got {c.anchor!r}")
            if c.outside_body:
                continue
            s = np.linspace(0.0, min(c.anchor, L), 2001)
            r = self.rod.radius_at(s)
            reach = np.hypot(*c.offset_at(s).T)
            if np.any(reach >= r):
                i = int(np.argmax(reach >= r))
                raise ParameterError(
                    f"cable {c.name!r}: offset {tuple(c.offset_at(s[i])[0].tolist())} m (|p| = {reach[i]:.6g} m) "
                    f"lies outside the body at s = {s[i]:.6g} m where the radius is "
                    f"{r[i]:.6g} m (a cable on spacer disks: Cable(..., outside_body=True))")

    def _grid(self):
        """The grid's nodes s_0..s_N [m] (the sectional quantities are sampled
        on them by the system, :mod:`rodmol.discretise.sampling`)."""
        self.s_nodes = np.linspace(0.0, self.rod.length, self.n_elements + 1)
        self.s_nodes.flags.writeable = False

    def tensions(self, t, state=None):
        """Cable tensions [N] at time t, shape (n_cables,)."""
        return np.array([c.tension_at(t, state) for c in self.cables])


def _rebuild(cls, rod, n_elements, options):
    return cls(rod, n_elements, **options)


def _check_no_inline_functions(model):
    """Refuse to pickle inputs given as lambdas or local functions, naming them:
    pickle stores functions by name, so these cannot reach another process."""
    inputs = [(f"cable {c.name!r} tension", c.tension) for c in model.cables]
    inputs += [(f"cable {c.name!r} offset", c.offset) for c in model.cables if callable(c.offset)]
    inputs += [(f"base {k}", getattr(model.base, k)) for k in ("velocity", "angular_velocity")]
    inputs += [(f"load {getattr(x, 'name', x)!r}", x) for x in model.loads]
    inputs += [(f"rod {name}", getattr(model.rod, name)) for name in ("rest_curvature", "rest_stretch")]
    for label, value in inputs:
        name = _inline_function(value)
        if name:
            raise pickle.PicklingError(
                f"the model does not pickle: the {label} is an inline Python function ({name}); "
                "give knots, a CSV table or a module-level function to send the model to "
                "other processes (sweeps, identification, dask)")


def _inline_function(value, depth=3):
    """The name of a lambda or local function in an input or what it wraps, or None."""
    name = getattr(value, "__qualname__", "") if callable(value) else ""
    if "<lambda>" in name or "<locals>" in name:
        return name
    for attr in ("function", "signal", "force", "moment", "position") if depth else ():
        found = _inline_function(getattr(value, attr, None), depth - 1)
        if found:
            return found
    return None


#: Drag laws a Model accepts (``drag_law``).
DRAG_LAWS = ("morison", "componentwise")


def _drag_law(law, coefficients):
    """(law, coefficients (3,) [kg/m^2] or None), checked."""
    _checks.choice("drag_law", law, DRAG_LAWS)
    if law == "morison":
        if coefficients is not None:
            raise ParameterError("`drag_coefficients` belong to drag_law='componentwise' (the Morison "
                                 f"law takes its coefficients from the medium), got {_checks.short(coefficients)}")
        return law, None
    if coefficients is None:
        raise ParameterError("drag_law='componentwise' needs `drag_coefficients` (C_x, C_y, C_z) [kg/m^2]")
    c = _checks.vector3("drag_coefficients", coefficients)
    if np.any(c < 0):
        raise ParameterError(f"`drag_coefficients` must be >= 0 kg/m^2, got {_checks.short(coefficients)}")
    return law, tuple(float(x) for x in c)


def _medium(medium, medium_density):
    density = _checks.non_negative("medium_density", medium_density, " kg/m^3")
    if medium is None:
        return Medium(rho=density)
    if density:
        raise ParameterError("give either `medium` or `medium_density`, not both "
                             f"(got medium={medium!r}, medium_density={medium_density!r})")
    if isinstance(medium, str):
        return Medium.preset(medium)
    if not isinstance(medium, Medium):
        raise ParameterError(f"`medium` must be a rodmol.Medium or a preset name, got {medium!r}")
    return medium
