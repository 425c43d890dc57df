"""A branch: a short arm pinned by its base under the middle of a beam
clamped at both ends (a penalty joint holding the arm's base segment to the
beam's node), released 30 degrees from hanging straight down: it swings
about the pin as a pendulum while the beam sags and sways under it. Its
period is close to the compound pendulum's, 2 pi sqrt(2 L / 3 g) for a
uniform rod of length L, lengthened by the amplitude and the beam's give.
tests/test_system_branches.py checks the arm hanging at rest against the
single beam under a point force; docs/systems.md shows its picture.

    python examples/branch.py [OUT_DIR] [N]

prints the arm's measured swing period and the compound pendulum's.
"""

import sys

import numpy as np

import rodmol

BEAM_L, BEAM_R, ARM_L, ARM_R = 0.2, 0.005, 0.1, 0.003  # m
MATERIAL = rodmol.Material(E=1e8, nu=0.5, mu=1e4, rho=1000.0)
G = 9.81  # m/s^2, along global -z
SWING = np.radians(30.0)  # the arm's start, turned about global x from straight down


def branched(n=16):
    """The System: ``beam`` along global x from the origin, clamped there and at
    its tip (a Hold), ``arm`` of n/2 elements pinned by its base to the beam's
    middle node, starting straight, SWING from the downward vertical towards +y."""
    beam = rodmol.Model(rodmol.Rod(BEAM_L, BEAM_R, MATERIAL), n, loads=[rodmol.Hold(BEAM_L, "clamp")])
    down = np.array([0.0, np.sin(SWING), -np.cos(SWING)])  # the arm's x axis, global
    rotation = np.column_stack([down, [1.0, 0.0, 0.0], np.cross(down, [1.0, 0.0, 0.0])])
    arm = rodmol.Model(rodmol.Rod(ARM_L, ARM_R, MATERIAL), n // 2,
                       base=rodmol.BaseMotion(position=(BEAM_L / 2, 0.0, 0.0), rotation=rotation))
    return rodmol.System({"beam": beam, "arm": arm}, gravity=(0.0, 0.0, -G),
                         joints=[rodmol.Joint(("arm", "base"), ("beam", BEAM_L / 2), kind="pin")])


def period(result):
    """The arm's swing period [s]: twice the mean time between its tip's
    crossings of the vertical plane y = 0 (linear interpolation between frames)."""
    t, y = result.t, result["arm"].tip[:, 1]
    k = np.flatnonzero(np.sign(y[1:]) != np.sign(y[:-1]))
    crossings = t[k] - y[k] * (t[k + 1] - t[k]) / (y[k + 1] - y[k])
    return 2.0 * np.mean(np.diff(crossings))


def compound_pendulum():
    """The small-amplitude period [s] of a rigid uniform rod of length ARM_L pinned at one end."""
    return 2.0 * np.pi * np.sqrt(2.0 * ARM_L / (3.0 * G))


if __name__ == "__main__":
    out = sys.argv[1] if len(sys.argv) > 1 and sys.argv[1] else None
    result = rodmol.simulate(branched(int(sys.argv[2]) if len(sys.argv) > 2 else 16), 1.2, output_dt=0.005,
                             out=out, overwrite=out is not None)
    print("success:", result.success)
    print(f"swing period [s]: {period(result):.4f}")
    print(f"compound pendulum [s]: {compound_pendulum():.4f}")
