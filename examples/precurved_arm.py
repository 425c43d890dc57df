"""A precurved arm: a quarter circle at rest, straightened by a tip moment, curled by a cable.

A rod clamped at the origin along +x has the rest curvature k* = (0, 0, 1/R)
[1/m] (local frame), R = 2 L / pi: unloaded, without gravity, it rests on a
quarter circle, tip at R (1, 1, 0). Two exact checks:

* the rest shape: the undeformed state's tip against R (1, 1, 0);
* a tip moment M = -EI / R about z straightens it: the bending moment is
  uniform, so the curvature k* + M / EI vanishes everywhere and, with no
  force, the rod lies straight along x with its tip at (L, 0, 0).

Then a cable on the inside of the bend (p_y = +4 mm) pulled with 0.2 N
curls the arm further (no reference: it shows a cable on a precurved rod).

    python examples/precurved_arm.py [--n 40] [--plot out.png]
"""

import argparse

import numpy as np

import rodmol

L, RADIUS, E, NU, RHO = 0.3, 0.008, 2.0e5, 0.5, 1080.0
BEND = 2.0 * L / np.pi  # the quarter circle's radius [m]
EI = E * np.pi * RADIUS**4 / 4.0


def model(n, loads=(), cables=()):
    rod = rodmol.Rod(L, RADIUS, rodmol.Material(E, NU, rho=RHO), rest_curvature=(0.0, 0.0, 1.0 / BEND))
    return rodmol.Model(rod, n, gravity=(0.0, 0.0, 0.0), loads=loads, cables=cables)


def shape(m, y):
    """Node positions [m], global, as Result.positions rebuilds them."""
    return rodmol.SemiDiscrete(m).state_view(0.0, y).positions


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n", type=int, default=40, help="number of elements (default 40)")
    parser.add_argument("--plot", metavar="PNG", help="save a figure of the three shapes")
    args = parser.parse_args()

    free = model(args.n)
    rest = shape(free, rodmol.undeformed_state(free))
    straightened_model = model(args.n, loads=[rodmol.PointMoment(L, (0.0, 0.0, -EI / BEND), frame="local")])
    straightened = shape(straightened_model, rodmol.equilibrium(straightened_model))
    curled_model = model(args.n, cables=[rodmol.Cable((0.004, 0.0), L, 0.2, name="inner")])
    curled = shape(curled_model, rodmol.equilibrium(curled_model))

    print(f"Rod L = {L} m, r = {RADIUS} m, E = {E:g} Pa, rest curvature 1/R = {1 / BEND:.6g} 1/m, "
          f"N = {args.n}, no gravity")
    print(f"{'tip [m]':<34} {'x':>10} {'y':>10} {'z':>10}")
    print(f"{'rest shape (exact R, R, 0)':<34} " + " ".join(f"{c:10.6f}" for c in rest[-1]))
    print(f"{'straightened (exact L, 0, 0)':<34} " + " ".join(f"{c:10.6f}" for c in straightened[-1]))
    print(f"{'curled by the cable (0.2 N)':<34} " + " ".join(f"{c:10.6f}" for c in curled[-1]))
    print(f"rest shape tip relative error: {np.linalg.norm(rest[-1] - [BEND, BEND, 0.0]) / L:.3e}")
    print(f"straightened tip relative error: {np.linalg.norm(straightened[-1] - [L, 0.0, 0.0]) / L:.3e}")

    if args.plot:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, ax = plt.subplots(figsize=(5, 4.5))
        phi = np.linspace(0.0, 0.5 * np.pi, 100)
        ax.plot(BEND * np.sin(phi), BEND * (1.0 - np.cos(phi)), "k-", lw=3, alpha=0.3, label="exact rest shape")
        for points, label in ((rest, "rest shape"), (straightened, "tip moment -EI/R"),
                              (curled, "cable, 0.2 N")):
            ax.plot(points[:, 0], points[:, 1], "o-", ms=2, lw=1.2, label=label)
        ax.set_aspect("equal")
        ax.set_xlabel("x [m]")
        ax.set_ylabel("y [m]")
        ax.set_title("A precurved arm")
        ax.legend(fontsize=8)
        fig.tight_layout()
        fig.savefig(args.plot, dpi=120)
        print(f"figure: {args.plot}")


if __name__ == "__main__":
    main()
