"""Two rods crossing at right angles (rodmol.RodContact): a soft rod clamped
at its base is released straight, just touching a stiffer rod clamped at
both ends that it crosses at two thirds of its length; it sags onto it and
settles resting across it. The support carries the share of its weight
that beam theory gives a cantilever propped there, w (6 L^2 - 4 L a + a^2)
/ (8 a), and the rods' centrelines end up the sum of their radii apart,
less the law's penetration. tests/test_examples.py runs it coarse;
docs/systems.md ("Contact between rods") shows its picture.

    python examples/rods_crossing.py [OUT_DIR] [N]

prints the weight the lower rod carries, the propped cantilever's and the
gap between the rods' surfaces.
"""

import sys

import numpy as np

import rodmol

L, R = 0.3, 0.01  # m, both rods
CROSS = 0.2025  # m, where the upper rod crosses the lower one, along it
SOFT = rodmol.Material(E=1e7, nu=0.5, mu=2e4, rho=1000.0)
STIFF = rodmol.Material(E=1e9, nu=0.5, mu=2e6, rho=1000.0)
G = 9.81  # m/s^2, along global -y
ALONG_Z = np.array([[0.0, 0.0, -1.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]])  # a rod's x axis along global z


def crossing(n=12):
    """The System: ``upper`` along global x from the origin, 2 R above ``lower``, which runs
    along global z under it at x = CROSS (off its nodes), clamped at both ends."""
    upper = rodmol.Model(rodmol.Rod(L, radius=R, material=SOFT), n,
                         base=rodmol.BaseMotion(position=(0.0, 2 * R, 0.0)))
    lower = rodmol.Model(rodmol.Rod(L, radius=R, material=STIFF), n,
                         base=rodmol.BaseMotion(position=(CROSS, 0.0, -L / 2 - 0.3 * L / n), rotation=ALONG_Z))
    return rodmol.System({"upper": upper, "lower": lower}, joints=[rodmol.Joint(("lower", "tip"), "world")],
                         contacts=[rodmol.RodContact("upper", "lower")], gravity=(0.0, -G, 0.0))


def propped_cantilever():
    """The prop's reaction [N] under the upper rod's weight (Euler-Bernoulli, rigid prop at CROSS)."""
    w = SOFT.rho * np.pi * R**2 * G
    return w * (6 * L**2 - 4 * L * CROSS + CROSS**2) / (8 * CROSS)


def carried(result):
    """The weight [N] the lower rod carries at the last frame: the upper rod's contact forces' sum."""
    forces, _, _ = result.rod_contacts()
    return float(forces["upper"][-1].sum(axis=0)[1])


if __name__ == "__main__":
    out = sys.argv[1] if len(sys.argv) > 1 and sys.argv[1] else None
    result = rodmol.simulate(crossing(int(sys.argv[2]) if len(sys.argv) > 2 else 12), 1.0, output_dt=0.01,
                             out=out, overwrite=out is not None)
    print("success:", result.success)
    print(f"carried [N]: {carried(result):.5f}")
    print(f"propped cantilever [N]: {propped_cantilever():.5f}")
    print(f"gap between the surfaces [m]: {result.rod_contacts()[1][-1]:.3g}")
