"""The octopus of ``examples/octopus.py``: eight of the paper's tapered, cable-driven arms
on a free spherical head in water, under gravity and buoyancy, on the sea floor (a
PlaneContact with friction on every arm); the System :func:`octopus` builds, which the
example crawls and ``rodmol/OctopusCrawl-v0`` (:mod:`rodmol.control.crawl`) drives.

The head (radius 5 cm, 2% heavier than the water it displaces, with a sphere's added
mass and drag) carries the arms on a circle below its centre, leaving it radially,
tilted down so that their straight tips just touch the floor. Global z is up, +x the
direction of arm 1.
"""

import numpy as np

from ..arm import BASE_RADIUS, LENGTH, MATERIAL, TIP_RADIUS, paper_arm
from ..bodies import RigidBody
from ..loads import PlaneContact
from ..parameters import MEDIA
from ..systems import Joint, System

ARMS = 8
HEAD_RADIUS = 0.05  # m
RING = 0.6  # the arms leave the head on the circle 0.6 of its radius below its centre
TILT = np.radians(8.0)  # the arms leave the head this far below the horizontal
FLOOR = -RING * HEAD_RADIUS - LENGTH * np.sin(TILT) - TIP_RADIUS  # m, global z: the straight tips touch it


def head():
    """A sphere 2% denser than water, with a sphere's added mass and quadratic drag (body frame)."""
    water = MEDIA["water"].rho
    volume = 4.0 / 3.0 * np.pi * HEAD_RADIUS**3
    mass = 1.02 * water * volume
    added = 0.5 * water * volume
    drag = 0.5 * water * 0.47 * np.pi * HEAD_RADIUS**2  # drag coefficient of a sphere, 0.47
    return RigidBody(mass, (0.4 * mass * HEAD_RADIUS**2,) * 3, volume=volume,
                     added_mass=(added,) * 3 + (0.0,) * 3, drag=(drag,) * 3 + (1e-4,) * 3)


def floor():
    """The sea floor, z = FLOOR: a stiff, damped penalty with Coulomb friction."""
    return PlaneContact(point=(0.0, 0.0, FLOOR), normal=(0.0, 0.0, 1.0), stiffness=2e3, damping=300.0,
                        friction=0.6, slip_speed=2e-3, name="floor")


def arm_angle(i):
    """The angle [rad] about z, from +x, at which arm ``i`` (0-based) leaves the head."""
    return 2.0 * np.pi * i / ARMS


def octopus(n_elements=30, pattern=lambda angle: {}):
    """The System, its arms ``"arm1"``-``"arm8"`` (N = ``n_elements`` each) on the body
    ``"head"``: ``pattern(angle)`` gives the tensions {cable number: input} of the arm
    leaving at ``angle`` [rad] (default: all slack)."""
    rods, joints = {}, []
    for i in range(ARMS):
        angle = arm_angle(i)
        radial = np.array([np.cos(angle), np.sin(angle), 0.0])
        out = np.cos(TILT) * radial - np.sin(TILT) * np.array([0.0, 0.0, 1.0])
        side = np.array([-np.sin(angle), np.cos(angle), 0.0])
        frame = np.column_stack([out, side, np.cross(out, side)])  # the arm's base frame in the head's
        where = HEAD_RADIUS * (np.sqrt(1.0 - RING**2) * radial - RING * np.array([0.0, 0.0, 1.0]))
        name = f"arm{i + 1}"
        rods[name] = paper_arm(n_elements, tensions=pattern(angle), markers=(), loads=[floor()])
        joints.append(Joint(("head", where, frame), (name, "base")))
    return System(rods, {"head": head()}, joints, medium="water", gravity=(0.0, 0.0, -9.81))


def net_weight(system):
    """Weight less buoyancy of the whole octopus [N] (> 0: it sinks), from the parts' volumes."""
    water, g = system.medium.rho, 9.81
    s = np.linspace(0.0, LENGTH, 2001)
    arm_volume = np.trapezoid(np.pi * np.interp(s, (0.0, LENGTH), (BASE_RADIUS, TIP_RADIUS)) ** 2, s)
    body = system.bodies["head"]
    return g * (body.mass - water * body.volume + ARMS * (MATERIAL.rho - water) * arm_volume)
