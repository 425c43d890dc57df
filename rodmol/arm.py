"""The paper's prototype arm (Renda et al. 2014, Tables I-III)."""

from .cables import Cable
from .errors import ParameterError
from .markers import Marker
from .model import Model
from .parameters import Material
from .rod import Rod

#: Table I: silicone body.
LENGTH = 0.418  # m
BASE_RADIUS, TIP_RADIUS = 0.015, 0.004  # m
ANCHORAGES = (0.098, 0.203, 0.311)  # L1, L2, L3 [m]
MATERIAL = Material(E=110e3, nu=0.5, mu=300.0, rho=1080.0)

#: Table II: cable offsets (p_y, p_z) [m]; cables 1-4 anchor at L1, 5-8 at L2, 9-12 at L3.
CABLE_OFFSETS = {
    1: (-0.009, 0.0), 2: (0.0, -0.009), 3: (0.009, 0.0), 4: (0.0, 0.009),
    5: (-0.006, 0.0), 6: (0.0, -0.006), 7: (0.006, 0.0), 8: (0.0, 0.006),
    9: (-0.003, 0.0), 10: (0.0, -0.003), 11: (0.003, 0.0), 12: (0.0, 0.003),
}


def cable_anchor(number):
    """Anchor arc length [m] of cable ``number`` (1-12)."""
    return ANCHORAGES[(number - 1) // 4]


def paper_rod():
    """The tapered silicone body of Table I."""
    return Rod(LENGTH, (BASE_RADIUS, TIP_RADIUS), MATERIAL)


def paper_markers():
    """Markers at L1, L2, L3 and L on the surface (+y side), as in section VI."""
    names = ("L1", "L2", "L3", "L")
    return tuple(Marker(s, name=n) for s, n in zip((*ANCHORAGES, LENGTH), names))


def paper_arm(n_elements=100, medium="water", tensions=None, gravity=(0.0, -9.81, 0.0),
              **options):
    """The paper's arm: Tables I-III, twelve cables numbered as in Table II.

    Parameters
    ----------
    n_elements : int
    medium : str or Medium
        ``"water"`` (Table III) or ``"air"``, or any :class:`Medium`.
    tensions : dict, optional
        Maps cable numbers 1-12 to tension inputs (see :mod:`rodmol.cables`);
        the other cables stay slack.
    gravity : (3,) [m/s^2], global frame.
    **options
        Passed to :class:`Model` (``drag``, ``added_mass``, ``viscosity``,
        ``munk_moment``, ``base``, ``markers``): e.g. ``paper_arm(drag=False)``
        is the paper's "no drag" worsened model.
    """
    tensions = dict(tensions or {})
    unknown = sorted(set(tensions) - set(CABLE_OFFSETS), key=str)
    if unknown:
        raise ParameterError(f"`tensions` has unknown cable numbers {unknown}; valid are 1-12")
    cables = [Cable(CABLE_OFFSETS[i], cable_anchor(i), tensions.get(i, 0.0), name=f"cable {i}")
              for i in sorted(CABLE_OFFSETS)]
    options.setdefault("markers", paper_markers())
    return Model(paper_rod(), n_elements, gravity=gravity, medium=medium, cables=cables, **options)
