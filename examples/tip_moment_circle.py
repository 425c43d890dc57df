"""A tip moment M = 2 pi EI / L rolls a straight rod into a closed circle.

A rod clamped at the origin along +x, no gravity, carries a pure moment
about z at its tip (a follower moment, in the section's frame; about z a
dead moment gives the same equilibrium). The exact solution is a uniform
curvature k_z = M / EI = 2 pi / L: the tip returns to the base and the rod
closes into a circle of radius L / (2 pi). The static solver reaches it by
load continuation from the straight rod.

    python examples/tip_moment_circle.py [--n 40] [--plot out.png]
"""

import argparse
import time

import numpy as np

import rodmol

L, RADIUS, E, NU, RHO = 1.0, 0.01, 1.0e6, 0.5, 1000.0
EI = E * np.pi * RADIUS**4 / 4.0
MOMENT = 2.0 * np.pi * EI / L


def equilibrium_result(n, moment):
    """The static equilibrium under a tip moment, as frame 0 of a Result."""
    rod = rodmol.Rod(L, RADIUS, rodmol.Material(E, NU, rho=RHO))
    model = rodmol.Model(rod, n, gravity=(0.0, 0.0, 0.0),
                         loads=[rodmol.PointMoment(L, (0.0, 0.0, moment), frame="local")])
    # Frame 0 of a (negligibly short) run is its initial state: the static equilibrium.
    return rodmol.simulate(model, 1e-6, initial="equilibrium", output_dt=1e-6)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n", type=int, default=40, help="number of elements (default 40)")
    parser.add_argument("--plot", metavar="PNG", help="save a figure of the rolling-up")
    args = parser.parse_args()

    print(f"Rod L = {L} m, r = {RADIUS} m, E = {E:g} Pa, N = {args.n}, tip moment "
          f"M = 2 pi EI/L = {MOMENT:.6g} N m, no gravity")
    start = time.perf_counter()
    result = equilibrium_result(args.n, MOMENT)
    wall = time.perf_counter() - start
    pos, k = result.positions[0], result.curvature[0, :-1]  # strain nodes 0..N-1
    gap = np.linalg.norm(pos[-1]) / L
    k_error = np.max(np.abs(k[:, 2] / (MOMENT / EI) - 1.0))
    centre = np.array([0.0, L / (2.0 * np.pi), 0.0])
    r_error = np.max(np.abs(np.linalg.norm(pos - centre, axis=1) / (L / (2.0 * np.pi)) - 1.0))
    print(f"{'quantity':<34} {'rodmol':>12} {'exact':>12}")
    print(f"{'tip position |u(L)| [m]':<34} {np.linalg.norm(pos[-1]):12.3e} {0.0:12.3e}")
    print(f"{'curvature k_z, min..max [1/m]':<34} {k[:, 2].min():12.6f} {MOMENT / EI:12.6f}")
    print(f"{'':<34} {k[:, 2].max():12.6f}")
    print(f"{'distance of nodes to centre [m]':<34} "
          f"{np.max(np.linalg.norm(pos - centre, axis=1)):12.6f} {L / (2 * np.pi):12.6f}")
    print(f"tip gap relative error: {gap:.3e}")
    print(f"curvature relative error: {k_error:.3e}")
    print(f"circle radius relative error: {r_error:.3e}  (nodes of a regular N-gon of side ds)")
    print(f"(equilibrium + one frame: {wall:.2f} s)")

    if args.plot:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, ax = plt.subplots(figsize=(5, 4.5))
        for frac in (0.25, 0.5, 0.75):
            p = equilibrium_result(args.n, frac * MOMENT).positions[0]
            ax.plot(p[:, 0], p[:, 1], "-", lw=1.2, label=f"M = {frac:g} x 2 pi EI/L")
        phi = np.linspace(0.0, 2.0 * np.pi, 200)
        rc = L / (2.0 * np.pi)
        ax.plot(rc * np.sin(phi), rc * (1.0 - np.cos(phi)), "k-", lw=3, alpha=0.3,
                label="exact circle")
        ax.plot(pos[:, 0], pos[:, 1], "o-", color="C3", ms=3, lw=1.2,
                label=f"M = 2 pi EI/L, N = {args.n}")
        ax.set_aspect("equal")
        ax.set_xlabel("x [m]")
        ax.set_ylabel("y [m]")
        ax.set_title("Tip moment rolls the rod into a circle")
        ax.legend(fontsize=8, loc="upper left")
        fig.tight_layout()
        fig.savefig(args.plot, dpi=120)
        print(f"figure: {args.plot}")


if __name__ == "__main__":
    main()
