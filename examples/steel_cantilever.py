"""A stiff, undamped steel cantilever released from a tip load, for 25 s.

Till's example (JohnDTill/ContinuumRobotExamples, 02_Dynamics): a steel rod
(E = 200 GPa, G = 80 GPa, r = 1 mm, L = 0.5 m, rho = 8000 kg/m^3, no
material damping) clamped along +x under transverse gravity carries a 0.196 N
tip force along -y, which is removed at t = 0+. The rod then swings about its
gravity equilibrium; its first-mode period is compared with Euler-Bernoulli,
2 pi L^2 / (1.8751^2 sqrt(EI / (rho A))) = 0.1787 s.

The release through the public API: the static equilibrium of the *loaded*
model is the initial state of the *unloaded* one. (A tip force given as knots
that drop to zero just after t = 0, ``PointForce(L, [(0, 0, -F, 0), (1e-6,
0, 0, 0)])``, does the same in one model, but then the solver has to step
through the drop.)

The grid's axial and shear waves are about 1e4 times faster than the swing
and nothing damps them, so this is a job for the fixed-step generalized-alpha
backend (``backend="galpha"``: 2 ms steps, numerical damping of the
unresolved modes set by ``rho_inf``); CVODE (``--backend cvode``) caps its
BDF order at 2 here and takes ~1 ms steps, damping the swing more
(``docs/troubleshooting.md``).

    python examples/steel_cantilever.py [--backend galpha|cvode] [--mu MU] [--plot out.png]
"""

import argparse
import time

import numpy as np

import rodmol

L, RADIUS, E, G, RHO = 0.5, 1e-3, 200e9, 80e9, 8000.0
TIP_FORCE = 0.196  # N: the weight of Till's 20 g tip mass
N, T_END = 40, 25.0


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--backend", default="galpha", choices=["galpha", "cvode"])
    parser.add_argument("--mu", type=float, default=0.0, help="Kelvin-Voigt viscosity [Pa s]")
    parser.add_argument("--plot", metavar="PNG", help="save a figure of the tip's swing")
    args = parser.parse_args()

    rod = rodmol.Rod(L, RADIUS, rodmol.Material(E, G=G, mu=args.mu, rho=RHO))
    free = rodmol.Model(rod, N)  # gravity (0, -9.81, 0) by default: transverse
    loaded = rodmol.Model(rod, N, loads=[rodmol.PointForce(L, (0.0, -TIP_FORCE, 0.0))])
    start = rodmol.equilibrium(loaded)

    options = dict(dt=2e-3, rho_inf=0.9) if args.backend == "galpha" else {}
    rodmol.simulate(free, 0.02, initial=start, backend=args.backend, **options)  # compile
    cpu = time.process_time()
    result = rodmol.simulate(free, T_END, initial=start, backend=args.backend, output_dt=2e-3,
                             **options)
    cpu = time.process_time() - cpu

    ei, rho_a = E * np.pi * RADIUS**4 / 4, RHO * np.pi * RADIUS**2
    period_eb = 2 * np.pi * L**2 / (1.8751**2 * np.sqrt(ei / rho_a))
    tip = result.tip[:, 1]
    first = result.t <= 2.0
    period = rodmol.oscillation_period(result.t[first], tip[first])
    swing = [np.ptp(tip[window]) / 2 * 1e3 for window in (result.t <= 0.5, result.t >= T_END - 0.5)]
    print(f"steel cantilever N = {N}, mu = {args.mu:g} Pa s, {T_END:g} s with {args.backend} "
          f"{options}: {cpu:.2f} s CPU, {result.stats['steps']} steps")
    print(f"first-mode period {period:.5f} s, Euler-Bernoulli {period_eb:.5f} s")
    print(f"period relative error: {abs(period / period_eb - 1):.2e}")
    print(f"tip swing amplitude {swing[0]:.2f} mm over the first 0.5 s, {swing[1]:.2f} mm over the last")

    if args.plot:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, axes = plt.subplots(1, 2, figsize=(10, 3.6), sharey=True)
        for ax, window in zip(axes, (result.t <= 1.0, result.t >= T_END - 1.0)):
            ax.plot(result.t[window], tip[window] * 1e3, lw=1)
            ax.set_xlabel("t [s]")
        axes[0].set_ylabel("tip y [mm]")
        axes[0].set_title("first second")
        axes[1].set_title("last second")
        fig.suptitle(f"Steel cantilever released from a {TIP_FORCE} N tip force ({args.backend})")
        fig.tight_layout()
        fig.savefig(args.plot, dpi=120)
        print(f"figure: {args.plot}")


if __name__ == "__main__":
    main()
