"""Till's tendon robot integrated with Till's own discretisation (an independent reproduction).

rodmol's example (examples/till_tendon_robot.py) is compared with Till's C++
(JohnDTill/ContinuumRobotExamples, 02_Dynamics/03_Tendon_Robot): a static tip
x of -0.1493 m and 0.2086 m at t = 10 s. This script re-implements Till's
scheme (till_scheme.py: shooting, forward Euler in s on N points, BDF-alpha
at a fixed dt) with the example's parameters, runs it at Till's settings
(N = 200, dt = 0.05 s, alpha = 0) and refines N and dt, to show where his
numbers come from and what they converge to.

Time labels: Till's loop solves step i with the motor at t_i = i dt and
stores it as column i; his plot draws column i at i T / (M - 1) (M = T / dt),
so the point his plot shows at 10 s is the state at 9.98 s. Both are given.

    python solvers/till_reference.py [--quick | --smoke] [--out DIR]
"""

import importlib.util
import os
import time

import _common as C
import till_scheme as S
from _common import np, plt, rodmol

SCRIPT = "till_reference.py"
EXAMPLE = os.path.join(os.path.dirname(C.HERE), "examples", "till_tendon_robot.py")
T_HELD = 10.0  # s


def example():
    """The module examples/till_tendon_robot.py (its parameters and model)."""
    spec = importlib.util.spec_from_file_location("till_tendon_robot", EXAMPLE)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def parameters(model, n_points):
    """Till's parameter vector (till_scheme.P) from a rodmol model of the robot.

    rodmol's rod runs along its local x with offsets (p_y, p_z); Till's along
    z with the tendon offset (x, y). The map (x, y, z)_Till = (y, z, x)_rodmol
    turns rodmol's local (x, y, z) components into Till's (z, x, y)."""
    rod, mat = model.rod, model.rod.material
    (cable,) = model.cables
    area, inertia = np.pi * rod.radius**2, np.pi * rod.radius**4 / 4.0
    to_till = [1, 2, 0]  # Till's component k is rodmol's component to_till[k]
    section = np.array([area] * 3)  # shear, shear, axial
    polar = np.array([2 * inertia, inertia, inertia])  # rodmol's (x, y, z): torsion, bending, bending
    visc = mat.viscosity
    P = np.zeros(S.N_PARAMS)
    P[S.KSE:S.KSE + 3] = [mat.G * area, mat.G * area, mat.E * area]
    P[S.KBT:S.KBT + 3] = [mat.E * inertia, mat.E * inertia, mat.G * 2 * inertia]
    P[S.BSE:S.BSE + 3] = (np.asarray(visc["shear_extension"]) * section)[to_till]
    P[S.BBT:S.BBT + 3] = (np.asarray(visc["bending_torsion"]) * polar)[to_till]
    P[S.CDRAG:S.CDRAG + 3] = np.asarray(model.drag_coefficients)[to_till]
    P[S.RHOJ:S.RHOJ + 3] = mat.rho * np.array([inertia, inertia, 2 * inertia])
    P[S.GRAV:S.GRAV + 3] = np.asarray(model.gravity)[to_till]
    P[S.OFFSET:S.OFFSET + 3] = [cable.offset[0], cable.offset[1], 0.0]
    P[S.RHOA] = mat.rho * area
    P[S.DS] = rod.length / (n_points - 1)
    P[S.COMPLIANCE] = cable.compliance
    P[S.REST] = cable.rest_length
    P[S.BASE_TO_MOTOR] = cable.base_to_actuator
    P[S.FSCALE] = mat.rho * area * np.linalg.norm(model.gravity) * rod.length
    P[S.LENGTH] = rod.length
    return P


