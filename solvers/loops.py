"""Penalty joints of systems (rodmol.Joint at a rod's tip): the constraint drift and the cost against the penalty stiffness, and the linear solvers.

Two systems whose loops close through penalty joints:

* ``payload``: a slender cantilever (L = 1 m, r = 1 cm, E = 1 GPa, no
  material damping) whose tip is clamped to a 0.3 kg payload, released
  straight under a small weight (0.5 m/s^2 sideways): it swings for 1 s;
* ``parallel robot``: three legs (L = 0.2 m, r = 5 mm, E = 200 MPa, Kelvin-Voigt
  mu = 2 MPa s) clamped to the ground and, at their tips, to a free 0.5 kg
  platform, released straight under gravity partly sideways; it settles in 1.5 s;
* ``six legs``: the same with six legs (a Stewart-Gough layout, as in Till's
  example) at a finer grid;
* ``two half beams``: two cantilevers (L = 0.25 m, r = 1 cm, E = 10 MPa)
  from opposite walls, their tips clamped to each other, released straight
  under gravity;
* ``three rods``: three such cantilevers from walls 120 degrees apart, their
  tips meeting at the middle, a's clamped to b's and b's to c's, released
  under gravity across their plane (they sag and twist);
* ``ring``: two soft rods (L = 0.2 m, r = 1 cm, E = 100 kPa) clamped to the
  ends of a free 0.2 m bar at their bases and to each other at their tips
  (an equilateral triangle, a closed loop with no world in it, the bar in
  the Schur complement), bent by a cable of one rod (0.3 N, ramped in
  50 ms), no gravity.

For penalty stiffnesses k = factor E A / ds of the tip element (damping
2 sqrt(k m), m = rho A ds, the Hold's default law), and the default
stiffness (the Hold's, 100 E A L / ds^2: factor 100 L / ds, marked), each system runs through
``rodmol.simulate`` (CVODE, default tolerances) with the sparse direct
solver and with GMRES and the block preconditioner (the free bodies with
penalty joints eliminated by their Schur complement). The table gives the drift |u - x - R p| of
each joint (max over the run and at the end, relative to L; between two
rods, the nodes' distance), CVODE's
right-hand sides and the solver's wall time, each also as a ratio to the same
rods with free tips and no body (the joints' cost), measured in the same
run, medians of --reps. A second table takes the systems of joints between
rods at the default stiffness (None: the Hold's law) through N = 8, 32, 100 per rod: right-hand
sides and wall times of GMRES (the rod-rod joints' blocks in its
preconditioner, :mod:`rodmol.discretise.rod_joint_coupling`) and of the
sparse solver, their ratios, and the largest distance between the two
runs' nodes over the run, relative to L.

    python solvers/loops.py [--quick | --smoke] [--out DIR] [--reps K]
"""

import os

import _common as C
from _common import np, rodmol

from rodmol.holds import HOLD_STIFFNESS_FACTOR

SCRIPT = "loops.py"
UP = np.array([[0.0, 0.0, -1.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]])  # a leg's x axis along global z


def _stiffness(model, factor):
    """factor E A / ds of the tip element [N/m]; None for the default (the Hold's law)."""
    if factor is None:
        return None
    rod = model.rod
    return factor * rod.material.E * float(rod.area(rod.length)) / model.ds


def default_factor(model):
    """The default stiffness's factor on E A / ds: HOLD_STIFFNESS_FACTOR L / ds (rodmol.holds.default_stiffness)."""
    return HOLD_STIFFNESS_FACTOR * model.rod.length / model.ds


def payload(n, factor, joined=True):
    material = rodmol.Material(E=1e9, nu=0.5, mu=0.0, rho=1000.0)
    beam = rodmol.Model(rodmol.Rod(1.0, radius=0.01, material=material), n)
    if not joined:
        return rodmol.System({"beam": beam}, gravity=(0.0, -0.5, 0.0))
    body = rodmol.RigidBody(0.3, (1e-5, 2e-4, 2e-4), position=(1.0, 0.0, 0.0))
    joint = rodmol.Joint(("payload", (0.0, 0.0, 0.0)), ("beam", "tip"), stiffness=_stiffness(beam, factor))
    return rodmol.System({"beam": beam}, {"payload": body}, [joint], gravity=(0.0, -0.5, 0.0))


