"""Rod geometry (radius profile) and the sectional stiffness, viscosity and inertia."""

from dataclasses import dataclass
from typing import Any

import numpy as np

from . import _checks
from .errors import ParameterError
from .parameters import Material


@dataclass(frozen=True)
class Rod:
    """A straight rod of circular section along the local x axis.

    Parameters
    ----------
    length : float
        Rest length L [m].
    radius : float, (float, float), [(s, r), ...] or callable
        Section radius [m]: a constant, a ``(base, tip)`` pair for a linear
        taper, ``(s, r)`` points [m] spanning s = 0 to L with increasing s
        (linear between them, as ``radius = [[s, r], ...]`` in a scenario
        file), or a callable ``r(s)`` of the arc length s in [0, L] [m] (it
        is called with numpy arrays).
    material : Material
    """

    length: float
    radius: Any
    material: Material

    def __post_init__(self):
        object.__setattr__(self, "length", _checks.positive("length", self.length, " m"))
        if not isinstance(self.material, Material):
            raise ParameterError(f"`material` must be a rodmol.Material, got {self.material!r}")
        if not callable(self.radius):
            shape = np.shape(r) if (r := _checks.floats(self.radius)) is not None else None
            if shape == ():
                _checks.positive("radius", self.radius, " m")
            elif shape == (2,):
                _checks.positive("radius[0] (base)", self.radius[0], " m")
                _checks.positive("radius[1] (tip)", self.radius[1], " m")
            elif len(shape or ()) == 2 and shape[1] == 2 and shape[0] >= 2:
                object.__setattr__(self, "radius", self._points(r))
            else:
                raise ParameterError(
                    "`radius` must be a number, a (base, tip) pair, (s, r) points or a callable "
                    f"r(s), got {_checks.short(self.radius)}"
                )
        # Callables are checked where they are sampled, on the actual grid.
        self.radius_at(np.linspace(0.0, self.length, 65))

    def _points(self, points):
        """``(s, r)`` points as a tuple of pairs, checked: increasing s from 0 to L."""
        s, r = np.asarray(points, dtype=float).T
        if np.any(np.diff(s) <= 0):
            raise ParameterError(f"`radius` points must have increasing s, got s = {_checks.short(s.tolist())}")
        if s[0] != 0.0 or abs(s[-1] - self.length) > 1e-9 * self.length:
            raise ParameterError(f"`radius` points must span s = 0 to the length {self.length!r} m, "
                                 f"got s from {s[0].item()!r} to {s[-1].item()!r} m")
        return tuple((float(a), float(b)) for a, b in zip(s, r))

    def radius_at(self, s):
        """Radius [m] at arc lengths ``s`` [m] (array in, array out)."""
        s = np.asarray(s, dtype=float)
        if callable(self.radius):
            try:
                r = np.broadcast_to(np.asarray(self.radius(s), dtype=float), s.shape)
            except Exception as exc:
                raise ParameterError(f"`radius` callable failed on arc lengths: {exc}") from exc
        elif np.ndim(self.radius) == 0:
            r = np.full(s.shape, float(self.radius))
        elif np.ndim(self.radius) == 2:
            knots, values = np.asarray(self.radius).T
            r = np.interp(s, knots, values)
        else:
            base, tip = (float(x) for x in self.radius)
            r = base + (tip - base) * s / self.length
        bad = ~(np.isfinite(r) & (r > 0.0))
        if np.any(bad):
            i = np.flatnonzero(bad.ravel())[0]
            raise ParameterError(
                f"`radius` must be finite and > 0 m along the rod; r({s.ravel()[i]:.6g} m) = "
                f"{float(r.ravel()[i])!r}"
            )
        return np.array(r)

    def area(self, s):
        """Section area A = pi r^2 [m^2]."""
        return np.pi * self.radius_at(s) ** 2

    def second_moments(self, s):
        """(Jx, Jy, Jz) [m^4] as an array (..., 3): Jy = Jz = pi r^4 / 4, Jx = Jy + Jz."""
        j = np.pi * self.radius_at(s) ** 4 / 4.0
        return np.stack([2.0 * j, j, j], axis=-1)

    def stiffness(self, s):
        """Linear and angular stiffness diagonals Kl = (EA, GA, GA), Kth = (G Jx, E Jy, E Jz)."""
        m = self.material
        a = self.area(s)[..., None]
        kl = a * np.array([m.E, m.G, m.G])
        kth = self.second_moments(s) * np.array([m.G, m.E, m.E])
        return kl, kth

    def viscosity(self, s):
        """Kelvin-Voigt diagonals Vl = mu (3A, A, A), Vth = mu (Jx, 3Jy, 3Jz) [N s, N m^2 s],
        or A eta_l, J eta_th with the material's per-component viscosities."""
        mu = self.material.mu
        a = self.area(s)[..., None]
        if self.material.viscosity is not None:
            eta_l, eta_th = self.material.viscosities
            return a * eta_l, self.second_moments(s) * eta_th
        vl = mu * a * np.array([3.0, 1.0, 1.0])
        vth = mu * self.second_moments(s) * np.array([1.0, 3.0, 3.0])
        return vl, vth

    def volume(self):
        """Volume [m^3], by Gauss-Legendre quadrature of A(s)."""
        x, w = np.polynomial.legendre.leggauss(64)
        s = 0.5 * self.length * (x + 1.0)
        return 0.5 * self.length * np.sum(w * self.area(s))

    def mass(self):
        """Mass [kg]."""
        return self.material.rho * self.volume()
