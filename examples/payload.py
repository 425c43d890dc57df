"""A payload swinging at a cantilever's tip: a slender beam (1 m, radius
1 cm, E = 1 GPa, its own mass 0.3 kg) clamped at its base to the world,
a 0.3 kg payload clamped to its tip (a penalty joint), released straight
under gravity. The suddenly applied weight swings the payload down past its
rest, to about twice its static sag (a linear, undamped oscillator's
dynamic factor is 2), and back up. tests/test_system_joints.py checks the
same beam's swing frequency against the Euler-Bernoulli beam with a tip
mass; docs/systems.md shows its picture.

    python examples/payload.py [OUT_DIR] [N]

prints the payload's lowest height, its static sag (rodmol.equilibrium) and
their ratio.
"""

import sys

import rodmol

LENGTH, RADIUS = 1.0, 0.01  # m
MATERIAL = rodmol.Material(E=1e9, nu=0.5, mu=0.0, rho=1000.0)
PAYLOAD_M, PAYLOAD_J = 0.3, 2e-4  # kg, kg m^2 about the bending axes
GRAVITY = 1.0  # m/s^2, along -y: a sag of 2% of the length, where the beam is close to linear


def cantilever(n=16):
    """The System: ``beam`` along global x, ``payload`` clamped to its tip."""
    beam = rodmol.Model(rodmol.Rod(LENGTH, radius=RADIUS, material=MATERIAL), n)
    payload = rodmol.RigidBody(PAYLOAD_M, (1e-5, PAYLOAD_J, PAYLOAD_J), position=(LENGTH, 0.0, 0.0))
    return rodmol.System({"beam": beam}, {"payload": payload},
                         [rodmol.Joint(("payload", (0.0, 0.0, 0.0)), ("beam", "tip"), kind="clamp")],
                         gravity=(0.0, -GRAVITY, 0.0))


def swing(n=16, out=None):
    """One swing (0.8 s) from straight; returns (the SystemResult, the static sag [m], global y)."""
    system = cantilever(n)
    rest = rodmol.equilibrium(system)
    sag = rodmol.simulate(system, 1e-6, initial=rest, output_dt=1e-6)["payload"].position[0, 1]
    return rodmol.simulate(system, 0.8, output_dt=0.01, out=out, overwrite=out is not None), sag


if __name__ == "__main__":
    out = sys.argv[1] if len(sys.argv) > 1 and sys.argv[1] else None
    result, sag = swing(int(sys.argv[2]) if len(sys.argv) > 2 else 16, out)
    lowest = result["payload"].position[:, 1].min()
    print("success:", result.success)
    print(f"lowest payload height [m]: {lowest:.6f}")
    print(f"static sag [m]: {sag:.6f}")
    print(f"dynamic factor: {lowest / sag:.4f}")
