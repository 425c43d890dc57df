"""Shared reference solutions for the physics tests (test_point_loads, test_beams)."""

import sys

import numpy as np
import pytest
from rod_bvp import catenary, clamped_pinned
from scipy.integrate import solve_bvp


def elastica_tip_force(length, ei, ea, ga, force, *, follower=False, weight=0.0):
    """Planar Reissner elastica (extensible, shearable) of a cantilever
    clamped at the origin along +x, with a tip force of magnitude ``force``
    along -y (dead) or along minus the second director of the tip section
    (follower, i.e. perpendicular to the tip section's axis), plus an
    optional dead weight ``weight`` [N/m] along -y.

    Unknowns x, y, theta (section angle), m (bending moment); the contact
    force n(s) is known up to the tip angle (a parameter for the follower).
    Returns the tip position (x, y) and the tip section angle.
    """
    s = np.linspace(0.0, length, 201)
    z = np.zeros((4, s.size))
    z[0] = s
    p = [0.0]

    def contact_force(s, p, f, w):
        if follower:
            fx, fy = f * np.sin(p[0]), -f * np.cos(p[0])
        else:
            fx, fy = 0.0, -f
        return fx + 0.0 * s, fy - w * (length - s)

    def rhs(s, z, p, f, w):
        _, _, th, m = z
        nx, ny = contact_force(s, p, f, w)
        c, sn = np.cos(th), np.sin(th)
        q1 = 1.0 + (nx * c + ny * sn) / ea      # axial strain + 1
        q2 = (-nx * sn + ny * c) / ga            # shear strain
        dx, dy = q1 * c - q2 * sn, q1 * sn + q2 * c
        return np.vstack([dx, dy, m / ei, -(dx * ny - dy * nx)])

    def bc(za, zb, p):
        return np.array([za[0], za[1], za[2], zb[3], zb[2] - p[0]])

    for frac in np.linspace(0.25, 1.0, 4):  # load continuation
        f, w = frac * force, frac * weight
        sol = solve_bvp(lambda s, z, p, f=f, w=w: rhs(s, z, p, f, w), bc, s, z, p=p,
                        tol=1e-10, max_nodes=100_000)
        assert sol.success, sol.message
        s, z, p = sol.x, sol.y, sol.p
    return z[:2, -1], z[2, -1]


def _observed_orders(errors):
    """log2 of the ratios of successive errors (grids refined by 2)."""
    e = np.asarray(errors, dtype=float)
    return np.log2(e[:-1] / e[1:])


@pytest.fixture
def elastica():
    """:func:`elastica_tip_force`, the planar Reissner elastica of a cantilever."""
    return elastica_tip_force


@pytest.fixture
def observed_orders():
    """Observed convergence orders of errors on grids refined by 2."""
    return _observed_orders


class ChecksPassed(Exception):
    """Raised where ``rodmol.simulate`` would start its work (compiling, the kernels, the
    initial equilibrium): building the system is no work, it sizes the state-sized checks."""


@pytest.fixture
def checks_only(monkeypatch):
    """``rodmol.simulate`` checks its arguments, then stops with :class:`ChecksPassed`
    instead of working; returns that class."""

    def stop(*args, **kwargs):
        raise ChecksPassed

    monkeypatch.setattr(sys.modules["rodmol.simulate"], "prepare_run", stop)
    return ChecksPassed


@pytest.fixture
def clamped_pinned_rod():
    """:func:`rod_bvp.clamped_pinned`, the planar Reissner rod clamped at one end
    and pinned at the other under its weight, by ``solve_bvp``."""
    return clamped_pinned


@pytest.fixture
def extensible_catenary():
    """:func:`rod_bvp.catenary`, the analytical extensible catenary."""
    return catenary
