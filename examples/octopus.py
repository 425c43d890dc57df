"""An octopus on the sea floor: eight of the paper's tapered, cable-driven arms
on a free spherical head in water, under gravity and buoyancy, resting on the
floor (a PlaneContact with friction on every arm), then crawling.

The head (radius 5 cm, 2% heavier than the water it displaces, with a
sphere's added mass and drag) carries the arms on a circle below its centre,
leaving it radially, tilted down so that their straight tips just touch the floor.
From the straight rest state the octopus settles for ``SETTLE`` seconds onto
the floor; then it crawls: in each cycle the three front arms curl down
(cable 2, below the centreline), so that their tips, held on the floor by
friction, drag the head forward (+x), then curl up (cable 4) and straighten
again above the floor. The system is built in Python here; docs/systems.md
shows the picture and the measured numbers, and tests/test_examples.py
checks that the resting octopus is held just above the floor by its arms,
symmetric, that the floor carries its weight less its buoyancy (to first
order in ds: docs/systems.md), and that the crawl moves it forward.

    python examples/octopus.py [OUT_DIR]
"""

import sys

import numpy as np

import rodmol
from rodmol.arm import BASE_RADIUS, LENGTH, MATERIAL, TIP_RADIUS

ARMS = 8
HEAD_RADIUS = 0.05  # m
RING = 0.6  # the arms leave the head on the circle 0.6 of its radius below its centre
TILT = np.radians(8.0)  # the arms leave the head this far below the horizontal
FLOOR = -RING * HEAD_RADIUS - LENGTH * np.sin(TILT) - TIP_RADIUS  # m, global z: the straight tips touch it
SETTLE = 4.0  # s at rest before the crawl
PERIOD = 0.5  # s, one crawl cycle
PULL = 2.0  # N, the largest tension
CYCLES = 8  # crawl cycles in the run below


def head():
    """A sphere 2% denser than water, with a sphere's added mass and quadratic drag (body frame)."""
    water = rodmol.MEDIA["water"].rho
    volume = 4.0 / 3.0 * np.pi * HEAD_RADIUS**3
    mass = 1.02 * water * volume
    added = 0.5 * water * volume
    drag = 0.5 * water * 0.47 * np.pi * HEAD_RADIUS**2  # drag coefficient of a sphere, 0.47
    return rodmol.RigidBody(mass, (0.4 * mass * HEAD_RADIUS**2,) * 3, volume=volume,
                            added_mass=(added,) * 3 + (0.0,) * 3, drag=(drag,) * 3 + (1e-4,) * 3)


def floor():
    """The sea floor, z = FLOOR: a stiff, damped penalty with Coulomb friction."""
    return rodmol.PlaneContact(point=(0.0, 0.0, FLOOR), normal=(0.0, 0.0, 1.0), stiffness=2e3, damping=300.0,
                               friction=0.6, slip_speed=2e-3, name="floor")


def pulse(start, width, amount=PULL):
    """A smooth periodic pulse of ``amount`` [N] lasting ``width`` of each PERIOD from
    ``start`` (fractions of the period), after SETTLE; zero before."""
    def tension(t):
        if t < SETTLE:
            return 0.0
        phase = ((t - SETTLE) / PERIOD - start) % 1.0
        return amount * np.sin(np.pi * phase / width) ** 2 if phase < width else 0.0
    return tension


def crawl(angle):
    """The cable tensions {cable number: tension(t)} of the arm leaving at ``angle``
    (from +x, about z): the three front arms reach and pull, the others rest."""
    if np.cos(angle) > 0.5:  # curl down (tips on the floor, dragging the head), then lift back
        return {2: pulse(0.0, 0.5), 4: pulse(0.5, 0.4)}
    return {}


def octopus(n_elements=30, pattern=crawl):
    """The System: ``pattern(angle)`` gives each arm's tensions."""
    rods, joints = {}, []
    for i in range(ARMS):
        angle = 2.0 * np.pi * i / ARMS
        radial = np.array([np.cos(angle), np.sin(angle), 0.0])
        out = np.cos(TILT) * radial - np.sin(TILT) * np.array([0.0, 0.0, 1.0])
        side = np.array([-np.sin(angle), np.cos(angle), 0.0])
        frame = np.column_stack([out, side, np.cross(out, side)])  # the arm's base frame in the head's
        where = HEAD_RADIUS * (np.sqrt(1.0 - RING**2) * radial - RING * np.array([0.0, 0.0, 1.0]))
        name = f"arm{i + 1}"
        rods[name] = rodmol.paper_arm(n_elements, tensions=pattern(angle), markers=(), loads=[floor()])
        joints.append(rodmol.Joint(("head", where, frame), (name, "base")))
    return rodmol.System(rods, {"head": head()}, joints, medium="water", gravity=(0.0, 0.0, -9.81))


def net_weight(system):
    """Weight less buoyancy of the whole octopus [N] (> 0: it sinks), from the parts' volumes."""
    water, g = system.medium.rho, 9.81
    s = np.linspace(0.0, LENGTH, 2001)
    arm_volume = np.trapezoid(np.pi * np.interp(s, (0.0, LENGTH), (BASE_RADIUS, TIP_RADIUS)) ** 2, s)
    body = system.bodies["head"]
    return g * (body.mass - water * body.volume + ARMS * (MATERIAL.rho - water) * arm_volume)


if __name__ == "__main__":
    out = sys.argv[1] if len(sys.argv) > 1 else None
    system = octopus()
    result = rodmol.simulate(system, SETTLE + CYCLES * PERIOD, output_dt=0.02, out=out, overwrite=out is not None)
    print(result)
    x = result["head"].position
    rest = np.searchsorted(result.t, SETTLE)
    print(f"head at rest (t = {result.t[rest]:.2f} s): z = {x[rest, 2]:.4f} m (floor at {FLOOR:.4f} m)")
    print(f"head moved by {x[-1] - x[rest]} m in {CYCLES * PERIOD:g} s of crawling")
