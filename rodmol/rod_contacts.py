"""Rods touching rods, and a rod touching itself: :class:`RodContact`, one of
a :class:`rodmol.System`'s ``contacts``.

The law (docs/systems.md, "Contact between rods"; compiled in
:mod:`rodmol.discretise.rod_contact`): each segment of one rod is sampled at
points a fraction of the sum of the radii apart, and each sample is pushed
out of the other rod's nearest segment capsule by the contact law of the
obstacles (:func:`rodmol.discretise.external.penalty`: a penalty smoothed over
``smoothing_depth``, damping that ramps in with it, regularised Coulomb
friction), with half the stiffness and damping from each rod's side, so that
two rods side by side feel ``stiffness`` per unit length of contact line.
"""

from dataclasses import dataclass

import numpy as np

from . import _checks
from .errors import ParameterError
from .loads import SMOOTHING_FRACTION

#: The name of the load through which a rod feels its rod contacts (a follower force density at every node).
LOAD_NAME = "rod contacts"


@dataclass(frozen=True)
class RodContact:
    """Contact between two rods of a System, or of a rod with itself (``a == b``).

    Parameters
    ----------
    a, b : str
        The rods' names in the System's ``rods``; the same name for self-contact
        (parts of the rod closer along it than pi times its largest radius
        never touch: on the tightest coil a tube can make, radius r, they are
        within 2 r of each other anyway).
    stiffness : float or None
        Penalty stiffness per unit length of contact line [N/m^2]; default the
        softer rod's Young's modulus E (the order of two elastic cylinders'
        line-contact stiffness).
    damping : float or None
        Normal damping per unit length [N s/m^2] (acts only in contact); default
        critical for the two rods' reduced mass per length m: 2 sqrt(stiffness m).
    friction : float
        Coulomb coefficient [-] (regularised below ``slip_speed``).
    slip_speed : float
        Sliding speed [m/s] below which friction is smoothed.
    smoothing_depth : float or None
        Depth [m] over which the penalty is smoothed; default 1% of the smaller
        radius (``rodmol.loads.SMOOTHING_FRACTION``).
    """

    a: str
    b: str
    stiffness: float | None = None
    damping: float | None = None
    friction: float = 0.0
    slip_speed: float = 1e-4
    smoothing_depth: float | None = None

    def __post_init__(self):
        for end in ("a", "b"):
            value = getattr(self, end)
            if not isinstance(value, str) or not value:
                raise ParameterError(f"RodContact `{end}` must be a rod's name, got {_checks.short(value)}")
        for key, check, unit in (("stiffness", _checks.positive, " N/m^2"), ("damping", _checks.non_negative,
                                                                               " N s/m^2"),
                                 ("smoothing_depth", _checks.positive, " m")):
            if getattr(self, key) is not None:
                object.__setattr__(self, key, check(f"RodContact {key}", getattr(self, key), unit))
        object.__setattr__(self, "friction", _checks.non_negative("RodContact friction", self.friction))
        object.__setattr__(self, "slip_speed", _checks.positive("RodContact slip_speed", self.slip_speed, " m/s"))

    @property
    def rods(self):
        """The rods' names, one for self-contact."""
        return (self.a,) if self.a == self.b else (self.a, self.b)

    def law(self, model_a, model_b):
        """(stiffness [N/m^2], damping [N s/m^2], friction, slip speed [m/s],
        smoothing depth [m]) between the rods of Models ``model_a``, ``model_b``:
        the given values, the defaults derived from the rods where None."""
        k = self.stiffness
        if k is None:
            k = min(model_a.rod.material.E, model_b.rod.material.E)
        c = self.damping
        if c is None:
            masses = [m.rod.material.rho * float(np.mean(m.rod.area(m.s_nodes))) for m in (model_a, model_b)]
            c = 2.0 * np.sqrt(k * masses[0] * masses[1] / (masses[0] + masses[1]))
        h = self.smoothing_depth
        if h is None:
            h = SMOOTHING_FRACTION * min(float(np.min(m.rod.radius_at(m.s_nodes))) for m in (model_a, model_b))
        return float(k), float(c), float(self.friction), float(self.slip_speed), float(h)


def check_rods(contacts, rods):
    """Refuse a :class:`RodContact` of ``contacts`` (the System's, numbered as
    there) naming a rod not in ``rods``, or a pair declared twice."""
    seen = {}
    for i, contact in enumerate(contacts):
        if not isinstance(contact, RodContact):
            continue
        for end in ("a", "b"):
            name = getattr(contact, end)
            if name not in rods:
                raise ParameterError(f"`contacts[{i}]` ({end}) names the rod {name!r}, which is not in `rods`"
                                     f"{_checks.did_you_mean(name, rods)}")
        pair = frozenset((contact.a, contact.b))
        if pair in seen:
            raise ParameterError(f"`contacts[{i}]` declares the contact of {contact.a!r} and {contact.b!r} again "
                                 f"(as `contacts[{seen[pair]}]`)")
        seen[pair] = i
