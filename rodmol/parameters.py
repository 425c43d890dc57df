"""Material and medium parameters (SI units), validated on construction."""

from dataclasses import dataclass

from . import _checks
from .errors import ParameterError


@dataclass(frozen=True)
class Material:
    """Isotropic Kelvin-Voigt material of the rod.

    Parameters
    ----------
    E : float
        Young's modulus [Pa].
    nu : float
        Poisson ratio, in (-1, 0.5]; the shear modulus is ``E / (2 (1 + nu))``.
    mu : float
        Shear viscosity [Pa s] of the Kelvin-Voigt law; 0 gives a linear
        elastic rod.
    rho : float
        Density [kg/m^3].
    """

    E: float
    nu: float
    mu: float
    rho: float

    def __post_init__(self):
        object.__setattr__(self, "E", _checks.positive("E", self.E, " Pa"))
        nu = _checks.finite("nu", self.nu)
        if not -1.0 < nu <= 0.5:
            raise ParameterError(f"`nu` must lie in (-1, 0.5], got {self.nu!r}")
        object.__setattr__(self, "nu", nu)
        object.__setattr__(self, "mu", _checks.non_negative("mu", self.mu, " Pa s"))
        object.__setattr__(self, "rho", _checks.positive("rho", self.rho, " kg/m^3"))

    @property
    def G(self):
        """Shear modulus [Pa]."""
        return self.E / (2.0 * (1.0 + self.nu))


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
        try:
            return MEDIA[name]
        except (KeyError, TypeError):
            raise ParameterError(
                f"unknown `medium` {name!r}; valid presets are {sorted(MEDIA)}"
            ) from None


#: The paper's water (Table III) and air, where fluid loads are neglected.
MEDIA = {
    "water": Medium(rho=1022.0, Cx=0.01, Cy=2.5, Cz=2.5, By=1.5, Bz=1.5),
    "air": Medium(),
}
