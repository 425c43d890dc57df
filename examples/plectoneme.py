"""A plectoneme (PyElastica's RodSelfContact/PlectonemesCase): a soft rod
held at both ends, one end turned N = 10 times about the rod's axis over
50 s, then held 50 s, with self-contact (rodmol.RodContact(rod, rod)). The
link Lk = Tw + Wr (rodmol.analysis.link) follows the turns applied and no
part passes through another. docs/systems.md ("Contact between rods")
shows its picture; solvers/plectoneme.py measures it.

PyElastica's numbers: L = 1 m, r = 0.025 m, E = 1 MPa, G = E / 1.5, a mass
of 1 kg, no gravity, 150 elements. Where it differs, and why:
- its far end slides freely along the axis (zero axial force) while
  turning; rodmol has no slider, so the base is first moved SLACK towards
  the tip over T_SLACK (the rod buckles into an Euler arch) as it starts to turn;
- it damps every node's velocity at 2 1/s; here the rod's Kelvin-Voigt
  viscosity MU (no drag on rigid motion: there is no fluid);
- it pushes its middle node sideways while turning (1e-4 m/s per step);
  here a small side force PUSH on the middle over T_SLACK;
- its self-contact is a penalty k = 1e4 N/m, 10 N s/m per element pair;
  here rodmol's law with its defaults (docs/systems.md).
The turning and the shortening follow smooth steps (no jerk at their ends),
so the integrator meets no corner. The run stalls once the first loop lies
on itself (t = 17-19 s; docs/systems.md, "The plectoneme").

    python examples/plectoneme.py [OUT_DIR] [N_ELEMENTS] [T_END] [TURNS]

prints the link, twist and writhe at the end, the least gap between
surfaces and the steps taken.
"""

import sys

import numpy as np

import rodmol
from rodmol import analysis

L, R = 1.0, 0.025  # m
E = 1e6  # Pa
RHO = 1.0 / (np.pi * R**2 * L)  # kg/m^3: a rod of 1 kg
MU = 2e4  # Pa s: the first bending mode (12 rad/s) about 0.4 of critical
T_TWIST, T_HOLD = 50.0, 50.0  # s
TURNS = 10
SLACK = 0.3 * L  # m, how far the turning end moves toward the other, over T_SLACK
T_SLACK = 5.0  # s
PUSH = 1e-3  # N, sideways on the middle over T_SLACK (the arch buckles one way)


def smooth_step(t, duration):
    """(fraction done, its rate [1/s]) of a step from 0 to 1 over ``duration`` [s] with no jerk at its ends."""
    w = min(max(t / duration, 0.0), 1.0)
    return w**3 * (10 - 15 * w + 6 * w * w), 30 * w * w * (1 - w) ** 2 / duration


def plectoneme(n=150, turns=TURNS, t_twist=T_TWIST, slack=SLACK, push=PUSH, t_slack=T_SLACK):
    """The System: the rod along global x, its base turned ``turns`` times about
    the axis (about -x: a right-handed twist from base to tip, Lk = +turns) over ``t_twist`` [s] and
    moved ``slack`` [m] along it over ``t_slack`` [s], its tip clamped where it is at rest."""
    material = rodmol.Material(E=E, G=E / 1.5, mu=MU, rho=RHO)

    def spin(t):
        return np.array([-2 * np.pi * turns * smooth_step(t, t_twist)[1], 0.0, 0.0])

    def shorten(t):
        return np.array([slack * smooth_step(t, t_slack)[1], 0.0, 0.0])

    def side(t):
        return np.array([0.0, 0.0, -push * (1.0 - smooth_step(t, t_slack)[0])])

    model = rodmol.Model(rodmol.Rod(L, radius=R, material=material), n, gravity=(0.0, 0.0, 0.0),
                         base=rodmol.BaseMotion(velocity=shorten, angular_velocity=spin),
                         loads=[rodmol.PointForce(L / 2, side, name="push")])
    return rodmol.System({"rod": model}, joints=[rodmol.Joint(("rod", "tip"), "world")],
                         contacts=[rodmol.RodContact("rod", "rod")], gravity=(0.0, 0.0, 0.0))


def turned(t, turns=TURNS, t_twist=T_TWIST):
    """Turns [-] the base has made at times ``t`` [s]."""
    return turns * np.array([smooth_step(ti, t_twist)[0] for ti in np.atleast_1d(t)])


def link_error(result, turns=TURNS, t_twist=T_TWIST):
    """(link, twist, writhe) [turns] per frame and the largest |link - turns applied| / turns."""
    lk, tw, wr = analysis.result_link(result["rod"])
    return lk, tw, wr, float(np.max(np.abs(lk - turned(result.t, turns, t_twist))) / turns)


if __name__ == "__main__":
    out = sys.argv[1] if len(sys.argv) > 1 and sys.argv[1] else None
    n = int(sys.argv[2]) if len(sys.argv) > 2 else 150
    t_end = float(sys.argv[3]) if len(sys.argv) > 3 else T_TWIST + T_HOLD
    turns = float(sys.argv[4]) if len(sys.argv) > 4 else TURNS
    result = rodmol.simulate(plectoneme(n, turns), t_end, output_dt=1.0, out=out, overwrite=out is not None,
                             progress=True)
    lk, tw, wr, worst = link_error(result, turns)
    print("success:", result.success, result.message)
    print(f"link {lk[-1]:.4f}, twist {tw[-1]:.4f}, writhe {wr[-1]:.4f} turns; worst |Lk - turns| / turns {worst:.2e}")
    print(f"least gap between surfaces [m]: {result.rod_contacts()[1].min():.3g}; steps {result.stats['steps']}")