def robot(n, factor, joined=True, legs=3):
    points = np.array([[0.05 * np.cos(a), 0.05 * np.sin(a), 0.0] for a in 2 * np.pi * np.arange(legs) / legs + 0.3])
    material = rodmol.Material(E=2e8, nu=0.5, mu=2e6, rho=1000.0)
    leg = rodmol.Rod(0.2, radius=0.005, material=material)
    legs = {f"leg{i}": rodmol.Model(leg, n, base=rodmol.BaseMotion(position=tuple(p), rotation=UP))
            for i, p in enumerate(points)}
    gravity = (-9.81, 0.0, -3.0)
    if not joined:
        return rodmol.System(legs, gravity=gravity)
    body = rodmol.RigidBody(0.5, (1e-3, 1e-3, 2e-3), centre_of_mass=(0.02, 0.01, 0.0), position=(0.0, 0.0, 0.2))
    stiffness = _stiffness(legs["leg0"], factor)
    joints = [rodmol.Joint(("platform", tuple(p)), (f"leg{i}", "tip"), stiffness=stiffness)
              for i, p in enumerate(points)]
    return rodmol.System(legs, {"platform": body}, joints, gravity=gravity)


def halves(n, factor, joined=True):
    material = rodmol.Material(E=1e7, nu=0.5, mu=7e4, rho=1000.0)
    half = rodmol.Rod(0.25, radius=0.01, material=material)
    right = rodmol.BaseMotion(position=(0.5, 0.0, 0.0), rotation=np.diag([-1.0, -1.0, 1.0]))
    rods = {"left": rodmol.Model(half, n), "right": rodmol.Model(half, n, base=right)}
    if not joined:
        return rodmol.System(rods, gravity=(0.0, -9.81, 0.0))
    joint = rodmol.Joint(("left", "tip"), ("right", "tip"), stiffness=_stiffness(rods["left"], factor))
    return rodmol.System(rods, joints=[joint], gravity=(0.0, -9.81, 0.0))


def three(n, factor, joined=True):
    material = rodmol.Material(E=1e7, nu=0.5, mu=7e4, rho=1000.0)
    arm = rodmol.Rod(0.25, radius=0.01, material=material)
    rods = {}
    for name, angle in zip("abc", np.radians([90.0, 210.0, 330.0])):
        inward = -np.array([np.cos(angle), np.sin(angle), 0.0])  # its x axis, from the wall to the middle
        turn = np.column_stack([inward, np.cross([0.0, 0.0, 1.0], inward), [0.0, 0.0, 1.0]])
        rods[name] = rodmol.Model(arm, n, base=rodmol.BaseMotion(position=tuple(-0.25 * inward), rotation=turn))
    if not joined:
        return rodmol.System(rods, gravity=(0.0, 0.0, -9.81))
    stiffness = _stiffness(rods["a"], factor)
    joints = [rodmol.Joint(("a", "tip"), ("b", "tip"), stiffness=stiffness),
              rodmol.Joint(("b", "tip"), ("c", "tip"), stiffness=stiffness)]
    return rodmol.System(rods, joints=joints, gravity=(0.0, 0.0, -9.81))


def _turn(degrees):
    """A rod's frame turned by ``degrees`` about global z from the x axis."""
    c, s = np.cos(np.radians(degrees)), np.sin(np.radians(degrees))
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def ring(n, factor, joined=True):
    material = rodmol.Material(E=1e5, nu=0.5, mu=300.0, rho=1080.0)
    pull = rodmol.Cable((0.005, 0.0), 0.2, tension=lambda t: 0.3 * min(t / 0.05, 1.0))
    rod = rodmol.Rod(0.2, radius=0.01, material=material)
    rods = {"a": rodmol.Model(rod, n, cables=[pull]), "b": rodmol.Model(rod, n)}
    bar = rodmol.RigidBody(0.02, (1e-5, 1e-5, 1e-5), centre_of_mass=(0.1, 0.0, 0.0))
    joints = [rodmol.Joint(("bar", (0.0, 0.0, 0.0), _turn(60.0)), ("a", "base")),
              rodmol.Joint(("bar", (0.2, 0.0, 0.0), _turn(120.0)), ("b", "base"))]
    if joined:
        joints.append(rodmol.Joint(("a", "tip"), ("b", "tip"), stiffness=_stiffness(rods["a"], factor)))
    return rodmol.System(rods, {"bar": bar}, joints, gravity=(0.0, 0.0, 0.0))


PROBLEMS = {  # name: (system(n, factor, joined), t_end per mode, N per mode)
    "payload": (payload, (1.0, 0.5, 0.05), (16, 16, 6)),
    "parallel robot": (robot, (1.5, 0.75, 0.05), (16, 16, 6)),
    "six legs": (lambda n, factor, joined=True: robot(n, factor, joined, legs=6), (1.5, 0.75, 0.05), (60, 40, 6)),
    "two half beams": (halves, (0.3, 0.3, 0.05), (8, 8, 4)),
    "three rods": (three, (0.3, 0.3, 0.05), (8, 8, 4)),
    "ring": (ring, (0.5, 0.5, 0.05), (8, 8, 4)),
}
#: The systems of joints between rods, and the grids per rod of the solvers' comparison, per mode.
BETWEEN_RODS = ("two half beams", "three rods", "ring")
SIZES = ((8, 32, 100), (8, 32), (4,))