def till_run(n_points=200, dt=0.05, alpha=0.0, t_end=25.0, tol=1e-7, module=None):
    """Till's scheme on the example's robot: dict with t (i dt) [s], tip
    (n_t, 3) in Till's frame [m], tension [N], iterations, the worst scaled
    residual and the wall time [s]. ``tol`` bounds the tip residuals as
    fractions of the rod's weight (force), weight x L (moment) and 1e-3 L
    (tendon length): at 1e-7 the tip moves by well under a micrometre, and the
    round-off floor (up to ~2e-8 at dt = 0.003 s, where c0 = 480/s) is below."""
    module = module or example()
    P = parameters(module.model(10), n_points)
    knots = np.array(module.MOTOR, dtype=float)
    n_steps = int(round(t_end / dt)) + 1
    steps = np.array([1e-4 * P[S.FSCALE]] * 3 + [1e-6 / P[S.LENGTH]] * 3 + [1e-4 * P[S.FSCALE]])
    start = time.perf_counter()
    # Start the static shooting from the straight rod with the tendon taut.
    guess = np.zeros(7)
    guess[6] = P[S.FSCALE]
    x_static, its, err = S.statics(guess, P, n_points, knots[0, 1], tol, steps)
    if its < 0:
        raise RuntimeError(f"Till's scheme: static shooting failed (residual {err:.2e}, N = {n_points})")
    tip, tension, its, worst = S.march(x_static, P, n_points, dt, alpha, knots[:, 0], knots[:, 1],
                                       n_steps, tol, steps)
    wall = time.perf_counter() - start
    if its[-1] < 0:
        raise RuntimeError(f"Till's scheme: shooting failed at t = {(len(its) - 1) * dt} s "
                           f"(N = {n_points}, dt = {dt})")
    return dict(t=np.arange(len(tip)) * dt, tip=tip, tension=tension, iterations=its, worst=worst, wall=wall)


def richardson(fine, coarse, ratio, order):
    """Richardson extrapolation of a value with error ~ h^order, h_coarse = ratio h_fine."""
    return fine + (fine - coarse) / (ratio**order - 1.0)


def extrapolated(runs, grid_n, grid_dt):
    """The reference extrapolated to dt -> 0 (BDF2: order 2) at the two largest
    N, then to ds -> 0 (forward Euler: order 1); runs[(N, dt)] are tip-x arrays
    on a common time grid."""
    (dt_c, dt_f), (n_c, n_f) = grid_dt[-2:], grid_n[-2:]
    in_time = {n: richardson(runs[(n, dt_f)], runs[(n, dt_c)], dt_c / dt_f, 2) for n in (n_c, n_f)}
    return richardson(in_time[n_f], in_time[n_c], (n_f - 1) / (n_c - 1), 1)


def rodmol_tip_x(module, n, t_end, rtol=None):
    """rodmol's example at N elements: (t [s], tip x in Till's frame [m], wall time [s])."""
    with C.Stopwatch() as clock:
        result = rodmol.simulate(module.model(n), t_end, output_dt=0.05, rtol=rtol)
    assert result.success, result.message
    return result.t, result.tip[:, 1], clock.seconds  # Till's x is rodmol's global y


def rms(a, b):
    return float(np.sqrt(np.mean((np.asarray(a) - np.asarray(b)) ** 2)))


