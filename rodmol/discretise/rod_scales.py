"""A rod's scales, derived from its model: the time scale of its first bending mode, the
typical size of each state field (the tolerances' scales) and the damping ratio of the
fastest wave its grid carries (which decides a backend for stiff, lightly damped rods)."""

import numpy as np


def first_bending_frequency(model):
    """Angular frequency [rad/s] of the first bending mode of a uniform
    cantilever with the base section (Euler-Bernoulli, without the fluid):
    2 pi over it is the rod's time scale."""
    rod = model.rod
    mat, r_base = rod.material, float(rod.radius_at(0.0))
    return 1.8751**2 * np.sqrt(mat.E * r_base**2 / (4.0 * mat.rho)) / rod.length**2


def field_scales(model):
    """Typical size of each field, chosen so that an error of ``rtol``
    times the scale in any field moves the rod by about ``rtol`` L:
    positions L, quaternions 1, strains q 1, curvatures 1/L, velocities
    L / T and angular velocities L / (T r_min), the angular velocity that
    moves the thinnest section's surface as fast. T is the period of the
    first bending mode of a uniform cantilever with the base section
    (Euler-Bernoulli, without the fluid), the time scale of the motion.
    With contact friction the speed is at most the smallest ``slip_speed``:
    the friction law changes over it, and a coarser velocity tolerance let
    a rod stuck on a slope creep ten times too fast, and 50-100 times slower.
    """
    rod = model.rod
    length = rod.length
    r_min = float(np.min(rod.radius_at(model.s_nodes)))
    speed = length * first_bending_frequency(model) / (2.0 * np.pi)  # L / T
    slip = [load.slip_speed for load in model.loads if getattr(load, "friction", 0.0) > 0.0]
    speed = min([speed, *slip])
    return {"u": length, "Q": 1.0, "q": 1.0, "k": 1.0 / length, "v": speed, "w": speed / r_min}


def grid_damping_ratio(model):
    """Kelvin-Voigt damping ratio zeta = omega tau / 2 of the fastest axial
    wave the grid carries, omega = (pi / ds) sqrt(E / rho), with the
    relaxation time tau = 3 mu / E of the sectional law. Below 1 every mode
    of the grid is underdamped; the paper's arm at N = 100 has about 30.
    With per-component viscosities (``Material(viscosity=...)``) tau is the
    shortest relaxation time of the six components: one undamped component
    (e.g. no extension-shear damping, Bse = 0) leaves its modes undamped."""
    mat = model.rod.material
    if not model.viscosity:
        tau = 0.0
    elif mat.viscosity is None:
        tau = 3.0 * mat.mu / mat.E
    else:
        tau = float(np.min(mat.relaxation_times()))
    return 0.5 * tau * np.pi / model.ds * np.sqrt(mat.E / mat.rho)
