"""What does an octopus cost? Eight of the paper's arms on a free head in
water against one arm alone, at the same N and settings.

The head is a sphere (radius 5 cm, 10% heavier than the water it displaces,
with the added mass and drag of a sphere); the arms leave it radially in the
horizontal plane, tilted 30 degrees down, and each pulls one cable
(alternately cable 1 and cable 3) with one of two patterns: ``ramp``, a 0.2
s ramp to 1 N then held (the arms come to rest while the head sinks), and
``pulsing``, 1 N (1 - cos(2 pi f t + phase)) / 2 at f = 2 Hz with the arms'
phases spread over a period (every arm keeps moving). The single arm is
``paper_arm`` under the same cable input (phase 0), clamped to the world, run as a
Model (CVODE's own choice of linear solver) and as a one-rod System; the
octopus with both linear solvers of systems (the preconditioned GMRES, the
default, and the sparse LU); all from the straight rest state. Reported: wall
time, simulated seconds per wall second, right-hand side evaluations, and
the ratio of the octopus's wall time to one arm's (medians of --reps rounds,
each round running every case once), and the same for the process's CPU
time (``time.process_time``: on the shared machine, a neighbour's load
stretches the wall time of a long case more than that of a short one).

    python solvers/octopus.py [--quick | --smoke] [--out DIR]
"""

import time

import _common as C
from _common import np, rodmol

SCRIPT = "octopus.py"
HEAD_RADIUS = 0.05  # m
ARMS = 8
WATER = dict(medium="water", gravity=(0.0, 0.0, -9.81))  # the octopus's medium and gravity


PULSE_HZ = 2.0


def ramp(phase):
    return lambda t: min(t / 0.2, 1.0)


def pulsing(phase):
    return lambda t: 0.5 * (1.0 - np.cos(2.0 * np.pi * PULSE_HZ * t + phase))


PATTERNS = {"ramp": ramp, "pulsing": pulsing}


def arm(n, cable, tension):
    return rodmol.paper_arm(n, tensions={cable: tension}, markers=())


def head(motion="free"):
    water = rodmol.MEDIA["water"].rho
    volume = 4.0 / 3.0 * np.pi * HEAD_RADIUS**3
    mass = 1.1 * water * volume
    inertia = 0.4 * mass * HEAD_RADIUS**2
    added = 0.5 * water * volume  # a sphere's added mass
    drag = 0.5 * water * 0.47 * np.pi * HEAD_RADIUS**2  # C_d = 0.47
    return rodmol.RigidBody(mass, (inertia,) * 3, volume=volume, added_mass=(added,) * 3 + (0.0,) * 3,
                            drag=(drag,) * 3 + (1e-4,) * 3, motion=motion)


def octopus(n, pattern, arms=ARMS, motion="free", tilt=30.0):
    """``arms`` arms spread evenly round the head (``motion``: free, or fixed for a study), their
    phases spread over a period, leaving it ``tilt`` degrees below the horizontal."""
    rods, joints = {}, []
    tilt = np.radians(tilt)
    for i in range(arms):
        angle = 2.0 * np.pi * i / arms
        out = np.array([np.cos(angle) * np.cos(tilt), np.sin(angle) * np.cos(tilt), -np.sin(tilt)])
        side = np.array([-np.sin(angle), np.cos(angle), 0.0])
        frame = np.column_stack([out, side, np.cross(out, side)])  # the arm's base frame in the head's
        rods[f"arm{i + 1}"] = arm(n, 1 if i % 2 == 0 else 3, pattern(2.0 * np.pi * i / arms))
        joints.append(rodmol.Joint(("head", HEAD_RADIUS * out, frame), (f"arm{i + 1}", "base")))
    return rodmol.System(rods, {"head": head(motion)}, joints, **WATER)


def timed(cases, t_end, reps):
    """Rows of the ``cases`` (label, model or system, simulate options): median
    wall times [s] of ``reps`` rounds, each round running every case once (so
    that a change of the shared machine's load falls on all of them); and the
    last case's last result."""
    walls = {label: [] for label, _, _ in cases}
    cpus = {label: [] for label, _, _ in cases}
    for _ in range(reps):
        for label, thing, options in cases:
            start, cpu = time.perf_counter(), time.process_time()
            rodmol.simulate(thing, t_end, **options)
            walls[label].append(time.perf_counter() - start)
            cpus[label].append(time.process_time() - cpu)
    rows = []
    for label, thing, options in cases:
        result = rodmol.simulate(thing, t_end, **options)  # for its statistics
        wall = float(np.median(walls[label]))
        rows.append(dict(case=label, state_size=result.states.shape[1], t_end_s=t_end, wall_s=wall,
                         sim_s_per_wall_s=t_end / wall, cpu_s=float(np.median(cpus[label])),
                         rhs_evals=result.stats["rhs_evals"], success=result.success))
    return rows, result


def settings(args):
    """The arms' N and the simulated time [s] of the run mode, after warming up the kernels
    (they compile on first use; every case runs warm)."""
    n = C.pick(args, 30, 30, 8)
    rodmol.simulate(rodmol.System({"a": arm(n, 1, ramp(0.0))}, **WATER), 0.01)
    rodmol.simulate(arm(n, 1, ramp(0.0)), 0.01, initial="straight")
    return n, C.pick(args, 1.0, 0.3, 0.05)


def main(argv=None):
    args = C.parse_args(__doc__.splitlines()[0], argv)
    header = C.header_lines(args, SCRIPT)
    n, t_end = settings(args)
    water = WATER
    rows, notes = [], ""
    for name, pattern in PATTERNS.items():
        single = arm(n, 1, pattern(0.0)).replace(gravity=water["gravity"])
        cases = [("one arm, Model", single, dict(initial="straight")),
                 ("one arm, System", rodmol.System({"a": arm(n, 1, pattern(0.0))}, **water), {}),
                 (f"octopus, {ARMS} arms + head, sparse LU", octopus(n, pattern), dict(linsolver="sparse")),
                 (f"octopus, {ARMS} arms + head, GMRES", octopus(n, pattern), {})]
        timed_rows, result = timed(cases, t_end, args.reps)
        for row in timed_rows:
            row = dict(pattern=name, **row, N=n, wall_vs_one_arm_model=row["wall_s"] / timed_rows[0]["wall_s"],
                       cpu_vs_one_arm_model=row["cpu_s"] / timed_rows[0]["cpu_s"])
            rows.append(row)
            print(row, flush=True)
        drift = max(float(np.max(result.pose_drift(rod)[0])) for rod in result.assembly.rods)
        notes += (f"- {name}: head at t_end {np.round(result['head'].position[-1], 4).tolist()} m, "
                  f"largest header-to-clamp drift of the arms {drift:.2e} m.\n")
    fmt = {"wall_s": ".3g", "sim_s_per_wall_s": ".3g", "wall_vs_one_arm_model": ".2f", "t_end_s": ".3g",
           "cpu_s": ".3g", "cpu_vs_one_arm_model": ".2f"}
    C.write_results(args, "octopus", "Octopus: eight arms on a free head against one arm", header, rows,
                    [("Results", C.markdown_table(rows, None, fmt)), ("Notes", notes)])


if __name__ == "__main__":
    main()
