"""What does a rod touching a body cost? A ball resting on a beam clamped at
both ends (rodmol.Contact: the ball's sphere touched by the beam), against
the same system with the ball's shape left out.

Per N: the right-hand side's cost with and without the contact (median of
--reps rounds of timed loops at the ball-on-beam state), the cost per
touched node (the contact is one part per velocity node, called from
Python), and a run from rest to t_end on CVODE GMRES (the ball eliminated
by its Schur complement with the touched nodes) and sparse LU: wall time,
right-hand sides, and the beam's contact force on the ball at the end
against its weight.

    python solvers/rod_contact.py [--quick | --smoke] [--out DIR]
"""

import time

import _common as C
from _common import np, rodmol

from rodmol.discretise.assembly import Assembly
from rodmol.discretise.contact_parts import ContactPart
from rodmol.discretise.rotations import matrices

SCRIPT = "rod_contact.py"
MATERIAL = rodmol.Material(E=1e6, nu=0.5, mu=5e3, rho=1000.0)
L, RADIUS, BALL_R, BALL_M, G = 0.2, 0.01, 0.03, 0.02, 9.81


def system(n, touched=True):
    """The beam of ``n`` elements and the ball between the two nodes next to midspan."""
    beam = rodmol.Model(rodmol.Rod(L, radius=RADIUS, material=MATERIAL), n)
    ball = rodmol.RigidBody(BALL_M, (0.4 * BALL_M * BALL_R**2,) * 3, position=(L / 2 + L / n / 2, RADIUS + BALL_R, 0.0))
    shape = rodmol.SphereContact((0.0, 0.0, 0.0), BALL_R, stiffness=2e3, damping=100.0)
    contacts = [rodmol.Contact("ball", "beam", shape)] if touched else []
    return rodmol.System({"beam": beam}, {"ball": ball}, [rodmol.Joint(("beam", "tip"), "world")],
                         contacts=contacts, gravity=(0.0, -G, 0.0))


def rhs_cost(assembly, y, calls):
    """Wall time [s] per call of ``calls`` right-hand sides at ``y``."""
    out = np.empty(assembly.size)
    assembly(0.0, y, out)
    start = time.perf_counter()
    for _ in range(calls):
        assembly(0.0, y, out)
    return (time.perf_counter() - start) / calls


def force_on_ball(assembly, y):
    """The beam's contact force on the ball [N], global, at ``y``."""
    part = assembly.bodies["ball"]
    body = assembly.body_state(part, 0.0, y)
    total = sum(np.array(j.wrench(y, body, j.row.copy(), j.value.copy())[0])
                for j in part.joints if isinstance(j, ContactPart))
    return matrices(body[3:7]) @ total


def main(argv=None):
    args = C.parse_args(__doc__.splitlines()[0], argv)
    header = C.header_lines(args, SCRIPT)
    sizes = C.pick(args, [10, 40, 100], [10, 40], [6])
    t_end = C.pick(args, 1.5, 0.5, 0.5)
    calls = C.pick(args, 2000, 500, 20)
    rows = []
    for n in sizes:
        touched, plain = Assembly(system(n)), Assembly(system(n, touched=False))
        for linsolver in ("gmres", "sparse"):
            rodmol.simulate(system(n), 0.002, linsolver=linsolver)  # compiled, warm
            walls = []
            for _ in range(args.reps):
                start = time.perf_counter()
                run = rodmol.simulate(system(n), t_end, output_times=[0.0, t_end], linsolver=linsolver)
                walls.append(time.perf_counter() - start)
            y = run.states[-1]
            with_s = float(np.median([rhs_cost(touched, y, calls) for _ in range(args.reps)]))
            without_s = float(np.median([rhs_cost(plain, y, calls) for _ in range(args.reps)]))
            rows.append(dict(N=n, linsolver=linsolver, t_end_s=t_end, wall_s=float(np.median(walls)),
                             rhs_evals=run.stats["rhs_evals"], rhs_us=1e6 * with_s, rhs_without_us=1e6 * without_s,
                             rhs_ratio=with_s / without_s, us_per_node=1e6 * (with_s - without_s) / n,
                             force_over_weight=float(force_on_ball(touched, y)[1] / (BALL_M * G)),
                             success=run.success))
            print(rows[-1], flush=True)
    fmt = {"wall_s": ".3g", "t_end_s": ".3g", "rhs_us": ".0f", "rhs_without_us": ".0f", "rhs_ratio": ".2f",
           "us_per_node": ".2f", "force_over_weight": ".5f"}
    C.write_results(args, "rod_contact", "Rods touching a body: a ball on a clamped beam", header, rows,
                    [("Results", C.markdown_table(rows, None, fmt))])


if __name__ == "__main__":
    main()
