"""Material and medium parameters (SI units), validated on construction."""

from dataclasses import dataclass, field

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
    """

    E: float
    nu: float | None = None
    mu: float = 0.0
    rho: float | None = None
    G: float | None = field(default=None, kw_only=True)

    def __post_init__(self):
        object.__setattr__(self, "E", _checks.positive("E", self.E, " Pa"))
        if self.rho is None:
            raise ParameterError("`rho` (density [kg/m^3]) is required")
        object.__setattr__(self, "rho", _checks.positive("rho", self.rho, " kg/m^3"))
        object.__setattr__(self, "mu", _checks.non_negative("mu", self.mu, " Pa s"))
        if (self.nu is None) == (self.G is None):
            raise ParameterError("give exactly one of `nu` (Poisson ratio) and `G` (shear modulus "
                                 f"[Pa]), got nu={self.nu!r}, G={self.G!r}")
        if self.G is None:
            nu = _checks.finite("nu", self.nu)
            if not -1.0 < nu <= 0.5:
                raise ParameterError(f"`nu` must lie in (-1, 0.5], got {self.nu!r}")
            object.__setattr__(self, "nu", nu)
            object.__setattr__(self, "G", self.E / (2.0 * (1.0 + nu)))
        else:
            object.__setattr__(self, "G", _checks.positive("G", self.G, " Pa"))
            object.__setattr__(self, "nu", self.E / (2.0 * self.G) - 1.0)


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
