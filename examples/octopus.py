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
again above the floor. The system is built by rodmol.control.octopus (which
rodmol/OctopusCrawl-v0 drives too); docs/systems.md
shows the picture and the measured numbers, and tests/test_examples.py
checks that the resting octopus is held just above the floor by its arms,
symmetric, that the floor carries its weight less its buoyancy (to first
order in ds: docs/systems.md), and that the crawl moves it forward.

    python examples/octopus.py [OUT_DIR]
"""

import sys

import numpy as np

import rodmol
from rodmol.control.octopus import ARMS, FLOOR, HEAD_RADIUS, RING, TILT, floor, head, net_weight  # noqa: F401
from rodmol.control.octopus import octopus as octopus_system

SETTLE = 4.0  # s at rest before the crawl
PERIOD = 0.5  # s, one crawl cycle
PULL = 2.0  # N, the largest tension
CYCLES = 8  # crawl cycles in the run below


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
    """The System (built by :func:`rodmol.control.octopus.octopus`): ``pattern(angle)`` gives
    each arm's tensions."""
    return octopus_system(n_elements, pattern)


if __name__ == "__main__":
    out = sys.argv[1] if len(sys.argv) > 1 else None
    system = octopus()
    result = rodmol.simulate(system, SETTLE + CYCLES * PERIOD, output_dt=0.02, out=out, overwrite=out is not None)
    print(result)
    x = result["head"].position
    rest = np.searchsorted(result.t, SETTLE)
    print(f"head at rest (t = {result.t[rest]:.2f} s): z = {x[rest, 2]:.4f} m (floor at {FLOOR:.4f} m)")
    print(f"head moved by {x[-1] - x[rest]} m in {CYCLES * PERIOD:g} s of crawling")
