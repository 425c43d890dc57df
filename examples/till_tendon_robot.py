"""Till, Aloi and Rucker's tendon robot, through rodmol's public API.

The dynamics example ``02_Dynamics/03_Tendon_Robot`` of
JohnDTill/ContinuumRobotExamples (C++): a 0.7144 m spring-steel backbone of
radius 0.675 mm with one tendon on spacer disks 15.06 mm off the axis,
terminated at the tip, driven by a motor that reels in 16.19 mm between
3.652 s and 3.967 s and lets it out again between 17.63 s and 17.94 s.
Till's parameters: E = 207 GPa, G = E / 2.6, total mass 0.034 kg, gravity
across the rod, tendon compliance 1e-4 1/N, 51.8 mm of tendon from the
motor to the base, no extension-shear damping (Bse = 0), bending-torsion
damping Bbt = 5e-4 I N m^2 s and the drag C q|q| with C = 1e-4 I kg/m^2.

Frames: Till's rod axis is z, gravity -x, the tendon at +x. rodmol's rod
runs along its local x axis with offsets (p_y, p_z); the map
(x, y, z)_Till -> (y, z, x)_rodmol is a rotation, so gravity is -y, the
tendon sits at p_y = +15.06 mm and Till's tip x is rodmol's tip y.

Till's C++ (N = 200 Euler steps in space, BDF-alpha with dt = 0.05 s)
gives a static tip x of -0.1493 m and a held tip x of 0.2086 m at t = 10 s.

    python examples/till_tendon_robot.py [--n 50] [--t-end 25] [--plot out.png] [--csv out.csv]
"""

import argparse
import time

import numpy as np

import rodmol

E, RADIUS, LENGTH, MASS = 207e9, 0.00135 / 2, 0.7144, 0.034  # Pa, m, m, kg
AREA, J = np.pi * RADIUS**2, np.pi * RADIUS**4 / 4  # m^2, m^4 (Jy = Jz = J, Jx = 2 J)
BBT = 5e-4  # N m^2 s, Till's bending-torsion damping matrix Bbt = 5e-4 I
MOTOR = [(0.0, 0.0), (3.652, 0.0), (3.967, -0.01619), (17.63, -0.01619), (17.94, 0.0)]  # (s, m)
TILL_STATIC_TIP_X, TILL_HELD_TIP_X = -0.1493, 0.2086  # m, at t = 0 and t = 10 s


def model(n_elements=50):
    material = rodmol.Material(
        E=E, G=E / 2.6, rho=MASS / (LENGTH * AREA),
        # Per-component viscosities [Pa s]: Bse = 0, and Bbt / J for each component.
        viscosity=dict(shear_extension=(0.0, 0.0, 0.0), bending_torsion=(BBT / (2 * J), BBT / J, BBT / J)))
    tendon = rodmol.Cable((0.01506, 0.0), LENGTH, outside_body=True, displacement=MOTOR,
                          compliance=1e-4, base_to_actuator=0.0518, name="tendon")
    return rodmol.Model(rodmol.Rod(LENGTH, RADIUS, material), n_elements, gravity=(0.0, -9.81, 0.0),
                        cables=[tendon], drag_law="componentwise", drag_coefficients=(1e-4, 1e-4, 1e-4))


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n", type=int, default=50, help="number of elements")
    parser.add_argument("--t-end", type=float, default=25.0, help="end time [s]")
    parser.add_argument("--rtol", type=float, default=None, help="CVODE relative tolerance")
    parser.add_argument("--plot", metavar="PNG", help="save the tip trajectory")
    parser.add_argument("--csv", metavar="CSV", help="save t, tip x, y, z (Till's frame)")
    args = parser.parse_args()

    robot = model(args.n)
    start = time.perf_counter()
    result = rodmol.simulate(robot, args.t_end, output_dt=0.05, rtol=args.rtol)
    wall = time.perf_counter() - start
    print(result.message)
    till_x = result.tip[:, 1]  # Till's x is rodmol's global y
    print(f"N = {args.n}, {result.stats.get('steps')} steps, wall time {wall:.1f} s "
          f"(solver {result.stats.get('wall_time_s', float('nan')):.1f} s)")
    print(f"static tip x: {till_x[0]:.5f} m (Till {TILL_STATIC_TIP_X} m), "
          f"difference {1e3 * (till_x[0] - TILL_STATIC_TIP_X):+.2f} mm")
    if result.t[-1] >= 10.0:
        held = float(np.interp(10.0, result.t, till_x))
        print(f"tip x at t = 10 s: {held:.5f} m (Till {TILL_HELD_TIP_X} m), "
              f"difference {1e3 * (held - TILL_HELD_TIP_X):+.2f} mm")
    print(f"tendon tension: static {result.tensions[0, 0]:.3f} N, max {result.tensions[:, 0].max():.3f} N")
    if result.t[-1] >= 10.0:
        system = rodmol.SemiDiscrete(robot)
        held = rodmol.equilibrium(system, 10.0)
        print(f"held pose (equilibrium with the motor at z = -16.19 mm): tip x "
              f"{system.state_view(10.0, held).tip[1]:.5f} m")
    if args.csv:
        till = np.column_stack([result.t, result.tip[:, 1], result.tip[:, 2], result.tip[:, 0]])
        np.savetxt(args.csv, till, delimiter=",", header="t [s],tip x [m],tip y [m],tip z [m] (Till's frame)")
    if args.plot:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, (ax, bx) = plt.subplots(2, 1, figsize=(7, 5.5), sharex=True, height_ratios=(3, 1.2))
        ax.plot(result.t, till_x, "C0-", lw=1.2, label=f"rodmol, N = {args.n}")
        ax.plot([0.0], [TILL_STATIC_TIP_X], "kx", ms=9, mew=2, label="Till's C++: static tip")
        ax.plot([10.0], [TILL_HELD_TIP_X], "k+", ms=11, mew=2, label="Till's C++: t = 10 s")
        ax.set_ylabel("tip x (Till's frame) [m]")
        ax.legend(loc="center", fontsize=8)
        ax.grid(alpha=0.3)
        bx.plot(result.t, 1e3 * result.actuator_positions[:, 0], "C1-", lw=1.2)
        bx.set_ylabel("motor z [mm]")
        bx.set_xlabel("t [s]")
        bx.grid(alpha=0.3)
        fig.suptitle("Till's tendon robot (02_Dynamics/03_Tendon_Robot) in rodmol")
        fig.tight_layout()
        fig.savefig(args.plot, dpi=120)


if __name__ == "__main__":
    main()
