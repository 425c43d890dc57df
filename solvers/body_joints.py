"""Joints of bodies and pinned rod bases (rodmol.Joint between bodies, a body and the world, or at a pinned base): the drift and the cost against the joint stiffness, and the linear solvers.

* ``pendulum``: a 0.5 kg body pinned to the world 0.1 m above its centre
  of mass, swinging from 0.3 rad for two periods (1.5 s), in air; the
  system's one rod (it must hold one) hangs damped far away;
* ``two bodies``: the same body with a 0.3 kg body clamped 0.2 m below
  the pivot, swinging as one from 0.4 rad for 1 s;
* ``simply supported``: a beam (L = 1 m, r = 1 cm, E = 10 GPa, N = 16)
  whose base is pinned to the world (its base segment's body pinned) and
  tip pinned (a Hold), settling under its weight for 0.3 s.

For stiffnesses k = factor times the default (the joint's reduced mass
times a squared frequency: between bodies a rod element's on 100 E A / ds,
at the pinned base its rod's node on its default Hold; damping critical:
docs/systems.md, "Joints of bodies"), each system runs through
``rodmol.simulate`` (CVODE, default tolerances) with GMRES and the block
preconditioner (the free bodies with joints between them, and the pinned
bases with their rods, in its Schur complement) and with the sparse direct
solver. The table gives the drift of the joints (the distance between the
two points, max over the run and at the end, relative to the pendulum's
arm or the beam's length), CVODE's right-hand sides and the solver's wall
time, each also as a ratio to a reference measured in the same run: the
pendulum and the pair against the one body of the pair's combined mass
properties held by a joint of the default stiffness (the pendulum: against
itself at the default), the beam against the same beam with its base
clamped (the pinned base's fast mode: its segment's small inertia),
medians of --reps.

    python solvers/body_joints.py [--quick | --smoke] [--out DIR] [--reps K]
"""

import _common as C
from _common import np, rodmol

from rodmol.discretise.assembly import Assembly
from rodmol.loads import P_STIFFNESS

SCRIPT = "body_joints.py"
ARM, CB = 0.1, np.array([0.0, -0.2, 0.0])


def _far_rod():
    material = rodmol.Material(E=1e6, nu=0.5, mu=1e4, rho=1000.0)
    down = ((0.0, 1.0, 0.0), (-1.0, 0.0, 0.0), (0.0, 0.0, 1.0))
    return rodmol.Model(rodmol.Rod(0.1, radius=0.01, material=material), 4,
                        base=rodmol.BaseMotion(position=(1.0, 0.0, 0.0), rotation=down))


def _turn(angle):
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def _scaled(build, factor, n=None):
    """The system ``build(stiffness, n)`` with its body joints at ``factor`` times their default stiffness."""
    defaults = [j.row[P_STIFFNESS] for j in Assembly(build([None, None], n)).body_joints]
    return build([factor * k for k in defaults], n)


def pendulum(stiffness, n=None):
    body = rodmol.RigidBody(0.5, (2e-3,) * 3, centre_of_mass=(0.0, -ARM, 0.0), rotation=_turn(0.3))
    return rodmol.System({"far": _far_rod()}, {"a": body},
                         [rodmol.Joint(("a", (0.0, 0.0, 0.0)), "world", "pin", stiffness=stiffness[0])])


def pair(stiffness, n=None):
    start = _turn(0.4)
    a = rodmol.RigidBody(0.5, (2e-3,) * 3, centre_of_mass=(0.0, -ARM, 0.0), rotation=start)
    b = rodmol.RigidBody(0.3, (5e-4, 5e-4, 1e-3), position=start @ CB, rotation=start)
    return rodmol.System({"far": _far_rod()}, {"a": a, "b": b},
                         [rodmol.Joint(("a", (0.0, 0.0, 0.0)), "world", "pin", stiffness=stiffness[0]),
                          rodmol.Joint(("a", CB), ("b", (0.0, 0.0, 0.0)), stiffness=stiffness[1])])


