"""The static equilibrium of a system with a free body: the coupled Jacobian
sparse (SuperLU) against dense (LAPACK's LU), side by side in one run.

The system: the octopus of ``octopus.py`` (eight of the paper's arms at N on
a free head in water) hung upside down: its arms rise 30 degrees from the
head and their tips are clamped to the world where they are at rest, so the
head hangs from them (an octopus lying on its arms, ``octopus.py``'s pose,
has no equilibrium this solver finds from the straight rods: the soft arms
buckle under the head). :func:`rodmol.solve.system_equilibrium.free_rest_state`
solves the arms and the head's pose together; its Jacobian by
``CoupledDifferences`` either as a sparse matrix (the default) or dense.
Reported per N and path: wall and CPU time (medians of --reps interleaved
rounds), the peak of Python's allocations (``tracemalloc``, in a separate
untimed run: it slows allocation), the number of unknowns, and the largest
difference of the two paths' states over each entry's scale.

    python solvers/system_equilibrium_speed.py [--quick | --smoke] [--out DIR] [--reps K]
"""

import time
import tracemalloc

import _common as C
import octopus as O
from _common import np, rodmol

from rodmol.discretise.assembly import Assembly
from rodmol.solve import system_equilibrium

SCRIPT = "system_equilibrium_speed.py"


def hanging_octopus(n):
    """The octopus hung from its arms' tips (see the module's docstring)."""
    system = O.octopus(n, O.ramp, tilt=-30.0)
    joints = list(system.joints) + [rodmol.Joint("world", (name, "tip")) for name in system.rods]
    return rodmol.System(system.rods, system.bodies, joints, medium="water", gravity=(0.0, 0.0, -9.81))


def solve(assembly, dense):
    """The rest state with the dense or the sparse Jacobian; (state, wall [s], CPU [s])."""
    original = system_equilibrium.CoupledDifferences
    system_equilibrium.CoupledDifferences = lambda equations: original(equations, dense=dense)
    try:
        wall, cpu = time.perf_counter(), time.process_time()
        y = system_equilibrium.free_rest_state(assembly, 0.0, 1e-10, 40)
        return y, time.perf_counter() - wall, time.process_time() - cpu
    finally:
        system_equilibrium.CoupledDifferences = original


def peak_memory(assembly, dense):
    """Peak of Python's allocations [B] during one solve."""
    tracemalloc.start()
    try:
        solve(assembly, dense)
        return tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()


def main(argv=None):
    args = C.parse_args(__doc__.splitlines()[0], argv)
    header = C.header_lines(args, SCRIPT)
    sizes = C.pick(args, (8, 16, 30), (8, 16), (4,))
    if not args.smoke:  # compile (the smoke run times nothing it checks)
        solve(Assembly(hanging_octopus(sizes[0])), False)
    rows = []
    for n in sizes:
        assembly = Assembly(hanging_octopus(n))
        unknowns = system_equilibrium.FreeRestEquations(assembly, 0.0).size
        times = {True: [], False: []}
        states = {}
        for _ in range(args.reps):
            for dense in (False, True):
                states[dense], wall, cpu = solve(assembly, dense)
                times[dense].append((wall, cpu))
        scale = assembly.atol_scale()
        difference = float(np.max(np.abs(states[True] - states[False]) / scale))
        head = states[False][assembly.bodies["head"].fields["x"]]
        for dense in (False, True):
            wall, cpu = np.median(np.array(times[dense]), axis=0)
            rows.append(dict(N=n, unknowns=unknowns, jacobian="dense" if dense else "sparse", wall_s=wall,
                             cpu_s=cpu, peak_MB=peak_memory(assembly, dense) / 1e6,
                             max_difference_over_scale=difference, head_z_m=float(head[2])))
            print(rows[-1], flush=True)
    for row in rows:
        dense = next(r for r in rows if r["N"] == row["N"] and r["jacobian"] == "dense")
        row["wall_vs_dense"] = row["wall_s"] / dense["wall_s"]
        row["peak_vs_dense"] = row["peak_MB"] / dense["peak_MB"]
    fmt = {"wall_s": ".3g", "cpu_s": ".3g", "peak_MB": ".3g", "max_difference_over_scale": ".2g",
           "head_z_m": ".6g", "wall_vs_dense": ".2f", "peak_vs_dense": ".3f"}
    C.write_results(args, "system_equilibrium_speed", "System equilibrium: sparse against dense Jacobian",
                    header + [f"medians of {args.reps} interleaved rounds; peak memory in a separate run"],
                    rows, [("Results", C.markdown_table(rows, None, fmt))])


if __name__ == "__main__":
    main()
