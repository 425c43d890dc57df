"""Rod geometry (radius profile, rest strains) and the sectional stiffness, viscosity and inertia."""

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from . import _checks
from .errors import ParameterError
from .parameters import Material

#: The rest strains of a straight rod, local frame: stretch/shear q* [-] and curvature/twist k* [1/m].
STRAIGHT_STRETCH, STRAIGHT_CURVATURE = (1.0, 0.0, 0.0), (0.0, 0.0, 0.0)


@dataclass(frozen=True)
class Rod:
    """A rod of circular section, straight along the local x axis at rest
    unless its rest strains say otherwise.

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
    rest_curvature : (3,) floats, [(s, k_x, k_y, k_z), ...] or callable, keyword-only
        Rest curvature and twist k*(s) [1/m], local (material) frame: k*_x
        is the twist, k*_y and k*_z the curvatures about the section's axes.
        A constant, ``(s, k_x, k_y, k_z)`` points [m, 1/m] spanning s = 0 to
        L with increasing s (linear between them), or a callable ``k(s)`` of
        an array of arc lengths [m] returning shape ``s.shape + (3,)`` (or
        (3,) for a constant). Default (0, 0, 0): straight.
    rest_stretch : (3,) floats, [(s, q_x, q_y, q_z), ...] or callable, keyword-only
        Rest stretch and shear q*(s) [-], local frame, given like
        ``rest_curvature``; q*_x > 0 (the section faces forward). Default
        (1, 0, 0): unstretched, unsheared.

    Stresses are measured from the rest strains: N = Kl (q - q*) + Vl q_t,
    M = Kth (k - k*) + Vth k_t. The rest shape is the rod these strains
    build from the base (:func:`rodmol.undeformed_state`).
    """

    length: float
    radius: Any
    material: Material
    rest_curvature: Any = field(default=STRAIGHT_CURVATURE, kw_only=True)
    rest_stretch: Any = field(default=STRAIGHT_STRETCH, kw_only=True)

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
        for name in REST_STRAINS:
            self._rest_profile(name)
        # Callables are checked where they are sampled, on the actual grid.
        s = np.linspace(0.0, self.length, 65)
        self.radius_at(s)
        self.rest_strains_at(s)

    def _points(self, points, name="radius"):
        """``(s, values...)`` points as a tuple of rows, checked: increasing s from 0 to L."""
        points = np.asarray(points, dtype=float)
        s = points[:, 0]
        if np.any(np.diff(s) <= 0):
            raise ParameterError(f"`{name}` points must have increasing s, got s = {_checks.short(s.tolist())}")
        if s[0] != 0.0 or abs(s[-1] - self.length) > 1e-9 * self.length:
            raise ParameterError(f"`{name}` points must span s = 0 to the length {self.length!r} m, "
                                 f"got s from {s[0].item()!r} to {s[-1].item()!r} m")
        return tuple(tuple(float(x) for x in row) for row in points)

    def _rest_profile(self, name):
        """Check the form of a rest strain (a 3-vector, points or a callable) and
        store constants and points as tuples."""
        value = getattr(self, name)
        if callable(value):
            return
        shape = np.shape(v) if (v := _checks.floats(value)) is not None else None
        if shape == (3,):
            object.__setattr__(self, name, tuple(float(x) for x in v))
        elif len(shape or ()) == 2 and shape[1] == 4 and shape[0] >= 2:
            object.__setattr__(self, name, self._points(v, name))
        else:
            raise ParameterError(
                f"`{name}` must be a 3-vector (local frame), (s, x, y, z) points or a callable of s, "
                f"got {_checks.short(value)}")

    @property
    def straight(self):
        """True if the rod is straight and unstretched at rest (the default rest strains)."""
        return self.rest_stretch == STRAIGHT_STRETCH and self.rest_curvature == STRAIGHT_CURVATURE

    def rest_strains_at(self, s):
        """Rest strains (q*, k*) at arc lengths ``s`` [m], each ``s.shape + (3,)``,
        local frame: stretch/shear [-] and curvature/twist [1/m]."""
        s = np.asarray(s, dtype=float)
        q, k = (_vector_profile(name, getattr(self, name), s) for name in REST_STRAINS)
        bad = ~(q[..., 0] > 0.0)
        if np.any(bad):
            i = np.flatnonzero(bad.ravel())[0]
            raise ParameterError(f"`rest_stretch` must have q*_x > 0 along the rod (the section faces "
                                 f"forward); q*({s.ravel()[i]:.6g} m) = {q.reshape(-1, 3)[i].tolist()}")
        return q, k

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
        x, w = GAUSS_LEGENDRE
        s = 0.5 * self.length * (x + 1.0)
        return 0.5 * self.length * np.sum(w * self.area(s))

    def mass(self):
        """Mass [kg]."""
        return self.material.rho * self.volume()


#: 64-point Gauss-Legendre nodes and weights on [-1, 1], computed once (an eigenvalue
#: problem: 10 ms a call, which every equilibrium's load scale paid through volume()).
GAUSS_LEGENDRE = np.polynomial.legendre.leggauss(64)
#: The rest strain parameters, in the order :meth:`Rod.rest_strains_at` returns them.
REST_STRAINS = ("rest_stretch", "rest_curvature")


def _vector_profile(name, value, s):
    """A rest strain ``value`` (checked by the Rod) sampled at arc lengths ``s`` [m],
    ``s.shape + (3,)``, finite (else a ParameterError naming ``name``)."""
    if callable(value):
        try:
            out = np.broadcast_to(np.asarray(value(s), dtype=float), s.shape + (3,))
        except Exception as exc:
            raise ParameterError(f"`{name}` callable failed on arc lengths (it must return "
                                 f"s.shape + (3,) values, local frame): {exc}") from exc
    elif np.ndim(value) == 1:
        out = np.broadcast_to(np.asarray(value, dtype=float), s.shape + (3,))
    else:
        knots = np.asarray(value)
        out = np.stack([np.interp(s, knots[:, 0], knots[:, c]) for c in (1, 2, 3)], axis=-1)
    bad = ~np.all(np.isfinite(out), axis=-1)
    if np.any(bad):
        i = np.flatnonzero(bad.ravel())[0]
        raise ParameterError(f"`{name}` must be finite along the rod; at s = {s.ravel()[i]:.6g} m it is "
                             f"{out.reshape(-1, 3)[i].tolist()}")
    return np.array(out)
