"""A parallel robot: three soft legs clamped to the ground on a circle and to
a free platform above, under gravity partly sideways, the platform's centre
of mass off its middle: the legs bend and the platform moves 12 mm aside and
tilts. From straight, the robot settles (Kelvin-Voigt damping near critical
for the platform's sway) within 1.5 s. It is the robot of
tests/test_system_joints.py, which checks its settled pose against an
independent shooting solution of the Cosserat rod equations (after Till et
al.); docs/systems.md shows its picture.

    python examples/parallel_robot.py [OUT_DIR] [N]

prints the platform's settled position [m] and rotation vector (global).
"""

import sys

import numpy as np
from scipy.spatial.transform import Rotation

import rodmol

LEG_L, LEG_R = 0.2, 0.005  # m
MATERIAL = rodmol.Material(E=2e8, nu=0.5, mu=2e6, rho=1000.0)  # mu: near critical for the sway, ~30 rad/s
PLATFORM_M, PLATFORM_COM, BASE_RADIUS = 0.5, (0.02, 0.01, 0.0), 0.05  # kg, m (platform frame), m
GRAVITY = (-9.81, 0.0, -3.0)  # m/s^2, global: sideways and down
UP = np.array([[0.0, 0.0, -1.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]])  # a leg's x axis along global z
LEG_POINTS = [(BASE_RADIUS * np.cos(a), BASE_RADIUS * np.sin(a), 0.0)  # m, global and platform frame
              for a in 2 * np.pi * np.arange(3) / 3 + 0.3]


def robot(n=32):
    """The System: legs ``leg0``..``leg2`` of ``n`` elements from the ground
    points (global) up to the same points of the platform (its frame), each
    tip clamped to it; the platform starts level at height LEG_L."""
    leg = rodmol.Rod(LEG_L, radius=LEG_R, material=MATERIAL)
    legs = {f"leg{i}": rodmol.Model(leg, n, base=rodmol.BaseMotion(position=p, rotation=UP))
            for i, p in enumerate(LEG_POINTS)}
    platform = rodmol.RigidBody(PLATFORM_M, (1e-3, 1e-3, 2e-3), centre_of_mass=PLATFORM_COM,
                                position=(0.0, 0.0, LEG_L))
    joints = [rodmol.Joint(("platform", p), (f"leg{i}", "tip")) for i, p in enumerate(LEG_POINTS)]
    return rodmol.System(legs, {"platform": platform}, joints, gravity=GRAVITY)


def settle(n=32, out=None):
    """Run the robot for 1.5 s from straight; returns the SystemResult."""
    return rodmol.simulate(robot(n), 1.5, output_dt=0.05, out=out, overwrite=out is not None)


if __name__ == "__main__":
    out = sys.argv[1] if len(sys.argv) > 1 and sys.argv[1] else None
    result = settle(int(sys.argv[2]) if len(sys.argv) > 2 else 32, out)
    platform = result["platform"]
    print("success:", result.success)
    print("platform position [m]:", np.array2string(platform.position[-1], precision=6))
    turned = Rotation.from_matrix(platform.rotation[-1]).as_rotvec()
    print("platform rotation vector:", np.array2string(turned, precision=6))
