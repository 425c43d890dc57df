"""Cantilever under a large tip force: rodmol against the elastica.

A rod clamped at the origin along +x, no gravity, carries a tip force of
magnitude F = 2 EI / L^2 (the tip deflects by about half the length), either
dead (fixed along -y) or follower (perpendicular to the tip section). The
reference is the planar Reissner elastica (extensible and shearable, like
the Cosserat rod) solved with ``scipy.integrate.solve_bvp``. rodmol's default
(centred) scheme is second order in ds: the error quarters as N doubles
(``scheme="upwind"``, the paper's, is first order).

    python examples/cantilever_tip_force.py [--plot out.png]
"""

import argparse

import numpy as np
from scipy.integrate import solve_bvp

import rodmol

L, RADIUS, E, NU, RHO = 1.0, 0.01, 1.0e6, 0.5, 1000.0
EI = E * np.pi * RADIUS**4 / 4.0
EA = E * np.pi * RADIUS**2
GA = E / (2.0 * (1.0 + NU)) * np.pi * RADIUS**2
FORCE = 2.0 * EI / L**2
NS = (10, 20, 40, 80)


def elastica(follower):
    """Centreline (x, y) of the planar Reissner elastica under the tip force."""
    s = np.linspace(0.0, L, 201)
    z = np.zeros((4, s.size))
    z[0] = s
    p = [0.0]  # tip section angle (used by the follower force)

    def rhs(s, z, p, f):
        _, _, th, m = z
        nx, ny = (f * np.sin(p[0]), -f * np.cos(p[0])) if follower else (0.0, -f)
        c, sn = np.cos(th), np.sin(th)
        q1 = 1.0 + (nx * c + ny * sn) / EA
        q2 = (-nx * sn + ny * c) / GA
        dx, dy = q1 * c - q2 * sn, q1 * sn + q2 * c
        return np.vstack([dx, dy, m / EI, -(dx * ny - dy * nx)])

    def bc(za, zb, p):
        return np.array([za[0], za[1], za[2], zb[3], zb[2] - p[0]])

    for frac in (0.25, 0.5, 0.75, 1.0):
        sol = solve_bvp(lambda s, z, p, f=frac * FORCE: rhs(s, z, p, f), bc, s, z, p=p, tol=1e-10,
                        max_nodes=100_000)
        if not sol.success:
            raise RuntimeError(sol.message)
        s, z, p = sol.x, sol.y, sol.p
    return z[:2]


def rodmol_positions(n, frame):
    rod = rodmol.Rod(L, RADIUS, rodmol.Material(E, NU, rho=RHO))
    model = rodmol.Model(rod, n, gravity=(0.0, 0.0, 0.0),
                         loads=[rodmol.PointForce(L, (0.0, -FORCE, 0.0), frame=frame)])
    # Frame 0 of a (negligibly short) run is its initial state: the static equilibrium.
    result = rodmol.simulate(model, 1e-6, initial="equilibrium", output_dt=1e-6)
    return result.positions[0]


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--plot", metavar="PNG", help="save a figure of the shapes")
    args = parser.parse_args()

    print(f"Cantilever L = {L} m, r = {RADIUS} m, E = {E:g} Pa, nu = {NU}, tip force "
          f"F = 2 EI/L^2 = {FORCE:.6g} N, no gravity")
    shapes = {}
    for frame, name in (("global", "dead"), ("local", "follower")):
        ref = elastica(frame == "local")
        print(f"\n{name} load: elastica tip (x, y) = ({ref[0, -1]:.6f}, {ref[1, -1]:.6f}) m")
        print(f"{'N':>5} {'x_tip [m]':>12} {'y_tip [m]':>12} {'|error|/L':>11} {'order':>6}")
        errors = []
        for n in NS:
            pos = rodmol_positions(n, frame)
            shapes[name, n] = pos
            errors.append(np.linalg.norm(pos[-1, :2] - ref[:, -1]) / L)
            order = f"{np.log2(errors[-2] / errors[-1]):6.2f}" if len(errors) > 1 else ""
            print(f"{n:5d} {pos[-1, 0]:12.6f} {pos[-1, 1]:12.6f} {errors[-1]:11.3e} {order:>6}")
        print(f"{name} relative error (N = {NS[-1]}): {errors[-1]:.3e}")
        shapes[name, "ref"] = ref

    if args.plot:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, ax = plt.subplots(figsize=(6, 4.5))
        for name, colour in (("dead", "C0"), ("follower", "C3")):
            ref = shapes[name, "ref"]
            ax.plot(ref[0], ref[1], "k-", lw=2.5, alpha=0.35)
            for n, marker in zip(NS[:2], ("o", "s")):
                pos = shapes[name, n]
                ax.plot(pos[:, 0], pos[:, 1], marker + "-", color=colour, ms=3, lw=0.8,
                        label=f"{name}, N = {n}")
            pos = shapes[name, NS[-1]]
            ax.plot(pos[:, 0], pos[:, 1], "-", color=colour, lw=1.2, label=f"{name}, N = {NS[-1]}")
        ax.plot([], [], "k-", lw=2.5, alpha=0.35, label="elastica (solve_bvp)")
        ax.set_aspect("equal")
        ax.set_xlabel("x [m]")
        ax.set_ylabel("y [m]")
        ax.set_title(r"Tip force $F = 2EI/L^2$: dead and follower")
        ax.legend(fontsize=8, loc="lower left")
        fig.tight_layout()
        fig.savefig(args.plot, dpi=120)
        print(f"figure: {args.plot}")


if __name__ == "__main__":
    main()
