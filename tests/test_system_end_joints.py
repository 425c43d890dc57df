"""Joints at rods' ends converge at second order, as the rest of the scheme:
beams held or joined at their ends by penalty joints (a pinned base's body
joint, a tip Hold, two bases joined, a base on another rod's tip, two tips
joined) against the beam formulas (Timoshenko, no shear correction: the
Cosserat rod's G A), at N = 15, 30, 60 per rod.

The penalties' default stiffness makes their compliance O(ds^2) against the
rod's (rodmol.holds.default_stiffness: 100 E A L / ds^2). At 100 E A / ds
(before) it was ds / 100 of an element's, a first-order term: the joined
bases and the branch converged at order 1.0 (2e-3, 1e-3, 5e-4 of the sag),
and on the propped cantilever and the two joined tips it cancelled part of
the scheme's own second-order error (orders 2.5 and 5.1, 2.3 and 2.8)."""

import numpy as np
import pytest

import rodmol
from rodmol.discretise.assembly import Assembly

GRIDS = (15, 30, 60)
# A stiff slender beam (sag / L ~ 1e-5: no membrane force, no geometric nonlinearity to speak of).
L, R, E, RHO, G = 0.1, 0.005, 1e10, 1000.0, 9.81
MATERIAL = rodmol.Material(E, 0.5, rho=RHO, mu=1e4)
W, EI, GA = RHO * np.pi * R**2 * G, E * np.pi * R**4 / 4, E / 3 * np.pi * R**2  # nu = 0.5: G = E / 3
BACK = rodmol.BaseMotion(rotation=np.diag([-1.0, -1.0, 1.0]))  # a rod leaving x = 0 along -x


def _nodes(system, rest, rod):
    """(N + 1, 3) positions [m] of rod ``rod``'s nodes in the state ``rest``."""
    assembly = Assembly(system)
    return assembly.rods[rod].layout.integrated_positions(rest[assembly.parts[rod]])


def cantilever_tip(length):
    """The tip's sag [m] of a cantilever of ``length`` under its weight."""
    return W * length**4 / (8 * EI) + W * length**2 / (2 * GA)


def propped_sag(x, length):
    """The sag [m] at x of a beam pinned at 0, clamped at ``length``: the shear force is
    R - w x with the pin's reaction R from the sag's zero at the clamp (the section turned
    by the bending alone, zero at the clamp)."""
    def sag(x, reaction):  # the bending's (EI turn' = M, the turning zero at the clamp), then the shear's
        def turn(s):
            return (reaction * s**2 / 2 - W * s**3 / 6) / EI
        bending = turn(length) * x - (reaction * x**3 / 6 - W * x**4 / 24) / EI
        return bending + (reaction * x - W * x**2 / 2) / GA
    a, b = sag(length, 0.0), sag(length, 1.0) - sag(length, 0.0)
    return sag(x, -a / b)


def joined_bases(n):
    """Two rods from x = 0 (a along +x, b along -x), bases joined (two base bodies, a body
    joint), b's tip clamped by a Hold: one cantilever of 2L. a's tip against the formula."""
    a = rodmol.Model(rodmol.Rod(L, R, MATERIAL), n)
    b = rodmol.Model(rodmol.Rod(L, R, MATERIAL), n, base=BACK, loads=[rodmol.Hold(L, "clamp")])
    system = rodmol.System({"a": a, "b": b}, joints=[rodmol.Joint(("a", "base"), ("b", "base"))],
                           gravity=(0.0, 0.0, -G))
    return -_nodes(system, rodmol.equilibrium(system), "a")[-1, 2] / cantilever_tip(2 * L) - 1.0


def branch(n):
    """Rod b's base clamped to rod a's tip (a base body held by a penalty joint), continuing
    it: one cantilever of 2L. b's tip against the formula."""
    a = rodmol.Model(rodmol.Rod(L, R, MATERIAL), n)
    b = rodmol.Model(rodmol.Rod(L, R, MATERIAL), n, base=rodmol.BaseMotion(position=(L, 0.0, 0.0)))
    system = rodmol.System({"a": a, "b": b}, joints=[rodmol.Joint(("b", "base"), ("a", "tip"))],
                           gravity=(0.0, 0.0, -G))
    return -_nodes(system, rodmol.equilibrium(system), "b")[-1, 2] / cantilever_tip(2 * L) - 1.0


def propped(n):
    """A beam of 2L pinned at its base (a base body's pin), its tip clamped (a Hold): the
    sag of its middle node against the formula."""
    model = rodmol.Model(rodmol.Rod(2 * L, R, MATERIAL), n)
    system = rodmol.System({"beam": model}, joints=[rodmol.Joint(("beam", "base"), "world", kind="pin"),
                                                    rodmol.Joint(("beam", "tip"), "world")],
                           gravity=(0.0, 0.0, -G))
    node = n // 2
    return -_nodes(system, rodmol.equilibrium(system), "beam")[node, 2] / propped_sag(model.s_nodes[node], 2 * L) - 1.0


def joined_tips(n):
    """Two cantilevers from walls 2L apart, their tips clamped to each other (a penalty joint
    between rods): the clamped-clamped beam's midspan."""
    left = rodmol.Model(rodmol.Rod(L, R, MATERIAL), n)
    right = rodmol.Model(rodmol.Rod(L, R, MATERIAL), n,
                         base=rodmol.BaseMotion(position=(2 * L, 0.0, 0.0), rotation=BACK.rotation))
    system = rodmol.System({"left": left, "right": right}, joints=[rodmol.Joint(("left", "tip"), ("right", "tip"))],
                           gravity=(0.0, 0.0, -G))
    span = 2 * L
    return -_nodes(system, rodmol.equilibrium(system), "left")[-1, 2] / (
        W * span**4 / (384 * EI) + W * span**2 / (8 * GA)) - 1.0


@pytest.mark.parametrize("case", [joined_bases, branch, propped, joined_tips], ids=lambda f: f.__name__)
def test_joints_at_rods_ends_converge_at_second_order_to_the_beam_formulas(case):
    """Measured (relative errors at N = 15, 30, 60; orders): joined bases 1.3e-4, 3.3e-5,
    8.3e-6 (2.00, 2.00); branch 1.1e-5, 2.8e-6, 6.6e-7 (2.01, 2.07); propped -1.2e-2, -3.1e-3,
    -7.9e-4 (1.97, 2.00); joined tips -4.3e-3, -1.1e-3, -2.7e-4 (2.00, 2.00)."""
    errors = np.array([case(n) for n in GRIDS])
    orders = np.log2(errors[:-1] / errors[1:])  # NaN if the error changed sign: a first-order term cancelling
    assert abs(errors[-1]) < 1e-2, errors
    assert np.all((orders > 1.8) & (orders < 2.3)), (errors, orders)