def one_body(stiffness=None, n=None):
    centre = (0.5 * np.array([0.0, -ARM, 0.0]) + 0.3 * CB) / 0.8
    arms = [np.array([0.0, -ARM, 0.0]) - centre, CB - centre]
    shift = [np.dot(r, r) * np.eye(3) - np.outer(r, r) for r in arms]
    inertia = 2e-3 * np.eye(3) + 0.5 * shift[0] + np.diag((5e-4, 5e-4, 1e-3)) + 0.3 * shift[1]
    body = rodmol.RigidBody(0.8, inertia, centre_of_mass=centre, rotation=_turn(0.4))
    return rodmol.System({"far": _far_rod()}, {"a": body}, [rodmol.Joint(("a", (0.0, 0.0, 0.0)), "world", "pin")])


def beam(stiffness, n, base="pin"):
    material = rodmol.Material(E=1e10, nu=0.5, mu=1e7, rho=1000.0)
    model = rodmol.Model(rodmol.Rod(1.0, radius=0.01, material=material), n)
    extra = {} if base == "clamp" else dict(stiffness=stiffness[0])
    return rodmol.System({"beam": model}, joints=[rodmol.Joint(("beam", "base"), "world", base, **extra),
                                                  rodmol.Joint(("beam", "tip"), "world", "pin")])


PROBLEMS = {  # name: (build(stiffness, n), reference(n), t_end per mode, N per mode, the drift's length)
    "pendulum": (pendulum, lambda n: _scaled(pendulum, 1.0, n), (1.5, 0.75, 0.05), (0, 0, 0), ARM),
    "two bodies": (pair, one_body, (1.0, 0.5, 0.05), (0, 0, 0), ARM),
    "simply supported": (beam, lambda n: beam(None, n, "clamp"), (0.3, 0.3, 0.02), (16, 16, 4), 1.0),
}


def drift(run, system):
    """Max over the body joints of the distance between their two points [m] at each frame."""
    gaps = []
    for joint in system.body_joints:
        a = run[joint.a]
        u_a = a.position + np.einsum("tij,j->ti", a.rotation, joint.point_a)
        if joint.b is None:
            u_b = joint.point_b
        else:
            b = run[joint.b]
            u_b = b.position + np.einsum("tij,j->ti", b.rotation, joint.point_b)
        gaps.append(np.linalg.norm(u_a - u_b, axis=-1))
    return np.max(gaps, axis=0)


def main(argv=None):
    args = C.parse_args(__doc__.splitlines()[0], argv)
    header = C.header_lines(args, SCRIPT)
    factors = C.pick(args, (0.01, 1.0, 100.0, 1e4), (0.01, 1.0, 100.0), (1.0,))
    rows = []
    for name, (build, reference, t_ends, sizes, length) in PROBLEMS.items():
        t_end, n = C.pick(args, *t_ends), C.pick(args, *sizes)
        rodmol.simulate(_scaled(build, 1.0, n), t_end / 10)  # compile, warm
        for solver in ("gmres", "sparse"):
            run_ref, wall_ref = C.timed_simulate(reference(n), t_end, args.reps, linsolver=solver)
            for factor in factors:
                system = _scaled(build, factor, n)
                run, wall = C.timed_simulate(system, t_end, args.reps, linsolver=solver)
                rows.append(C.drift_row(run, wall, drift(run, system) / length, run_ref, wall_ref, "reference",
                                        problem=name, N=n, factor=factor, linear_solver=solver))

    formats = dict(factor="g", t_reached_s=".3g", max_drift_over_L=".2e", end_drift_over_L=".2e",
                   rhs_over_reference=".2f", solver_s=".3f", solver_over_reference=".2f")
    C.write_results(args, "body_joints", "Joints of bodies and pinned bases: drift and cost against the stiffness",
                    header, rows, [
                        ("k = factor times the default (reduced mass times a held rod node's squared frequency: "
                         "docs/systems.md), "
                         "damping critical; drift over the pendulum's arm (0.1 m) or the beam's length; ratios to "
                         "the reference of the module docstring, same run, same linear solver",
                         C.markdown_table(rows, formats=formats))])


if __name__ == "__main__":
    main()
