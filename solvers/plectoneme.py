"""The plectoneme (examples/plectoneme.py, PyElastica's PlectonemesCase): how
far rodmol gets in the 100 s, at what cost, with what link and overlap.

One run per grid (N elements) of the example (10 turns over 50 s, then 50 s
held), capped at --wall seconds of wall time (the run stops there and the
table says where). Reported per run: the time reached, steps, right-hand
sides, wall and CPU time, steps per simulated second, the least surface gap
(negative: overlap) and the largest |Lk - turns applied| over the frames
(rodmol.analysis.link); per frame, the link, twist, writhe, gap and turns
applied. PyElastica's own run (the issue's author's, on this machine; not
run here): 6 million steps of 0.0025 L / n for the 100 s, t = 41 s in 44
min (938 steps/s slowing to about 760: about 2 hours in all), its link 0.90
of the turns applied, 632 element pairs overlapping by up to 3.2 mm at t =
41 s.

    python solvers/plectoneme.py [--quick | --smoke] [--out DIR] [--wall SECONDS]
"""

import os
import sys
import time

import _common as C
from _common import np, rodmol

SCRIPT = "plectoneme.py"


def example():
    """examples/plectoneme.py as a module (this script has its name)."""
    import importlib.util

    spec = importlib.util.spec_from_file_location("plectoneme_example",
                                                  os.path.join(C.ROOT, "examples", "plectoneme.py"))
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def run(P, n, t_end, turns, wall, output_dt):
    system = P.plectoneme(n, turns)
    rodmol.simulate(system, 1e-3)  # compiled, warm
    start, cpu = time.perf_counter(), time.process_time()
    result = rodmol.simulate(system, t_end, output_dt=output_dt, max_wall_time=wall)
    wall_s, cpu_s = time.perf_counter() - start, time.process_time() - cpu
    lk, tw, wr, worst = P.link_error(result, turns)
    _, gap, pairs = result.rod_contacts()
    applied = P.turned(result.t, turns)
    stats = result.stats
    row = dict(n=n, turns=turns, t_end=t_end, reached_s=float(result.t[-1]), success=bool(result.success),
               steps=stats["steps"], rhs_evals=stats["rhs_evals"], wall_s=wall_s, cpu_s=cpu_s,
               steps_per_sim_s=stats["steps"] / max(float(result.t[-1]), 1e-12),
               least_gap_mm=1e3 * float(np.min(gap)), least_gap_r=float(np.min(gap)) / P.R,
               most_pairs=int(np.max(pairs)),
               link_error_turns=float(np.max(np.abs(lk - applied))), link_error_rel=worst,
               stopped=("" if result.success else result.message.split(":")[0][:120]))
    frames = [dict(n=n, t=float(t), applied=float(a), link=float(x), twist=float(y), writhe=float(z),
                   gap_mm=1e3 * float(g), pairs=int(p))
              for t, a, x, y, z, g, p in zip(result.t, applied, lk, tw, wr, gap, pairs)]
    return row, frames


def main(argv=None):
    argv = sys.argv[1:] if argv is None else argv
    wall = next((float(a.split("=", 1)[1]) for a in argv if a.startswith("--wall=")), None)
    args = C.parse_args(__doc__.splitlines()[0], [a for a in argv if not a.startswith("--wall=")])
    header = C.header_lines(args, SCRIPT)
    P = example()
    sizes = C.pick(args, [60, 150], [60], [20])
    t_end = C.pick(args, P.T_TWIST + P.T_HOLD, P.T_TWIST + P.T_HOLD, 2.0)
    wall = wall or C.pick(args, 300.0, 120.0, 60.0)
    rows, frames = [], []
    for n in sizes:
        row, per_frame = run(P, n, t_end, P.TURNS, wall, C.pick(args, 1.0, 1.0, 0.5))
        print(row, flush=True)
        rows.append(row)
        frames += per_frame
    pyelastica = dict(n=150, turns=10, t_end=100.0, reached_s=41.0, steps="6.0e6 (100 s)", wall_s=44 * 60.0,
                      steps_per_sim_s=60000.0, least_gap_mm=-3.2, most_pairs=632, link_error_rel=0.10,
                      stopped="PyElastica, the issue's author's run on this machine (quoted, not run here)")
    fmt = {"wall_s": ".3g", "cpu_s": ".3g", "steps_per_sim_s": ".3g", "least_gap_mm": ".3g", "least_gap_r": ".3f",
           "link_error_turns": ".2e", "link_error_rel": ".2e", "reached_s": ".4g"}
    every = [f for f in frames if abs(f["t"] - round(f["t"] / 5) * 5) < 1e-9]
    C.write_results(args, "plectoneme", "The plectoneme: steps, time, link and overlap", header, rows + frames,
                    [("Runs", C.markdown_table(rows + [pyelastica], None, fmt)),
                     ("Link against the turns applied (every 5 s)",
                      C.markdown_table(every, None, {"link": ".4f", "twist": ".4f", "writhe": ".4f", "applied": ".4f",
                                                     "gap_mm": ".3g"}))])


if __name__ == "__main__":
    main()
