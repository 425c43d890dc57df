"""What does contact between rods cost (rodmol.RodContact)?

1. A system without rod contacts is not slower than before: the two arms on
   a free head (examples/two_arms.toml, N = 8 and 10, t_end 2 s) run by
   this tree and by the tree of ``--base`` (default: where this branch left
   ``main``, ``git merge-base HEAD main``), each in its own
   worker process, alternately, and the CPU time of one right-hand side at
   the run's last state, a timed loop (target: ratio <= 1).
2. With a rod contact declared but never active (the arms stay apart): the
   two arms with ``RodContact("right", "left")`` and with
   ``RodContact("right", "right")`` (self-contact), and solvers/octopus.py's
   eight arms (N = 30, pulsing, 1 s) with each arm declared in contact with
   its neighbour, against none (target <= 1.2x).
3. A rod resting across another (examples/rods_crossing.py, N = 12 and 48
   per rod, released straight from rest to t_end): wall time,
   steps, right-hand sides, CVODE's linear iterations per nonlinear one (the
   preconditioner leaves the contact's coupling out) against the same
   system with the contact held by the lower rod's Hold at the crossing
   instead; and the share of one right-hand side spent in the contact (its
   broad and narrow phase, refreshed at every call).

Reported: medians of --reps rounds (wall and CPU time).

    python solvers/rods_touching.py [--quick | --smoke] [--out DIR] [--base=COMMIT]
"""

import json
import os
import subprocess
import sys
import time

import _common as C
from _common import np, rodmol

SCRIPT = "rods_touching.py"
TWO_ARMS = os.path.join(C.ROOT, "examples", "two_arms.toml")

# Runs in a worker process, with the tree under test first on PYTHONPATH: ``reps`` runs of the
# two arms, then the right-hand side's cost at their last state (a timed loop of ``calls``).
WORKER = """
import json, sys, time
import numpy as np
import rodmol
from rodmol.discretise.assembly import Assembly
spec = json.loads(sys.argv[1])
system = rodmol.load_scenario(spec["file"]).model
rodmol.simulate(system, 0.002)  # compiled, warm
out = []
for _ in range(spec["reps"]):
    wall, cpu = time.perf_counter(), time.process_time()
    run = rodmol.simulate(system, spec["t_end"], output_dt=0.05)
    out.append((time.perf_counter() - wall, time.process_time() - cpu, run.stats["steps"], bool(run.success)))
assembly, y = Assembly(system), np.ascontiguousarray(run.states[-1])
rates = np.empty(assembly.size)
assembly(0.0, y, rates)
cpu = time.process_time()
for _ in range(spec["calls"]):
    assembly(0.0, y, rates)
print(json.dumps([out, (time.process_time() - cpu) / spec["calls"]]))
"""


def worker(tree, t_end, reps, calls):
    """([(wall, cpu, steps, success)] of the two arms run ``reps`` times, the CPU time [s] of one
    right-hand side) by the rodmol of ``tree``."""
    env = {**os.environ, "PYTHONPATH": tree}
    spec = json.dumps({"file": TWO_ARMS, "t_end": t_end, "reps": reps, "calls": calls})
    done = subprocess.run([sys.executable, "-c", WORKER, spec], env=env, check=True, capture_output=True, text=True)
    return json.loads(done.stdout.strip().splitlines()[-1])


def before_after(args, t_end, base, calls):
    old_tree, old_sha = C.package_tree(base)
    rows = []
    samples = {"before": ([], []), "after": ([], [])}
    for _ in range(args.reps):  # alternate, so that a neighbour's load falls on both
        for label, tree in (("before", old_tree), ("after", C.ROOT)):
            runs, rhs = worker(tree, t_end, 1, calls)
            samples[label][0].extend(runs)
            samples[label][1].append(rhs)
    for label, (runs, rhs) in samples.items():
        rows.append(dict(case=f"two arms, no rod contact ({label}: {old_sha[:8] if label == 'before' else 'this tree'})",
                         wall_s=float(np.median([r[0] for r in runs])), cpu_s=float(np.median([r[1] for r in runs])),
                         steps=runs[-1][2], success=all(r[3] for r in runs), rhs_us=1e6 * float(np.median(rhs))))
    for row in rows:
        row["ratio"] = row["cpu_s"] / rows[0]["cpu_s"]
        row["rhs_ratio"] = row["rhs_us"] / rows[0]["rhs_us"]
    return rows


