"""What does a body's contact cost? The octopus of examples/octopus.py with
its head touching the sea floor too, against the example as it is.

Cases, all from the straight rest state at the example's N and settings,
through the settling and two crawl cycles: the example (the head held above
the floor by its arms); the same with the head given the floor as a contact
(one point at its centre, a sphere of its radius: above the floor at rest,
so this is mostly the cost of evaluating the law; at N = 30 it touches in
passing while settling); and the arms tilted 4 degrees
instead of 8 below the horizontal, so that the head comes to rest on the
floor before the arms' tips reach it. Reported: wall time (median of --reps
rounds, each round running every case once), right-hand sides, the ratio
to the example's wall time, the head's lowest point above the floor at the
end of the settling, and the floor's force on the head there against the
octopus's weight less buoyancy.

    python solvers/body_contact.py [--quick | --smoke] [--out DIR]
"""

import dataclasses
import importlib.util
import os
import time

import _common as C
from _common import np, rodmol

from rodmol.discretise.assembly import Assembly
from rodmol.discretise.body_contact import BodyContacts

SCRIPT = "body_contact.py"
EXAMPLE = os.path.join(os.path.dirname(C.HERE), "examples", "octopus.py")


def example():
    """examples/octopus.py as a module."""
    spec = importlib.util.spec_from_file_location("octopus_example", EXAMPLE)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def with_head_contact(octopus, n, tilt_deg):
    """The example's system at ``n`` with its arms ``tilt_deg`` below the
    horizontal and the head on the floor (its law per point: 2e4 N/m, about
    critical damping for the head and its added mass, the arms' friction)."""
    plain_head, plain_tilt = octopus.head, octopus.TILT
    floor = rodmol.PlaneContact((0.0, 0.0, octopus.FLOOR), (0.0, 0.0, 1.0), stiffness=2e4, damping=250.0,
                                friction=0.6, slip_speed=2e-3, name="floor")
    octopus.head = lambda: dataclasses.replace(plain_head(), contacts=(floor,), contact_points=[(0.0, 0.0, 0.0)],
                                               contact_radius=octopus.HEAD_RADIUS)
    octopus.TILT = np.radians(tilt_deg)
    try:
        return octopus.octopus(n)
    finally:
        octopus.head, octopus.TILT = plain_head, plain_tilt


def main(argv=None):
    args = C.parse_args(__doc__.splitlines()[0], argv)
    header = C.header_lines(args, SCRIPT)
    octopus = example()
    n = C.pick(args, 30, 10, 4)
    settle = C.pick(args, octopus.SETTLE, 2.0, 0.02)
    t_end = settle + C.pick(args, 2 * octopus.PERIOD, 2 * octopus.PERIOD, 0.01)
    cases = [("example (head above the floor)", octopus.octopus(n)),
             ("head with the floor, above it at rest", with_head_contact(octopus, n, np.degrees(octopus.TILT))),
             ("arms tilted 4 deg, head on the floor", with_head_contact(octopus, n, 4.0))]
    for _, system in cases[:2]:  # the kernels compile on first use; every case below runs warm
        rodmol.simulate(system, 0.01)
    walls, results = {label: [] for label, _ in cases}, {}
    times = np.array([0.0, settle, t_end])
    for _ in range(args.reps):
        for label, system in cases:
            start = time.perf_counter()
            results[label] = rodmol.simulate(system, t_end, output_times=times)
            walls[label].append(time.perf_counter() - start)
    rows = []
    for label, system in cases:
        result, wall = results[label], float(np.median(walls[label]))
        head = system.bodies["head"]
        rest = result.states[1, Assembly(system).bodies["head"].slice]
        on_head = BodyContacts(head).forces(rest).sum(axis=0)[2] if head.contacts else 0.0
        rows.append(dict(case=label, N=n, t_end_s=t_end, wall_s=wall, rhs_evals=result.stats["rhs_evals"],
                         wall_vs_example=wall / float(np.median(walls[cases[0][0]])),
                         head_gap_at_rest_mm=float(1e3 * (rest[2] - octopus.HEAD_RADIUS - octopus.FLOOR)),
                         floor_on_head_at_rest_N=float(on_head), net_weight_N=float(octopus.net_weight(system)),
                         success=result.success))
        print(rows[-1], flush=True)
    fmt = {"wall_s": ".3g", "wall_vs_example": ".2f", "t_end_s": ".3g", "head_gap_at_rest_mm": ".3f",
           "floor_on_head_at_rest_N": ".4f", "net_weight_N": ".4f"}
    C.write_results(args, "body_contact", "Body contact: the octopus's head on the sea floor", header, rows,
                    [("Results", C.markdown_table(rows, None, fmt))])


if __name__ == "__main__":
    main()