def main(argv=None):
    args = C.parse_args(__doc__.splitlines()[0], argv)
    header = C.header_lines(args, SCRIPT)
    module = example()
    t_end = C.pick(args, 25.0, 25.0, 10.5)
    grid_n = C.pick(args, [100, 200, 400, 800], [100, 200], [20, 40])
    grid_dt = C.pick(args, [0.05, 0.025, 0.0125, 0.00625, 0.003125], [0.05, 0.025, 0.0125, 0.00625],
                     [0.05, 0.025])
    t_out = np.round(np.arange(int(round(t_end / 0.05)) + 1) * 0.05, 10)
    i10 = int(round(T_HELD / 0.05))

    till_run(10, 0.05, 0.0, 0.1, module=module)  # compile (or load) the kernels outside the timings
    # Till's settings, with both time labels of his t = 10 s.
    till = till_run(200, 0.05, 0.0, t_end, module=module)
    m_cols = int(25.0 / 0.05)  # his M = T / dt columns, drawn at i T / (M - 1)
    plotted = np.interp(T_HELD, np.arange(len(till["t"])) * 25.0 / (m_cols - 1), till["tip"][:, 0])
    settings = [dict(quantity="static tip x [m]", till_cpp=module.TILL_STATIC_TIP_X,
                     reference=till["tip"][0, 0], diff_mm=1e3 * (till["tip"][0, 0] - module.TILL_STATIC_TIP_X)),
                dict(quantity="tip x, column 200 = state at t = 10.00 s [m]", till_cpp=module.TILL_HELD_TIP_X,
                     reference=till["tip"][i10, 0], diff_mm=1e3 * (till["tip"][i10, 0] - module.TILL_HELD_TIP_X)),
                dict(quantity="tip x drawn at 10 s by his plot = state at 9.98 s [m]",
                     till_cpp=module.TILL_HELD_TIP_X, reference=plotted,
                     diff_mm=1e3 * (plotted - module.TILL_HELD_TIP_X))]
    print(settings, f"wall {till['wall']:.2f} s", flush=True)

    runs, rows = {}, []
    for n in grid_n:
        for dt in grid_dt:
            r = till_run(n, dt, 0.0, t_end, module=module)
            stride = int(round(0.05 / dt))
            runs[(n, dt)] = r["tip"][::stride, 0][:len(t_out)]
            rows.append(dict(N=n, dt_s=dt, static_tip_x_m=r["tip"][0, 0], tip_x_10s_m=runs[(n, dt)][i10],
                             wall_s=r["wall"], mean_newton_its=float(np.mean(r["iterations"]))))
            print(rows[-1], flush=True)
    refined = extrapolated(runs, grid_n, grid_dt)
    coarser = extrapolated(runs, grid_n[:-1], grid_dt[:-1]) if len(grid_n) > 2 else refined * np.nan

    t_rod, x_rod, wall_rod = rodmol_tip_x(module, 50, t_end)
    # rtol 1e-8 stalls CVODE at the first motor knot (steps of 1e-6 s: with
    # Bse = 0 the axial waves the ramp's corner excites are undamped).
    n_tight = C.pick(args, 200, 100, 20)
    _, x_tight, _ = rodmol_tip_x(module, n_tight, t_end, rtol=1e-7)
    assert np.allclose(t_rod, t_out)
    x_till = till["tip"][:len(t_out), 0]
    for row in rows:
        row["rms_vs_refined_mm"] = 1e3 * rms(runs[(row["N"], row["dt_s"])], refined)
    # Observed orders from the RMS of successive differences over the whole run.
    orders = []
    for n in grid_n:
        d = [rms(runs[(n, a)], runs[(n, b)]) for a, b in zip(grid_dt, grid_dt[1:])]
        orders += [dict(refined="dt", at=f"N = {n}", step=f"{a} -> {b}", rms_change_mm=1e3 * d[k],
                        order=float(np.log2(d[k - 1] / d[k])) if k else float("nan"))
                   for k, (a, b) in enumerate(zip(grid_dt, grid_dt[1:]))]
    dt_f = grid_dt[-1]
    d = [rms(runs[(a, dt_f)], runs[(b, dt_f)]) for a, b in zip(grid_n, grid_n[1:])]
    orders += [dict(refined="N", at=f"dt = {dt_f}", step=f"{a} -> {b}", rms_change_mm=1e3 * d[k],
                    order=float(np.log2(d[k - 1] / d[k])) if k else float("nan"))
               for k, (a, b) in enumerate(zip(grid_n, grid_n[1:]))]
    compare = [dict(pair="refined reference - rodmol N = 50", at_10s_mm=1e3 * (refined[i10] - x_rod[i10]),
                    rms_mm=1e3 * rms(refined, x_rod)),
               dict(pair=f"refined reference - rodmol N = {n_tight}, rtol 1e-7",
                    at_10s_mm=1e3 * (refined[i10] - x_tight[i10]), rms_mm=1e3 * rms(refined, x_tight)),
               dict(pair="refined reference - the same from the next coarser grids",
                    at_10s_mm=1e3 * (refined[i10] - coarser[i10]), rms_mm=1e3 * rms(refined, coarser)),
               dict(pair="Till's settings - rodmol N = 50", at_10s_mm=1e3 * (x_till[i10] - x_rod[i10]),
                    rms_mm=1e3 * rms(x_till, x_rod)),
               dict(pair="Till's settings - refined reference", at_10s_mm=1e3 * (x_till[i10] - refined[i10]),
                    rms_mm=1e3 * rms(x_till, refined))]
    static_refined = richardson(rows[-1]["static_tip_x_m"], rows[-1 - len(grid_dt)]["static_tip_x_m"],
                                (grid_n[-1] - 1) / (grid_n[-2] - 1), 1)
    values = [dict(run="Till's C++ (his numbers)", static_m=module.TILL_STATIC_TIP_X,
                   at_10s_m=module.TILL_HELD_TIP_X),
              dict(run="Till's scheme at his settings", static_m=till["tip"][0, 0], at_10s_m=x_till[i10]),
              dict(run="Till's scheme refined", static_m=static_refined, at_10s_m=refined[i10]),
              dict(run="rodmol example, N = 50", static_m=x_rod[0], at_10s_m=x_rod[i10]),
              dict(run=f"rodmol N = {n_tight}, rtol 1e-7", static_m=x_tight[0], at_10s_m=x_tight[i10])]
    print(compare, values, flush=True)

    base = os.path.join(args.out, "till_reference")
    C.write_csv(base + ".csv", rows, header)
    C.write_csv(base + "_trajectories.csv",
                [dict(t_s=t, rodmol_n50_m=a, rodmol_tight_m=b, till_settings_m=c, refined_m=e)
                 for t, a, b, c, e in zip(t_out, x_rod, x_tight, x_till, refined)], header)
    plot(base + ".png", t_out, x_rod, x_till, refined, module, grid_n, grid_dt)
    fmt = {"reference": ".5f", "till_cpp": ".4f", "diff_mm": "+.2f", "static_tip_x_m": ".5f",
           "tip_x_10s_m": ".5f", "wall_s": ".1f", "mean_newton_its": ".1f", "rms_vs_refined_mm": ".3f",
           "rms_change_mm": ".4f", "order": ".2f", "at_10s_mm": "+.3f", "rms_mm": ".3f",
           "static_m": ".5f", "at_10s_m": ".5f"}
    C.write_markdown(base + ".md", "Till's tendon robot in Till's own discretisation", header, [
        ("Till's settings (N = 200, dt = 0.05 s, BDF2)", C.markdown_table(settings, None, fmt)
         + f"\nWall time {till['wall']:.1f} s for {t_end:g} s. rodmol N = 50: {wall_rod:.1f} s.\n"),
        ("Tip x (Till's frame) at t = 0 and 10 s", C.markdown_table(values, None, fmt)),
        ("Refinement (tip x in Till's frame; RMS over the run against the refined reference)",
         C.markdown_table(rows, None, fmt)),
        ("Observed orders (RMS of the change between successive runs)", C.markdown_table(orders, None, fmt)),
        (f"Comparison (refined: dt -> 0 from dt = {grid_dt[-2]}, {grid_dt[-1]}, then ds -> 0 from "
         f"N = {grid_n[-2]}, {grid_n[-1]})", C.markdown_table(compare, None, fmt)),
        ("Figure", f"![till]({os.path.basename(base)}.png)\n")])
    print("wrote", base + ".{csv,md,png}")