def declared(args, t_end, octopus_n, octopus_t):
    import octopus as O

    two = rodmol.load_scenario(TWO_ARMS).model
    eight = O.octopus(octopus_n, O.pulsing)
    neighbours = [rodmol.RodContact(f"arm{i + 1}", f"arm{(i + 1) % O.ARMS + 1}") for i in range(O.ARMS)]
    cases = {"two arms: none": (two, [], t_end), "two arms: right-left": (two, [rodmol.RodContact("right", "left")], t_end),
             "two arms: right-right (self)": (two, [rodmol.RodContact("right", "right")], t_end),
             f"octopus N={octopus_n}: none": (eight, [], octopus_t),
             f"octopus N={octopus_n}: each arm with its neighbours": (eight, neighbours, octopus_t)}
    rows, first = [], None
    for name, (base, contacts, t_end) in cases.items():
        if contacts == []:
            first = None
        system = base.replace(contacts=list(base.contacts) + contacts)
        rodmol.simulate(system, 0.002)
        walls, cpus = [], []
        for _ in range(args.reps):
            wall, cpu = time.perf_counter(), time.process_time()
            run = rodmol.simulate(system, t_end, output_dt=0.05)
            walls.append(time.perf_counter() - wall)
            cpus.append(time.process_time() - cpu)
        row = dict(case=f"declared, {name}", wall_s=float(np.median(walls)), cpu_s=float(np.median(cpus)),
                   steps=run.stats["steps"], success=run.success,
                   least_gap_mm=1e3 * run.stats.get("rod_contact_least_gap", np.inf),
                   pairs=run.stats.get("rod_contact_pairs", 0))
        first = first or row
        row["ratio"] = row["cpu_s"] / first["cpu_s"]
        rows.append(row)
    return rows


def crossing(n, held=False):
    """examples/rods_crossing.py's crossing at ``n`` elements per rod; ``held``: the upper rod
    pinned where it crosses instead of the contact (a reference of the same stiffness scale)."""
    sys.path.append(os.path.join(C.ROOT, "examples"))  # last: solvers/ holds namesakes (octopus.py)
    import rods_crossing as X

    system = X.crossing(n)
    if held:
        s = round(X.CROSS / (X.L / n)) * X.L / n
        return system.replace(contacts=[], joints=list(system.joints) + [rodmol.Joint(("upper", s), "world",
                                                                                        kind="pin")])
    return system


def rhs_share(system, y, calls):
    """(one right-hand side [us], the contact's share of it) at ``y``."""
    from rodmol.discretise.assembly import Assembly

    assembly = Assembly(system)
    out = np.empty(assembly.size)
    assembly(0.0, y, out)
    start = time.perf_counter()
    for _ in range(calls):
        assembly(0.0, y, out)
    whole = (time.perf_counter() - start) / calls
    start = time.perf_counter()
    for _ in range(calls):
        assembly.rod_pairs.apply(y)
    return 1e6 * whole, (time.perf_counter() - start) / calls / whole


def resting(args, sizes, t_end, calls):
    rows = []
    for n in sizes:
        for label, held in (("contact", False), ("pinned instead", True)):
            system = crossing(n, held)
            rodmol.simulate(system, 0.002)
            walls = []
            for _ in range(args.reps):
                wall = time.perf_counter()
                run = rodmol.simulate(system, t_end, output_times=[0.0, t_end])
                walls.append(time.perf_counter() - wall)
            stats = run.stats
            row = dict(case=f"crossing N={n}: {label}", wall_s=float(np.median(walls)), steps=stats["steps"],
                       rhs_evals=stats["rhs_evals"], prec_solves_per_step=stats["prec_solves"] / stats["steps"],
                       success=run.success)
            if not held:
                row["rhs_us"], row["contact_share"] = rhs_share(system, run.states[-1], calls)
                row["least_gap_um"] = 1e6 * stats["rod_contact_least_gap"]
            rows.append(row)
            print(row, flush=True)
    return rows


def main(argv=None):
    argv = sys.argv[1:] if argv is None else argv
    base = next((a.split("=", 1)[1] for a in argv if a.startswith("--base=")), None)
    if base is None:  # where this branch left main: the same code but for its own changes
        base = subprocess.run(["git", "-C", C.ROOT, "merge-base", "HEAD", "main"], check=True, capture_output=True,
                              text=True).stdout.strip()
    args = C.parse_args(__doc__.splitlines()[0], [a for a in argv if not a.startswith("--base=")])
    header = C.header_lines(args, SCRIPT)
    t_end = C.pick(args, 2.0, 0.5, 0.05)
    first = before_after(args, t_end, base, C.pick(args, 20000, 5000, 100))
    print(first, flush=True)
    second = declared(args, t_end, C.pick(args, 30, 30, 8), C.pick(args, 1.0, 0.3, 0.05))
    print(second, flush=True)
    third = resting(args, C.pick(args, [12, 48], [12, 24], [12]), C.pick(args, 1.0, 0.5, 0.1), C.pick(args, 2000, 500, 20))
    fmt = {"wall_s": ".3g", "cpu_s": ".3g", "ratio": ".3f", "rhs_ratio": ".3f", "prec_solves_per_step": ".2f", "rhs_us": ".0f",
           "contact_share": ".2f", "least_gap_mm": ".3g", "least_gap_um": ".3g"}
    rows = first + second + third
    C.write_results(args, "rods_touching", "Contact between rods: cost", header, rows,
                    [("Without rod contacts, before and after", C.markdown_table(first, None, fmt)),
                     ("Declared but never active", C.markdown_table(second, None, fmt)),
                     ("A rod resting across another", C.markdown_table(third, None, fmt))])


if __name__ == "__main__":
    main()
