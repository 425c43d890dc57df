"""Rigid bodies of a system: mass properties, fluid loads, motion and their
mass properties from a closed surface (a mesh file, :mod:`rodmol.meshes`)."""

from dataclasses import dataclass, field

import numpy as np

from . import _checks
from .base_motion import BaseMotion
from .errors import ParameterError
from .loads import CONTACT_NAMES, CONTACT_SHAPES, SMOOTHING_FRACTION
from .meshes import (
    mesh_properties,  # noqa: F401 (its home before rodmol.meshes)
    read_surface,
    solid_properties,
)

#: Motions of a body besides a prescribed :class:`BaseMotion`.
MOTIONS = ("free", "fixed")
_IDENTITY = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))
#: The units of a contact law on a body, where they differ from a rod's: per contact point, not per length.
BODY_CONTACT_UNITS = {"stiffness": "N/m", "damping": "N s/m"}


@dataclass(frozen=True, eq=False)  # compared by identity: its fields are arrays
class RigidBody:
    """A rigid body: a head, a platform, a payload.

    Its *body frame* has its origin at ``position`` and axes ``rotation``
    (body to global) at t = 0; every vector below is in the body frame.

    Parameters
    ----------
    mass : float
        Mass [kg].
    inertia : (3,) or (3, 3) float
        Inertia tensor [kg m^2] about the centre of mass, body frame: three
        principal values along the body axes or a symmetric positive definite tensor.
    volume : float
        Displaced volume [m^3]: buoyancy ``-rho_fluid volume gravity`` acts at
        the centre of mass (a body of uniform density).
    centre_of_mass : (3,) float
        Centre of mass [m], body frame.
    added_mass : (6,) or (6, 6) float, optional
        Added-mass matrix of the surrounding fluid, about the body origin,
        body frame, ordered (translation [kg], rotation [kg m^2]); it adds to
        the body's mass matrix (its gyroscopic terms are left out, as the
        rods' Munk moment by default).
    drag : (6,) float, optional
        Quadratic drag coefficients: force ``-d_i v_i |v_i|`` [N] along the
        body axes (d [kg/m]) from the velocity of the centre of mass, and
        torque ``-d_i w_i |w_i|`` [N m] about them (d [kg m^2]).
    mesh : str or path, optional
        The surface the body was built from (:meth:`from_mesh`), for views.
    motion : "free", "fixed" or BaseMotion
        Free in 6 DOF (default), fixed where it is, or driven: a
        :class:`BaseMotion`, whose velocities are the body frame's (origin
        velocity and angular velocity, body frame) and whose position and
        rotation are the body's initial pose.
    position : (3,) float, optional
        Initial position [m] of the body origin, global (default: the origin,
        or the BaseMotion's).
    rotation : (3, 3) float, optional
        Initial rotation, body to global (default: identity, or the BaseMotion's).
    contacts : sequence of PlaneContact or CapsuleContact (SphereContact), optional
        Obstacles the body touches (a free body only), through the rods'
        contact law at each of its ``contact_points``. For a body the law's
        numbers are per contact point: ``stiffness`` [N/m] and ``damping``
        [N s/m] (a rod's are per unit length, N/m^2 and N s/m^2: a point's
        force is the law's density times 1 m); ``friction`` and ``slip_speed``
        as for a rod. ``smoothing_depth`` defaults to ``SMOOTHING_FRACTION``
        of the contact radius, or of the points' extent if the radius is 0.
    contact_points : (n, 3) float, optional
        Points [m] of the body frame whose spheres of ``contact_radius``
        touch the obstacles (a sphere: its centre; a box: its corners;
        :meth:`from_mesh` takes ``"vertices"``, the mesh's vertices).
    contact_radius : float or (n,) float
        Radius [m] of the sphere around each contact point (0: a point).
    """

    mass: float
    inertia: tuple
    volume: float = 0.0
    centre_of_mass: tuple = (0.0, 0.0, 0.0)
    added_mass: tuple | None = None
    drag: tuple | None = None
    mesh: object = None
    motion: object = "free"
    position: tuple | None = None
    rotation: tuple | None = None
    contacts: tuple = ()
    contact_points: tuple | None = None
    contact_radius: float = 0.0
    #: The 6x6 mass matrix about the body origin, body frame (with the added mass).
    mass_matrix: np.ndarray = field(init=False, repr=False, compare=False)
    #: The default smoothing depth [m] of its contacts (see ``contacts``).
    contact_smoothing: float = field(init=False, repr=False, compare=False)

    def __post_init__(self):
        put = object.__setattr__
        put(self, "mass", _checks.positive("mass", self.mass, " kg"))
        put(self, "inertia", _inertia(self.inertia))
        put(self, "volume", _checks.non_negative("volume", self.volume, " m^3"))
        put(self, "centre_of_mass", _checks.vector3("centre_of_mass", self.centre_of_mass))
        added = _six("added_mass", self.added_mass, square=True)
        if np.any(np.linalg.eigvalsh(0.5 * (added + added.T)) < 0.0):
            raise ParameterError(f"`added_mass` must be positive semi-definite, got {_checks.short(self.added_mass)}")
        put(self, "added_mass", added)
        drag = np.diag(_six("drag", self.drag, square=False)).copy()
        if np.any(drag < 0.0):
            raise ParameterError(f"`drag` must be >= 0, got {_checks.short(self.drag)}")
        put(self, "drag", drag)
        motion = self.motion
        if not isinstance(motion, BaseMotion):
            _checks.choice("motion", motion, MOTIONS)
        elif self.position is not None or self.rotation is not None:
            raise ParameterError("a driven body (`motion` a BaseMotion) starts at the BaseMotion's "
                                 "position and rotation: leave `position` and `rotation` out")
        pose = BaseMotion(
            position=(0.0, 0.0, 0.0) if self.position is None else _checks.vector3("position", self.position),
            rotation=_IDENTITY if self.rotation is None else _checks.rotation("rotation", self.rotation, tol=1e-9))
        start = motion if isinstance(motion, BaseMotion) else pose
        put(self, "position", np.array(start.position, dtype=float))
        put(self, "rotation", np.array(start.rotation, dtype=float))
        matrix = mass_matrix_about_origin(self.mass * np.eye(3), self.inertia, self.centre_of_mass)
        put(self, "mass_matrix", matrix + added)
        _contact_geometry(self)

    @property
    def driven(self):
        """True if the body's motion is prescribed (a BaseMotion)."""
        return isinstance(self.motion, BaseMotion)

    @property
    def free(self):
        """True if the body moves freely in 6 DOF."""
        return isinstance(self.motion, str) and self.motion == "free"

    @classmethod
    def from_mesh(cls, path, density, **options):
        """A body of uniform ``density`` [kg/m^3] filling the closed surface
        in the file ``path`` (any format meshio reads: STL, OBJ, PLY, VTU, ...;
        triangles, quads or polygons; coordinates in metres, the body frame).
        The surface is checked first (:func:`rodmol.meshes.check_surface`:
        closed, manifold, consistently oriented, enclosing a volume; one turned
        wholly inwards is taken turned outwards); volume, centre of mass and
        inertia come from :func:`rodmol.meshes.solid_properties`; ``options`` are
        the other arguments of :class:`RigidBody`."""
        density = _checks.positive("density", density, " kg/m^3")
        given = sorted(set(options) & {"mass", "inertia", "volume", "centre_of_mass", "mesh"})
        if given:
            raise ParameterError(f"`{given[0]}` comes from the mesh and its density: leave it out of "
                                 f"RigidBody.from_mesh, got {given[0]}={_checks.short(options[given[0]])}")
        points, triangles = read_surface(path)
        volume, centre, inertia = solid_properties(points, triangles)
        if isinstance(options.get("contact_points"), str) and options["contact_points"] == "vertices":
            options["contact_points"] = points
        return cls(density * volume, density * inertia, volume=volume, centre_of_mass=centre,
                   mesh=str(path), **options)