def plot(path, t, x_rod, x_till, refined, module, grid_n, grid_dt):
    fig, (ax, bx) = plt.subplots(2, 1, figsize=(8, 6.5), sharex=True, height_ratios=(3, 2))
    ax.plot(t, x_rod, "C0-", lw=1.4, label="rodmol example, N = 50")
    ax.plot(t, refined, "k--", lw=1.0, label=f"Till's scheme, N, dt -> 0 (N <= {grid_n[-1]})")
    ax.plot(t, x_till, "C3-", lw=1.0, label="Till's scheme, N = 200, dt = 0.05 s")
    ax.plot([0.0], [module.TILL_STATIC_TIP_X], "kx", ms=9, mew=2, label="Till's C++: static tip")
    ax.plot([T_HELD], [module.TILL_HELD_TIP_X], "k+", ms=11, mew=2, label="Till's C++: t = 10 s")
    ax.set_ylabel("tip x (Till's frame) [m]")
    ax.legend(fontsize=7.5, loc="lower center", bbox_to_anchor=(0.42, 0.02))
    ax.grid(alpha=0.3)
    bx.plot(t, 1e3 * (x_rod - refined), "C0-", lw=1.2, label="rodmol N = 50 - refined")
    bx.plot(t, 1e3 * (x_till - refined), "C3-", lw=1.0, label="Till's settings - refined")
    bx.set_ylabel("difference [mm]")
    bx.set_xlabel("t [s]")
    bx.legend(fontsize=8)
    bx.grid(alpha=0.3)
    fig.suptitle("Till's tendon robot: rodmol against Till's discretisation")
    C.save_figure(fig, path)


if __name__ == "__main__":
    main()
