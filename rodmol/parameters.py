"""Material and medium parameters (SI units), validated on construction."""

from dataclasses import dataclass, field

import numpy as np

from . import _checks
from .errors import ParameterError


@dataclass(frozen=True)
class Material:
    """Isotropic Kelvin-Voigt material of the rod.

    Parameters
    ----------
    E : float
        Young's modulus [Pa].
    nu : float, optional
        Poisson ratio, in (-1, 0.5]; gives the shear modulus ``E / (2 (1 + nu))``.
    mu : float
        Shear viscosity [Pa s] of the Kelvin-Voigt law; 0 (default) gives a
        linear elastic rod.
    rho : float
        Density [kg/m^3].
    G : float, optional, keyword-only
        Shear modulus [Pa], instead of ``nu`` (for example a Timoshenko beam
        with G = E / 100). Give exactly one of ``nu`` and ``G``; ``nu`` is
        then reported as E / (2 G) - 1.
    viscosity : dict, optional, keyword-only
        Kelvin-Voigt viscosities per strain component [Pa s], instead of the
        paper's ratios: ``shear_extension=(eta_x, eta_y, eta_z)`` gives
        Vl = A diag(eta) (extension along the local x axis, then the two
        shears), ``bending_torsion=(eta_x, eta_y, eta_z)`` gives
        Vth = diag(Jx eta_x, Jy eta_y, Jz eta_z) (torsion, then the two
        bendings). A key left out keeps the paper's values from ``mu``:
        (3 mu, mu, mu) and (mu, 3 mu, 3 mu). So
        ``viscosity=dict(shear_extension=(0, 0, 0))`` with mu > 0 damps
        bending and torsion only. A sectional damping matrix B [N s or
        N m^2 s] of a constant section is ``B / A`` or ``B / J`` here.
    """

    E: float
    nu: float | None = None
    mu: float = 0.0
    rho: float | None = None
    G: float | None = field(default=None, kw_only=True)
    viscosity: dict | None = field(default=None, kw_only=True)

    def __post_init__(self):
        object.__setattr__(self, "E", _checks.positive("E", self.E, " Pa"))
        if self.rho is None:
            raise ParameterError("`rho` (density [kg/m^3]) is required")
        object.__setattr__(self, "rho", _checks.positive("rho", self.rho, " kg/m^3"))
        object.__setattr__(self, "mu", _checks.non_negative("mu", self.mu, " Pa s"))
        if self.nu is None and self.G is None:
            raise ParameterError("missing `nu` (Poisson ratio [-]); or give the shear modulus `G` [Pa]")
        if self.nu is not None and self.G is not None:
            raise ParameterError(f"`G` = {self.G!r} Pa given with `nu` = {self.nu!r}: give either `nu` "
                                 "(Poisson ratio) or `G` (shear modulus [Pa]), not both")
        if self.G is None:
            nu = _checks.finite("nu", self.nu)
            if not -1.0 < nu <= 0.5:
                raise ParameterError(f"`nu` must lie in (-1, 0.5], got {self.nu!r}")
            object.__setattr__(self, "nu", nu)
            object.__setattr__(self, "G", self.E / (2.0 * (1.0 + nu)))
        else:
            object.__setattr__(self, "G", _checks.positive("G", self.G, " Pa"))
            object.__setattr__(self, "nu", self.E / (2.0 * self.G) - 1.0)
        if self.viscosity is not None:
            object.__setattr__(self, "viscosity", _component_viscosities(self.viscosity))

    @property
    def viscosities(self):
        """(eta_l, eta_th): the Kelvin-Voigt viscosities [Pa s] of the strain
        components, local frame order (extension, shear y, shear z) and
        (torsion, bending y, bending z); Vl = A eta_l, Vth = J eta_th."""
        given = self.viscosity or {}
        paper = {"shear_extension": (3.0 * self.mu, self.mu, self.mu),
                 "bending_torsion": (self.mu, 3.0 * self.mu, 3.0 * self.mu)}
        return tuple(np.array(given.get(key, paper[key]), dtype=float) for key in VISCOSITY_KEYS)

    def relaxation_times(self):
        """Kelvin-Voigt relaxation time eta / modulus [s] of each strain
        component (extension, shear y, shear z, torsion, bending y, bending z)."""
        eta_l, eta_th = self.viscosities
        moduli = np.array([self.E, self.G, self.G, self.G, self.E, self.E])
        return np.concatenate([eta_l, eta_th]) / moduli


#: Keys of ``Material(viscosity=...)``.
VISCOSITY_KEYS = ("shear_extension", "bending_torsion")


def _component_viscosities(value):
    """The ``viscosity`` dict checked: known keys, three finite values >= 0 [Pa s] each."""
    if not isinstance(value, dict):
        raise ParameterError("`viscosity` must be a dict with keys "
                             f"{', '.join(VISCOSITY_KEYS)}, got {_checks.short(value)}")
    unknown = sorted(set(value) - set(VISCOSITY_KEYS))
    if unknown:
        raise ParameterError(f"unknown `viscosity` key {unknown[0]!r}; valid keys are "
                             f"{', '.join(VISCOSITY_KEYS)}")
    checked = {}
    for key, eta in value.items():
        arr = _checks.floats(eta)
        if arr is None or arr.shape != (3,) or not np.all(np.isfinite(arr)) or np.any(arr < 0):
            raise ParameterError(f"`viscosity[{key!r}]` must be three finite numbers >= 0 Pa s, "
                                 f"got {_checks.short(eta)}")
        checked[key] = tuple(float(x) for x in arr)
    return checked


@dataclass(frozen=True)
class Medium:
    """The fluid around the rod (eqs. 7-9 of Renda et al. 2014).

    Parameters
    ----------
    rho : float
        Fluid density [kg/m^3] (buoyancy, drag and added mass scale with it).
    Cx, Cy, Cz : float
        Morison drag coefficients, axial and transverse [-].
    By, Bz : float
        Added-mass coefficients, transverse [-].
    """

    rho: float = 0.0
    Cx: float = 0.0
    Cy: float = 0.0
    Cz: float = 0.0
    By: float = 0.0
    Bz: float = 0.0

    def __post_init__(self):
        for name in ("rho", "Cx", "Cy", "Cz", "By", "Bz"):
            object.__setattr__(self, name, _checks.non_negative(name, getattr(self, name)))

    @classmethod
    def preset(cls, name):
        """A named medium: ``"water"`` (the paper's Table III) or ``"air"``."""
        return MEDIA[_checks.choice("medium", name, tuple(MEDIA))]


#: The paper's water (Table III) and air, where fluid loads are neglected.
MEDIA = {
    "water": Medium(rho=1022.0, Cx=0.01, Cy=2.5, Cz=2.5, By=1.5, Bz=1.5),
    "air": Medium(),
}
