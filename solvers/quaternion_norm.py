"""The quaternions' norm over the fetching test, with and without the projection of the stored states.

The integrator lets |Q| stray from 1 by up to its tolerance during fast
motion (CVODE's error test sees the norm like any other component); the
dynamics do not depend on |Q| (rotations divide by |Q|^2, the kinematics are
linear in Q), and the backends hand back states whose quaternions are put
back on the unit sphere (``StateLayout.project_quaternions``). Here the
paper's fetching test runs --t-end (60 s) at default settings, in memory
and streamed (the solver restarts from the projected states at every chunk
boundary), once as rodmol does and once with the projection switched off
(the code before it): the largest ||Q| - 1| of the frames, the tip's largest
distance between the two, and the wall times, in one process, alternating
(which of the two goes first alternates too), and the time the projection
of all the frames takes on its own.

    python solvers/quaternion_norm.py [--quick | --smoke] [--out DIR] [--reps K]
"""

import tempfile
import time

import _common as C
from _common import np, rodmol

from rodmol.discretise.layout import StateLayout
from rodmol.output.stream import RunWriter

SCRIPT = "quaternion_norm.py"
PROJECT = StateLayout.project_quaternions


def run(model, t_end, project, streamed):
    StateLayout.project_quaternions = PROJECT if project else (lambda self, y: None)
    try:
        with tempfile.TemporaryDirectory() as tmp:
            out = RunWriter(tmp, views=False) if streamed else None
            start = time.perf_counter()
            result = rodmol.simulate(model, t_end, out=out)
            wall = time.perf_counter() - start
            assert result.success, result.message
            states = np.array(result.states)
            start = time.perf_counter()
            PROJECT(StateLayout(model.n_elements), states)
            projection = time.perf_counter() - start  # what the projection costs the run
            return wall, result.positions[:, -1].copy(), float(result.quaternion_norm_error.max()), \
                result.stats["steps"], projection
    finally:
        StateLayout.project_quaternions = PROJECT


def main(argv=None):
    args = C.parse_args(__doc__.splitlines()[0], argv)
    header = C.header_lines(args, SCRIPT)
    t_end, n = C.pick(args, 60.0, 20.0, 2.0), C.pick(args, 100, 50, 10)
    model = rodmol.scenarios.get("fetching").model(n)
    run(model, min(t_end, 1.0), True, False)  # compile and warm up
    rows = []
    for streamed in (False, True):
        walls = {True: [], False: []}
        for rep in range(args.reps):
            for project in (False, True) if rep % 2 == 0 else (True, False):  # neither always first
                wall, tip, drift, steps, projection = run(model, t_end, project, streamed)
                walls[project].append(wall)
                if project:
                    tip_with, drift_with, steps_with = tip, drift, steps
                else:
                    tip_without, drift_without, steps_without = tip, drift, steps
        rows.append(dict(
            output="streamed" if streamed else "in memory", N=n, t_end_s=t_end,
            max_norm_error_without=drift_without, max_norm_error_with=drift_with,
            tip_difference_m=float(np.max(np.linalg.norm(tip_with - tip_without, axis=-1))),
            steps_without=steps_without, steps_with=steps_with,
            wall_without_s=float(np.median(walls[False])), wall_with_s=float(np.median(walls[True])),
            wall_ratio=float(np.median(walls[True]) / np.median(walls[False])),
            projection_s=projection))
        print(rows[-1], flush=True)
    table = C.markdown_table(rows, formats=dict(max_norm_error_without=".2e", max_norm_error_with=".2e",
                                                tip_difference_m=".2e", wall_ratio=".2f"))
    C.write_results(args, "quaternion_norm", "Quaternion norm over the fetching test", header, rows,
                    [(f"fetching test, N = {n}, {t_end:g} s, default tolerances, median of {args.reps}",
                      table)])


if __name__ == "__main__":
    main()
