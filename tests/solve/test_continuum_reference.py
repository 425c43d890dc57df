"""The continuum reference of solvers/continuum.py (solve_bvp on the static
Cosserat rod) against closed-form solutions, and rodmol's two schemes against
it: the centred scheme's equilibrium must converge at second order in ds, the
upwind (the paper's) at first order."""

import os
import sys

import numpy as np
import pytest

import rodmol

SOLVERS = os.path.join(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))), "solvers")
sys.path.insert(0, SOLVERS)

from continuum import continuum_equilibrium, discrete_positions, observed_orders  # noqa: E402

#: Base rotation taking the rod's axis (local x) to global +z.
ALONG_Z = ((0.0, 0.0, -1.0), (0.0, 1.0, 0.0), (1.0, 0.0, 0.0))


@pytest.mark.parametrize("rotation", [None, ALONG_Z], ids=["along x", "along z"])
def test_small_weight_matches_euler_bernoulli_cantilever(rotation):
    # Slender (r / L = 1e-2) so that shear adds only 3 (r/L)^2 = 3e-4 of the
    # deflection, and loaded lightly (tip deflection 5e-4 L) to stay linear.
    length, radius, young, rho, g = 1.0, 0.01, 1e6, 1000.0, 1e-4
    rod = rodmol.Rod(length, radius, rodmol.Material(E=young, nu=0.5, mu=0.0, rho=rho))
    base = None if rotation is None else rodmol.BaseMotion(position=(0.1, 0.2, 0.3), rotation=rotation)
    model = rodmol.Model(rod, 4, gravity=(0.0, -g, 0.0), base=base)
    ref = continuum_equilibrium(model)
    w = rho * np.pi * radius**2 * g  # N/m
    ei, ga = young * np.pi * radius**4 / 4.0, young / 3.0 * np.pi * radius**2
    bernoulli = w * length**4 / (8.0 * ei)
    base_point = np.asarray(model.base.position)
    axis = np.asarray(model.base.rotation)[:, 0]
    tip = ref["positions"][-1] - base_point
    deflection = -tip[1]
    assert deflection == pytest.approx(bernoulli, rel=1e-3)
    # With the shear deflection w L^2 / (2 G A) of a Timoshenko beam added,
    # only the geometric nonlinearity, O((deflection / L)^2), is left.
    assert deflection == pytest.approx(bernoulli + w * length**2 / (2.0 * ga), rel=1e-5)
    assert tip @ axis == pytest.approx(length, rel=1e-5)
    np.testing.assert_allclose(ref["positions"][0], base_point, atol=1e-14)
    np.testing.assert_allclose(ref["rotations"][0], model.base.rotation, atol=1e-12)


def test_tip_cable_without_weight_bends_into_a_circular_arc():
    # No external load: the total stress vanishes, so the body carries minus
    # the cable's stress, a constant axial force -T and moment -p x T e_x.
    length, radius, young, tension, pz = 0.3, 0.008, 110e3, 0.2, 0.004
    rod = rodmol.Rod(length, radius, rodmol.Material(E=young, nu=0.5, mu=0.0, rho=1000.0))
    model = rodmol.Model(rod, 8, gravity=(0.0, 0.0, 0.0), cables=[rodmol.Cable((0.0, pz), length, tension)])
    ref = continuum_equilibrium(model)
    stretch = 1.0 - tension / (young * np.pi * radius**2)
    ky = -tension * pz / (young * np.pi * radius**4 / 4.0)  # 1/m, about local y
    s = model.s_nodes
    arc = stretch / ky * np.stack([np.sin(ky * s), 0.0 * s, np.cos(ky * s) - 1.0], axis=1)
    np.testing.assert_allclose(ref["positions"], arc, atol=1e-9 * length)


def test_schemes_converge_to_the_continuum_at_their_order():
    # A uniform arm in water under its weight, bent out of the plane of
    # gravity by a tip-anchored cable (tip deflection about 0.8 L).
    length = 0.3
    rod = rodmol.Rod(length, 0.008, rodmol.Material(E=110e3, nu=0.5, mu=300.0, rho=1080.0))
    cable = rodmol.Cable((0.0, 0.004), length, 0.2)

    def model(n):
        return rodmol.Model(rod, n, medium_density=1022.0, cables=[cable])

    ref = continuum_equilibrium(model(10))
    exact_tip = ref["positions"][-1]
    assert exact_tip[2] > 0.2 * length and exact_tip[1] < -0.5 * length  # strongly bent both ways
    errors = {}
    for scheme in ("upwind", "centred"):
        errors[scheme] = [np.linalg.norm(discrete_positions(model(n), 0.0, scheme)[-1] - exact_tip) / length
                          for n in (10, 20, 40)]
    centred, upwind = observed_orders(errors["centred"]), observed_orders(errors["upwind"])
    print("tip errors / L:", errors, "orders: centred", centred, "upwind", upwind)
    assert min(centred) >= 1.8, errors
    assert all(0.8 <= p <= 1.3 for p in upwind), errors
    assert errors["centred"][-1] < 1e-3  # and the reference is far more accurate than that