def _contact_geometry(body):
    """Check and set a body's ``contacts`` (a tuple), ``contact_points`` ((n, 3) [m], body frame),
    ``contact_radius`` ((n,) [m]) and ``contact_smoothing``, the default smoothing depth [m]."""
    put = object.__setattr__
    contacts = _checks.items("contacts", body.contacts, CONTACT_SHAPES, f"a {CONTACT_NAMES}")
    put(body, "contacts", contacts)
    points = np.zeros((0, 3)) if body.contact_points is None else _checks.floats(body.contact_points)
    if points is None or points.ndim != 2 or points.shape[1] != 3 or not np.all(np.isfinite(points)):
        raise ParameterError(f"`contact_points` must be (n, 3) finite numbers [m], body frame, got "
                             f"{_checks.short(body.contact_points)}")
    radius = _checks.floats(body.contact_radius)
    if radius is None or radius.ndim > 1 or (radius.ndim == 1 and radius.shape != (len(points),)):
        raise ParameterError(f"`contact_radius` must be a number or one per contact point ({len(points)}) [m], "
                             f"got {_checks.short(body.contact_radius)}")
    radius = np.broadcast_to(radius, (len(points),)).copy()
    if not np.all(np.isfinite(radius)) or np.any(radius < 0.0):
        raise ParameterError(f"`contact_radius` must be >= 0 m, got {_checks.short(body.contact_radius)}")
    put(body, "contact_points", points)
    put(body, "contact_radius", radius)
    extent = np.max(np.linalg.norm(points - points.mean(axis=0), axis=1)) if len(points) else 0.0
    put(body, "contact_smoothing", SMOOTHING_FRACTION * (radius.max() if np.any(radius > 0.0) else extent)
        if len(points) else 0.0)
    if not contacts:
        return
    if not body.free:
        raise ParameterError(f"`contacts` act on a free body only: this one's `motion` is {_checks.short(body.motion)}"
                             " (a fixed or driven body's motion is prescribed)")
    if not len(points):
        raise ParameterError("`contacts` need `contact_points` (the body's points, body frame, that touch them)")
    if body.contact_smoothing <= 0.0 and any(c.smoothing_depth is None for c in contacts):
        raise ParameterError("a single contact point of `contact_radius` 0 has no size to smooth the contact over: "
                             "give the contacts a `smoothing_depth` [m]")