def _node(run, system, rod, load):
    model = system.rods[rod]
    return run[rod].integrated_positions[:, int(round(model.loads[load].s / model.ds))]


def drift(run, system):
    """Max over the joints of |u - x - R p| (or |u_a - u_b| between two rods) [m] at each frame."""
    gaps = []
    for joint in system.penalty_joints:
        if joint.partner is not None:
            gaps.append(np.linalg.norm(_node(run, system, joint.rod, joint.load)
                                       - _node(run, system, joint.partner, joint.partner_load), axis=1))
            continue
        body = run[joint.body]
        held = body.position + np.einsum("tij,j->ti", body.rotation, joint.point)
        gaps.append(np.linalg.norm(_node(run, system, joint.rod, joint.load) - held, axis=1))
    return np.max(gaps, axis=0)


def main(argv=None):
    args = C.parse_args(__doc__.splitlines()[0], argv)
    header = C.header_lines(args, SCRIPT)
    factors = C.pick(args, (1.0, 10.0, 100.0, 1e3, 1e4, 1e5), (1.0, 100.0, 1e4), (100.0,))
    rows = []
    for name, (build, t_ends, sizes) in PROBLEMS.items():
        t_end, n = C.pick(args, *t_ends), C.pick(args, *sizes)
        free = build(n, None, joined=False)
        for solver in ("gmres", "sparse"):  # compile, warm
            rodmol.simulate(build(n, None), t_end / 10, linsolver=solver)
        run_free, wall_free = C.timed_simulate(free, t_end, args.reps)
        cases = [(f, solver) for f in (*factors, None) for solver in ("gmres", "sparse")]
        for factor, solver in cases:
            system = build(n, factor)
            run, wall = C.timed_simulate(system, t_end, args.reps, linsolver=solver)
            first = system.rods[next(iter(system.rods))]
            gap = drift(run, system) / first.rod.length
            rows.append(C.drift_row(run, wall, gap, run_free, wall_free, "free", problem=name, N=n,
                                    factor=default_factor(first) if factor is None else factor,
                                    default=factor is None, linear_solver=solver))

    formats = dict(factor="g", t_reached_s=".3g", max_drift_over_L=".2e", end_drift_over_L=".2e",
                   rhs_over_free=".2f", solver_s=".3f", solver_over_free=".2f")
    sizes = solvers_by_size(args)
    C.write_results(args, "loops", "Penalty joints of systems: drift and cost against the penalty stiffness",
                    header, rows, [
                        ("k = factor E A / ds, damping 2 sqrt(k m), the default (True) 100 E A L / ds^2; ratios to "
                         "the same rods with free tips and no body, same run, same linear solver",
                         C.markdown_table(rows, formats=formats)),
                        ("Joints between rods, default stiffness: GMRES against the sparse solver by N per rod "
                         "(wall times and their ratio medians of --reps, the two "
                         "solvers interleaved; the runs' largest node distance over L)", C.markdown_table(sizes, formats=dict(
                             gmres_s=".3f", sparse_s=".3f", rhs_ratio=".2f", wall_ratio=".2f",
                             max_difference_over_L=".1e")))])
    C.write_csv(os.path.join(args.out, "loops_by_size.csv"), sizes, header)


def solvers_by_size(args):
    """GMRES against the sparse solver on the joints between rods, at each N per rod."""
    out = []
    for name in BETWEEN_RODS:
        build, t_ends, _ = PROBLEMS[name]
        t_end = C.pick(args, *t_ends)
        for n in C.pick(args, *SIZES):
            system = build(n, None)
            walls = []
            for _ in range(args.reps):  # interleaved: the machine's load moves both alike
                gmres, gmres_s = C.timed_simulate(system, t_end, 1, linsolver="gmres")
                sparse, sparse_s = C.timed_simulate(system, t_end, 1, linsolver="sparse")
                walls.append((gmres_s, sparse_s, gmres_s / sparse_s))
            gmres_s, sparse_s, ratio = np.median(walls, axis=0)
            length = max(model.rod.length for model in system.rods.values())
            difference = max(np.abs(gmres[rod].integrated_positions - sparse[rod].integrated_positions).max()
                             for rod in system.rods)
            out.append(dict(problem=name, N=n, success=gmres.success and sparse.success,
                            gmres_rhs=gmres.stats["rhs_evals"], sparse_rhs=sparse.stats["rhs_evals"],
                            rhs_ratio=gmres.stats["rhs_evals"] / sparse.stats["rhs_evals"],
                            gmres_s=gmres_s, sparse_s=sparse_s, wall_ratio=ratio,
                            max_difference_over_L=float(difference) / length))
            print({k: (f"{v:.4g}" if isinstance(v, float) else v) for k, v in out[-1].items()}, flush=True)
    return out


if __name__ == "__main__":
    main()
