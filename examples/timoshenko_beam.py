"""Timoshenko beam: a shear-soft cantilever under a transverse end force.

L = 3 m, r = 0.25 m, rho = 5000 kg/m^3, E = 1 MPa, G = 10 kPa (G = E / 100,
so shear gives a third of the deflection), end force F = 15 N along -y, no
gravity. Reference: the linear Timoshenko tip deflection

    delta = F L^3 / (3 E I) + F L / (kappa G A),  kappa = 1,

since rodmol's shear stiffness is G A with no shear-correction factor (a
solid circle's usual kappa = 6 (1 + nu) / (7 + 6 nu) is not applied). The
deflection is 2% of L, so the linear theory is a fair reference to a few
1e-4: rodmol's default scheme is second order in ds, and from N = 40 on the
remaining 3.5e-4 is the geometric nonlinearity the linear theory leaves out.

    python examples/timoshenko_beam.py [--plot out.png]
"""

import argparse

import numpy as np

import rodmol

L, RADIUS, RHO, E, G, FORCE = 3.0, 0.25, 5000.0, 1.0e6, 1.0e4, 15.0
J = np.pi * RADIUS**4 / 4.0
A = np.pi * RADIUS**2
NS = (10, 20, 40, 80)


def timoshenko(x):
    """Linear Timoshenko deflection (positive down) along the beam, kappa = 1."""
    return FORCE / (E * J) * (L * x**2 / 2.0 - x**3 / 6.0) + FORCE * x / (G * A)


def rodmol_positions(n):
    rod = rodmol.Rod(L, RADIUS, rodmol.Material(E, rho=RHO, G=G))
    model = rodmol.Model(rod, n, gravity=(0.0, 0.0, 0.0),
                         loads=[rodmol.PointForce(L, (0.0, -FORCE, 0.0))])
    # Frame 0 of a (negligibly short) run is its initial state: the static equilibrium.
    return rodmol.simulate(model, 1e-6, initial="equilibrium", output_dt=1e-6).positions[0]


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--plot", metavar="PNG", help="save a figure of the deflection")
    args = parser.parse_args()

    bending = FORCE * L**3 / (3 * E * J)
    shear = FORCE * L / (G * A)
    reference = bending + shear
    print(f"Timoshenko beam L = {L} m, r = {RADIUS} m, E = {E:g} Pa, G = {G:g} Pa, F = {FORCE} N")
    print(f"reference tip deflection {reference:.6f} m = bending {bending:.6f} + shear {shear:.6f} "
          f"(kappa = 1)")
    print(f"{'N':>5} {'rodmol [m]':>12} {'reference [m]':>14} {'rel. error':>11} {'order':>6}")
    shapes, errors = {}, []
    for n in NS:
        pos = rodmol_positions(n)
        shapes[n] = pos
        delta = -pos[-1, 1]
        errors.append(abs(delta / reference - 1.0))
        order = f"{np.log2(errors[-2] / errors[-1]):6.2f}" if len(errors) > 1 else ""
        print(f"{n:5d} {delta:12.6f} {reference:14.6f} {errors[-1]:11.3e} {order:>6}")
    print(f"Euler-Bernoulli alone would give {bending:.6f} m ({bending / reference - 1.0:+.1%})")
    print(f"relative error (N = {NS[-1]}): {errors[-1]:.3e}")

    if args.plot:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, ax = plt.subplots(figsize=(6, 3.8))
        x = np.linspace(0.0, L, 200)
        ax.plot(x, 1e3 * timoshenko(x), "k-", lw=3, alpha=0.3, label="Timoshenko (kappa = 1)")
        ax.plot(x, 1e3 * FORCE / (E * J) * (L * x**2 / 2 - x**3 / 6), "k--", lw=1,
                label="Euler-Bernoulli")
        for n, marker in zip(NS, ("o", "s", "^", "")):
            pos = shapes[n]
            ax.plot(pos[:, 0], -1e3 * pos[:, 1], marker + "-", ms=3, lw=1, label=f"rodmol, N = {n}")
        ax.set_xlabel("x [m]")
        ax.set_ylabel("deflection [mm]")
        ax.set_title("Timoshenko beam, end force 15 N")
        ax.legend(fontsize=8)
        fig.tight_layout()
        fig.savefig(args.plot, dpi=120)
        print(f"figure: {args.plot}")


if __name__ == "__main__":
    main()