def mass_matrix_about_origin(translational, rotational, point):
    """The 6x6 mass matrix about the body origin (velocities (v, w) of the
    origin, body frame) of a rigid part at ``point`` [m] (body frame) with the
    3x3 ``translational`` mass [kg] (m I for a plain mass; anisotropic with an
    added mass) and the 3x3 ``rotational`` inertia [kg m^2] about the point:
    its kinetic energy is 1/2 (v_p M_t v_p + w J w) with v_p = v + w x p,
    which gives the parallel-axis terms."""
    translational, rotational = np.asarray(translational, dtype=float), np.asarray(rotational, dtype=float)
    p = np.asarray(point, dtype=float)
    cross_p = np.array([[0.0, -p[2], p[1]], [p[2], 0.0, -p[0]], [-p[1], p[0], 0.0]])
    return np.block([[translational, -translational @ cross_p],
                     [cross_p @ translational, rotational - cross_p @ translational @ cross_p]])


def _inertia(value):
    arr = _checks.floats(value)
    if arr is not None and arr.shape == (3,):
        arr = np.diag(arr)
    ok = arr is not None and arr.shape == (3, 3) and np.all(np.isfinite(arr))
    if ok and np.allclose(arr, arr.T, rtol=1e-9, atol=1e-12 * np.max(np.abs(arr))):
        arr = 0.5 * (arr + arr.T)
        principal = np.linalg.eigvalsh(arr)
        # A rigid body's principal moments obey the triangle inequality (I_i <= I_j + I_k).
        if np.all(principal > 0.0) and 2.0 * principal.max() <= principal.sum() * (1.0 + 1e-9):
            return arr
    raise ParameterError("`inertia` must be three positive numbers or a symmetric positive definite 3x3 "
                         "tensor [kg m^2] whose principal moments obey I_i <= I_j + I_k (a rigid body's), "
                         f"got {_checks.short(value)}")


def _six(name, value, square):
    """``value`` as a (6, 6) matrix (from None, six diagonal values or, if ``square``, a 6x6)."""
    if value is None:
        return np.zeros((6, 6))
    arr = _checks.floats(value)
    if arr is not None and arr.shape == (6,) and np.all(np.isfinite(arr)):
        return np.diag(arr)
    if square and arr is not None and arr.shape == (6, 6) and np.all(np.isfinite(arr)):
        return arr
    shapes = "six numbers or a 6x6 matrix" if square else "six numbers"
    raise ParameterError(f"`{name}` must be {shapes}, got {_checks.short(value)}")
