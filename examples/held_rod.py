"""A rod held at both ends: a propped cantilever and a slack rod hanging from a pin.

The base is clamped; ``rodmol.Hold(L)`` pins the tip to the world.

Propped cantilever: L = 0.5 m, r = 1 cm, E = 1 GPa, nu = 0.5, rho = 1000
kg/m^3 under its weight, tip pinned where it is at rest. Reference: the
beam clamped at one end and simply supported at the other, reaction
R = 3 w L / 8 and midspan deflection w L^4 / (192 EI) (Euler-Bernoulli),
plus the shear compliance 1 / GA the Cosserat rod has (Timoshenko, no
shear-correction factor); the printed errors are against the latter.

Slack rod: L = 1 m, r = 5 mm, E = 1 MPa, tip pinned at (0.8 L, 0, 0).
Reference: the extensible catenary through the two points (Irvine). A cable
has no bending stiffness: the rod's clamp turns it horizontal within a
boundary layer of length sqrt(EI / H) at the base, where the two differ by
centimetres; the midspan sag agrees to a few 1e-3.

    python examples/held_rod.py [--plot out.png]
"""

import argparse

import numpy as np

import rodmol

GRAVITY = 9.81
NS = (10, 20, 40, 80)


def section(radius, E, rho):
    """(w [N/m], EA [N], GA [N], EI [N m^2]) with nu = 0.5 (G = E / 3)."""
    area = np.pi * radius**2
    return rho * area * GRAVITY, E * area, E / 3 * area, E * np.pi * radius**4 / 4


def rest_positions(rod, n, hold):
    """Node positions (N + 1, 3) [m] of the rod at rest under its weight (air)."""
    model = rodmol.Model(rod, n, gravity=(0.0, 0.0, -GRAVITY), medium="air", loads=[hold])
    return rodmol.simulate(model, 1e-6, initial="equilibrium", output_dt=1e-6).positions[0]


def propped(x, length, w, ei, ga):
    """Tip reaction [N] and deflection [m] (down) at x, with shear compliance 1 / GA."""
    c = 1.0 / ga
    reaction = w * length * (length**2 / (8 * ei) + c / 2) / (length**2 / (3 * ei) + c)
    bending = (w * x**2 * (6 * length**2 - 4 * length * x + x**2) / (24 * ei)
               - reaction * x**2 * (3 * length - x) / (6 * ei))
    return reaction, bending + c * (w * (length * x - x**2 / 2) - reaction * x)


def catenary(length, w, ea, span):
    """(x(s), z(s), H) of the extensible catenary between two points at equal height."""
    v = 0.5 * w * length

    def x_of(s, h):
        return h * s / ea + h / w * (np.arcsinh((w * s - v) / h) + np.arcsinh(v / h))

    lo, hi = 1e-9, 1e3 * w * length + ea
    for _ in range(200):
        h = 0.5 * (lo + hi)
        lo, hi = (h, hi) if x_of(length, h) < span else (lo, h)

    def z_of(s):
        return ((0.5 * w * s * s - v * s) / ea
                + h / w * (np.sqrt(1 + ((w * s - v) / h) ** 2) - np.sqrt(1 + (v / h) ** 2)))

    return (lambda s: x_of(s, h)), z_of, h


def cantilever_part():
    length, radius, E, rho = 0.5, 0.01, 1e9, 1000.0
    w, _, ga, ei = section(radius, E, rho)
    rod = rodmol.Rod(length, radius, rodmol.Material(E, 0.5, 0.0, rho))
    _, sag = propped(length / 2, length, w, ei, ga)
    print(f"propped cantilever: midspan sag, Euler-Bernoulli w L^4/(192 EI) = "
          f"{1e6 * w * length**4 / (192 * ei):.4f} um, with shear {1e6 * sag:.4f} um; "
          f"reaction 3 w L / 8 = {3 * w * length / 8:.5f} N")
    print(f"{'N':>5} {'sag [um]':>10} {'rel. error':>11} {'order':>6}")
    errors, shapes = [], {}
    for n in NS:
        pos = rest_positions(rod, n, rodmol.Hold(length))
        shapes[n] = pos
        errors.append(abs(-pos[n // 2, 2] / sag - 1))
        order = f"{np.log2(errors[-2] / errors[-1]):6.2f}" if len(errors) > 1 else ""
        print(f"{n:5d} {-1e6 * pos[n // 2, 2]:10.4f} {errors[-1]:11.3e} {order:>6}")
    print(f"propped cantilever relative error (N = {NS[-1]}): {errors[-1]:.3e}")
    return shapes, (lambda x: propped(x, length, w, ei, ga)[1])


def slack_part():
    length, radius, E, rho, span = 1.0, 0.005, 1e6, 1000.0, 0.8
    w, ea, _, ei = section(radius, E, rho)
    rod = rodmol.Rod(length, radius, rodmol.Material(E, 0.5, 0.0, rho))
    x_of, z_of, h = catenary(length, w, ea, span)
    layer = np.sqrt(ei / h)
    print(f"slack rod: catenary H = {h:.4f} N, midspan sag {-z_of(length / 2):.5f} m, "
          f"bending layer sqrt(EI/H) = {layer:.4f} m")
    print(f"{'N':>5} {'sag [m]':>9} {'rel. error':>11} {'max gap [m]':>12}")
    shapes = {}
    for n in NS:
        pos = rest_positions(rod, n, rodmol.Hold(length, position=(span, 0.0, 0.0)))
        shapes[n] = pos
        s = np.linspace(0.0, length, n + 1)
        gap = np.max(np.hypot(pos[:, 0] - x_of(s), pos[:, 2] - z_of(s)))
        error = abs(pos[n // 2, 2] / z_of(length / 2) - 1)
        print(f"{n:5d} {-pos[n // 2, 2]:9.5f} {error:11.3e} {gap:12.4f}")
    print(f"slack rod midspan sag relative error (N = {NS[-1]}): {error:.3e}")
    return shapes, x_of, z_of


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--plot", metavar="PNG", help="save a figure of both rods")
    args = parser.parse_args()
    beams, sag_of = cantilever_part()
    hanging, x_of, z_of = slack_part()
    if args.plot:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, (a, b) = plt.subplots(1, 2, figsize=(10, 3.8))
        x = np.linspace(0.0, 0.5, 200)
        a.plot(x, -1e6 * sag_of(x), "k-", lw=3, alpha=0.3, label="beam formula (with shear)")
        for n, marker in zip(NS, ("o", "s", "^", "")):
            a.plot(beams[n][:, 0], 1e6 * beams[n][:, 2], marker + "-", ms=3, lw=1, label=f"rodmol, N = {n}")
        a.set_xlabel("x [m]")
        a.set_ylabel("z [um]")
        a.set_title("propped cantilever under its weight")
        a.legend(fontsize=8)
        s = np.linspace(0.0, 1.0, 300)
        b.plot(x_of(s), z_of(s), "k-", lw=3, alpha=0.3, label="extensible catenary")
        for n, marker in zip(NS, ("o", "s", "^", "")):
            b.plot(hanging[n][:, 0], hanging[n][:, 2], marker + "-", ms=3, lw=1, label=f"rodmol, N = {n}")
        b.set_xlabel("x [m]")
        b.set_ylabel("z [m]")
        b.set_aspect("equal")
        b.set_title("slack rod: clamped base, tip pinned at 0.8 L")
        b.legend(fontsize=8)
        fig.tight_layout()
        fig.savefig(args.plot, dpi=120)
        print(f"figure: {args.plot}")


if __name__ == "__main__":
    main()
