"""Independent references for held rods: the planar Reissner (Cosserat) rod
solved as a boundary-value problem with scipy's ``solve_bvp``, and the
analytical extensible catenary (Irvine, Cable Structures, 1981).

Plane (x, z), z up; theta is the angle of the section's tangent d1 from the
x axis toward z, n (nx, nz) the internal force [N] and m the moment [N m]
(positive turning x toward z) that the part beyond s exerts on the part
before it. Balance per unit reference length under the weight w [N/m]:
n' = (0, w), m' = -(r' x n), m = EI theta'; strains from the internal force
in the section frame: r' = (1 + N / EA) d1 + (V / GA) d2, N = n . d1,
V = n . d2, d2 = (-sin theta, cos theta). Nothing here comes from rodmol.
"""

import numpy as np
from scipy.integrate import solve_bvp


def _rates(s, y, w, ea, ga, ei):
    x, z, theta, nx, nz, m = y
    c, si = np.cos(theta), np.sin(theta)
    axial, shear = (nx * c + nz * si) / ea, (-nx * si + nz * c) / ga
    dx = (1.0 + axial) * c - shear * si
    dz = (1.0 + axial) * si + shear * c
    return np.vstack([dx, dz, m / ei, np.zeros_like(s), np.full_like(s, w), -(dx * nz - dz * nx)])


def clamped_pinned(length, weight, ea, ga, ei, tip, n_mesh=400, tol=1e-8):
    """A rod clamped at the origin along x and pinned at ``tip`` (x, z) [m]
    under its weight ``weight`` [N/m] (acting along -z): returns a function of
    s [m] giving (x, z, theta, nx, nz, m) and the solver's result."""
    s = np.linspace(0.0, length, n_mesh)
    sag = 0.5 * np.sqrt(max(length**2 - tip[0] ** 2, 0.0))
    guess = np.zeros((6, n_mesh))
    guess[0] = s * tip[0] / length
    guess[1] = -4.0 * sag * s * (length - s) / length**2 + tip[1] * s / length
    guess[2] = np.arctan(np.gradient(guess[1], guess[0]))
    guess[3] = weight * length**2 / (8.0 * max(sag, 1e-3 * length))
    guess[4] = weight * (s - 0.5 * length)

    def boundary(ya, yb):
        return np.array([ya[0], ya[1], ya[2], yb[0] - tip[0], yb[1] - tip[1], yb[5]])

    sol = solve_bvp(lambda s, y: _rates(s, y, weight, ea, ga, ei), boundary, s, guess, tol=tol,
                    max_nodes=200000)
    if not sol.success:
        raise RuntimeError(f"solve_bvp: {sol.message}")
    return sol.sol, sol


def catenary(length, weight, ea, span):
    """The extensible catenary of unstretched ``length`` [m], weight
    ``weight`` [N/m] per unstretched length and axial stiffness ``ea`` [N]
    hung between two points at the same height ``span`` [m] apart: returns
    (x(s), z(s)) of the unstretched arc length s and the horizontal tension H [N]."""
    v = 0.5 * weight * length  # the vertical reaction of each support

    def x_of(s, h):
        return h * s / ea + (h / weight) * (np.arcsinh((weight * s - v) / h) + np.arcsinh(v / h))

    lo, hi = 1e-9 * weight * length, 1e3 * weight * length + ea
    for _ in range(200):  # bisection on H: the span grows with the tension
        h = 0.5 * (lo + hi)
        lo, hi = (h, hi) if x_of(length, h) < span else (lo, h)
    h = 0.5 * (lo + hi)

    def z_of(s):
        return ((0.5 * weight * s * s - v * s) / ea
                + (h / weight) * (np.sqrt(1.0 + ((weight * s - v) / h) ** 2) - np.sqrt(1.0 + (v / h) ** 2)))

    return (lambda s: x_of(s, h)), z_of, h
