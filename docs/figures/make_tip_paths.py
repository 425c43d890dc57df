"""Tip paths of the paper's three tests (bending, reaching, fetching) at N = 100.

Runs each scenario of :mod:`rodmol.scenarios` with the CVODE backend from the
gravity equilibrium, prints a table (wall time, solver steps, tip position at
the end) and writes ``tip_path_<name>.png`` next to this script: the tip
path in the x-y plane (and the x-z plane when the run leaves it), coloured
by time, with the centreline at a few instants, and below it the tip
coordinates and the cable tensions against time.

Two tips are drawn: ``Result.tip``, rebuilt from the strains (what rodmol
outputs), and the time-integrated tip u(L) (u_t = R v,
``Result.integrated_positions``). The paper's upwind scheme does not keep
u' = R q exactly, so the integrated tip drifts from the shape by O(ds) per
unit time; the gap is drawn so that it can be judged.

Usage::

    python docs/figures/make_tip_paths.py [--n-elements 100] [--out DIR]
"""

import argparse
import os
import time

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import rodmol  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))


def plot(name, result, integrated_tip, path):
    """Tip path in the x-y (and, for a 3-D run, x-z) plane, and the tip and tensions vs time."""
    t, tip = result.t, result.tip
    three_d = np.abs(tip[:, 2]).max() > 1e-3
    fig = plt.figure(figsize=(11, 8.5) if three_d else (8.5, 8.5), constrained_layout=True)
    grid = fig.add_gridspec(2, 2 if three_d else 1, height_ratios=(1.6, 1.0))
    path_axes = [fig.add_subplot(grid[0, 0])] + ([fig.add_subplot(grid[0, 1])] if three_d else [])
    snapshots = np.linspace(0, len(t) - 1, 7).astype(int)
    for ax, (j, label) in zip(path_axes, ((1, "y"), (2, "z"))):
        for n, i in enumerate(snapshots):
            ax.plot(result.positions[i, :, 0], result.positions[i, :, j], color="0.75", lw=1.0,
                    zorder=1, label="centreline at 7 instants" if n == 0 else None)
        ax.plot(integrated_tip[:, 0], integrated_tip[:, j], "--", color="tab:red", lw=1.0, zorder=2,
                label="time-integrated tip u(L)")
        sc = ax.scatter(tip[:, 0], tip[:, j], c=t, s=4, cmap="viridis", zorder=3,
                        label="tip (Result.tip, from the strains)")
        ax.plot(*tip[0, [0, j]], "ko", ms=6, zorder=4, label="t = 0 (equilibrium)")
        ax.plot(*tip[-1, [0, j]], "ks", ms=7, mfc="none", zorder=4, label=f"t = {t[-1]:g} s")
        ax.plot(0.0, 0.0, "k^", ms=8, zorder=4, label="base")
        ax.set_xlabel("x [m] (global)")
        ax.set_ylabel(f"{label} [m] (global)")
        ax.set_aspect("equal", adjustable="datalim")
        ax.grid(True, lw=0.3)
        ax.set_title(f"tip path, x-{label} projection")
    path_axes[0].legend(loc="best", fontsize=7)
    fig.colorbar(sc, ax=path_axes, label="t [s]", shrink=0.8)

    ax = fig.add_subplot(grid[1, :])
    for j, (label, color) in enumerate(zip("xyz", ("tab:blue", "tab:orange", "tab:green"))):
        ax.plot(t, tip[:, j], color=color, label=f"tip {label} (Result.tip)")
        ax.plot(t, integrated_tip[:, j], "--", color=color, lw=0.9, label=f"tip {label} integrated")
    ax.set_xlabel("t [s]")
    ax.set_ylabel("tip position [m] (global)")
    ax.grid(True, lw=0.3)
    ax.legend(loc="upper left", fontsize=7, ncol=3)
    twin = ax.twinx()
    names = [c["name"] for c in result.meta["cables"]]
    for i in np.flatnonzero(np.any(result.tensions > 0, axis=0)):
        twin.plot(t, result.tensions[:, i], ":", color="k", lw=1.2)
        k = int(np.argmax(result.tensions[:, i]))
        twin.annotate(names[i], (t[k], result.tensions[k, i]), fontsize=7,
                      textcoords="offset points", xytext=(2, 3))
    twin.set_ylabel("cable tension [N] (dotted)")
    twin.set_ylim(0, 1.3 * max(result.tensions.max(), 1e-9))
    fig.suptitle(f"{name} test, N = {result.meta['n_elements']}, CVODE")
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n-elements", type=int, default=100)
    parser.add_argument("--out", default=HERE)
    args = parser.parse_args()

    rows = []
    for name in ("bending", "reaching", "fetching"):
        scenario = rodmol.scenarios.get(name)
        model = scenario.model(args.n_elements)
        start = time.perf_counter()
        result = rodmol.simulate(model, scenario.t_end, backend="cvode", output_dt=0.01)
        wall = time.perf_counter() - start
        if not result.success:
            raise SystemExit(f"{name}: {result.message}")
        integrated_tip = result.integrated_positions[:, -1]
        path = os.path.join(args.out, f"tip_path_{name}.png")
        plot(name, result, integrated_tip, path)
        gap = np.max(np.linalg.norm(result.tip - integrated_tip, axis=1))
        rows.append((name, scenario.t_end, wall, result.stats["wall_time_s"], result.stats["steps"],
                     result.tip[-1], integrated_tip[-1], gap))
        print(f"wrote {path}", flush=True)

    print()
    print(f"N = {args.n_elements}, backend cvode, default rtol; wall time includes the initial equilibrium")
    print("| test | t_end [s] | wall [s] | solver wall [s] | steps | tip at end, Result.tip [m] "
          "| integrated tip at end [m] | max gap [m] |")
    print("|---|---|---|---|---|---|---|---|")
    for name, t_end, wall, solver_wall, steps, tip, stip, gap in rows:
        fmt = lambda v: "(" + ", ".join(f"{x:+.4f}" for x in v) + ")"  # noqa: E731
        print(f"| {name} | {t_end:g} | {wall:.1f} | {solver_wall:.1f} | {steps} | {fmt(tip)} "
              f"| {fmt(stip)} | {gap:.4f} |")


if __name__ == "__main__":
    main()
