"""Runs of systems of rods and rigid bodies (rodmol.simulate, what differs in rodmol.run_kinds) against single-rod
runs, analytic motions and the conservation of momentum."""

import numpy as np
import pytest

import rodmol

GRAVITY_OFF = (0.0, 0.0, 0.0)
MATERIAL = rodmol.Material(E=1e5, nu=0.5, mu=300.0, rho=1080.0)


def _ramp(t):
    return 0.2 * min(t / 0.05, 1.0)


def _arm(side=1.0, n=8, **options):
    """A 0.2 m cable-driven arm, the cable on its local +y side (``side`` 1) or -y side (-1)."""
    rod = rodmol.Rod(0.2, radius=0.01, material=MATERIAL)
    cable = rodmol.Cable((side * 0.005, 0.0), 0.2, name="c", tension=_ramp)
    return rodmol.Model(rod, n, cables=[cable], **options)


def _rz(angle):
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def test_one_rod_on_the_world_or_a_fixed_body_reproduces_the_model():
    point, turn = np.array([0.03, -0.01, 0.02]), _rz(0.7)
    body = rodmol.RigidBody(1.0, (1e-3, 1e-3, 1e-3), position=(0.1, 0.0, 0.0), rotation=_rz(-0.3), motion="fixed")
    base = rodmol.BaseMotion(position=tuple(body.position + body.rotation @ point),
                             rotation=tuple(map(tuple, body.rotation @ turn)))
    alone = rodmol.simulate(_arm(gravity=(0.0, -9.81, 0.0), base=base), 0.2, initial="straight", rtol=1e-6)
    on_world = rodmol.simulate(rodmol.System({"arm": _arm(base=base)}), 0.2, rtol=1e-6)
    on_body = rodmol.simulate(rodmol.System({"arm": _arm()}, {"b": body}, [rodmol.Joint(("b", point, turn), ("arm", "base"))]),
                              0.2, rtol=1e-6)
    assert np.ptp(alone.tip[:, 1]) > 0.02  # it moved
    for run in (on_world, on_body):
        assert run.success
        np.testing.assert_allclose(run["arm"].positions, alone.positions, atol=5e-6 * 0.2)  # rtol L, times a few
        moment = alone.internal_moment
        np.testing.assert_allclose(run["arm"].internal_moment, moment, atol=1e-4 * np.abs(moment).max())


def test_rod_on_a_driven_body_follows_the_model_with_the_same_base_pose():
    # The body turns at omega about z while its origin moves at speed V along its own x axis:
    # R = Rz(omega t), x = V / omega (sin, 1 - cos, 0). The single rod's base follows
    # x + R p, R Rj by central differences of that pose (BaseMotion.from_pose).
    omega, speed, point, turn = 2.0, 0.1, np.array([0.05, 0.02, 0.0]), _rz(0.5)

    def position(t):
        return speed / omega * np.array([np.sin(omega * t), 1.0 - np.cos(omega * t), 0.0])

    motion = rodmol.BaseMotion(lambda t: (speed, 0.0, 0.0), lambda t: (0.0, 0.0, omega))
    body = rodmol.RigidBody(1.0, (1e-3, 1e-3, 1e-3), motion=motion)
    system = rodmol.System({"arm": _arm()}, {"b": body}, [rodmol.Joint(("b", point, turn), ("arm", "base"))],
                           gravity=GRAVITY_OFF)
    run = rodmol.simulate(system, 0.3, rtol=1e-6)
    base = rodmol.BaseMotion.from_pose(lambda t: position(t) + _rz(omega * t) @ point,
                                       lambda t: _rz(omega * t) @ turn)
    alone = rodmol.simulate(_arm(base=base, gravity=GRAVITY_OFF), 0.3, initial="straight", rtol=1e-6)
    np.testing.assert_allclose(run["arm"].positions, alone.positions, atol=2e-6 * 0.2)
    np.testing.assert_allclose(run["b"].position, [position(t) for t in run.t], atol=1e-7)
    np.testing.assert_allclose(run["b"].rotation, [_rz(omega * t) for t in run.t], atol=1e-6)
    np.testing.assert_allclose(run["arm"].velocity[:, 0], alone.velocity[:, 0], atol=1e-6)


def _free_head(arms, rtol, gravity=GRAVITY_OFF, t_end=0.15, **options):
    head = rodmol.RigidBody(0.05, (2e-5, 3e-5, 4e-5), centre_of_mass=(0.0, 0.004, 0.0))
    joints = [rodmol.Joint(("head", point, turn), (name, "base")) for name, (_, point, turn) in arms.items()]
    system = rodmol.System({name: model for name, (model, _, _) in arms.items()}, {"head": head}, joints,
                           gravity=gravity)
    return rodmol.simulate(system, t_end, rtol=rtol, output_dt=0.01, **options)


def _one_arm(n=8):
    return {"arm": (_arm(n=n), np.array([0.02, 0.0, 0.01]), _rz(0.3))}


def test_free_body_and_rod_in_vacuum_keep_zero_momentum_to_the_tolerance():
    scale = 1080.0 * np.pi * 1e-4 * 0.2 * 0.1  # the arm's mass times its tip speed (~0.1 m/s)
    errors = {}
    for rtol in (1e-4, 1e-6):
        run = _free_head(_one_arm(), rtol)
        linear, angular = run.momentum()
        errors[rtol] = np.abs(linear).max() / scale, np.abs(angular).max() / (scale * 0.2)
        assert np.abs(run["head"].velocity).max() > 0.01  # the head recoils
        assert np.abs(run["head"].angular_velocity).max() > 0.1
    assert max(errors[1e-4]) < 3e-3
    assert max(errors[1e-6]) < 3e-5
    assert errors[1e-6][0] < errors[1e-4][0] / 10 and errors[1e-6][1] < errors[1e-4][1] / 10


def test_free_fall_gains_the_momentum_of_the_total_weight():
    """The whole rod's mass from its volume: the head carries the base half cell."""
    g = np.array([0.0, 0.0, -9.81])
    run = _free_head(_one_arm(), 1e-6, gravity=g, t_end=0.1)
    mass = 0.05 + 1080.0 * np.pi * 0.01**2 * 0.2
    linear, _ = run.momentum()
    np.testing.assert_allclose(linear, mass * g * run.t[:, None], atol=1e-5 * mass * 9.81 * 0.1)


def test_a_free_body_and_its_rod_fall_at_g_unstrained_and_unturned():
    """In vacuum everything falls at g: the head (its centre of mass off its
    origin, the arm clamped off it at an angle) with the arm's base half cell
    it carries; a mass without its weight, or a weight away from its mass,
    would strain the arm or turn the head."""
    g = np.array([0.0, -3.0, -9.0])
    arm = rodmol.Model(rodmol.Rod(0.2, radius=(0.01, 0.005), material=MATERIAL), 8)
    run = _free_head({"arm": (arm, np.array([0.02, 0.0, 0.01]), _rz(0.3))}, 1e-8, gravity=g, t_end=0.1)
    head, arm = run["head"], run["arm"]
    np.testing.assert_allclose(np.einsum("nij,nj->ni", head.rotation, head.velocity), g * run.t[:, None],
                               rtol=0, atol=1e-9)
    np.testing.assert_allclose(head.angular_velocity, 0.0, atol=1e-9)
    u = arm.integrated_positions  # a rigid translation: every node as the base
    np.testing.assert_allclose(u - u[:, :1], np.broadcast_to(u[0] - u[0, :1], u.shape), rtol=0, atol=1e-12)
    np.testing.assert_allclose(u[:, 0] - u[0, 0], 0.5 * g * run.t[:, None] ** 2, rtol=0, atol=1e-8)


def test_a_neutrally_buoyant_rod_on_a_neutrally_buoyant_body_stays_at_rest_in_water():
    """Rod and body of the water's density (the rod's added mass on, the head's
    centre of mass off its origin, the arm clamped off it at an angle): no net
    force anywhere, so nothing moves, to rounding."""
    water = rodmol.MEDIA["water"].rho
    rod = rodmol.Rod(0.2, radius=(0.01, 0.005), material=rodmol.Material(E=1e5, nu=0.5, mu=300.0, rho=water))
    head = rodmol.RigidBody(water * 5e-5, (2e-5, 3e-5, 4e-5), volume=5e-5, centre_of_mass=(0.0, 0.004, 0.0))
    system = rodmol.System({"arm": rodmol.Model(rod, 8)}, {"head": head},
                           [rodmol.Joint(("head", (0.02, 0.0, 0.01), _rz(0.3)), ("arm", "base"))],
                           medium="water", gravity=(0.0, -3.0, -9.81))
    run = rodmol.simulate(system, 0.5, output_dt=0.1)
    assert run.success
    np.testing.assert_allclose(run["head"].velocity, 0.0, atol=1e-14)
    np.testing.assert_allclose(run["head"].angular_velocity, 0.0, atol=1e-13)
    np.testing.assert_allclose(run["arm"].velocity, 0.0, atol=1e-14)
    np.testing.assert_allclose(run["head"].position, 0.0, atol=1e-14)


def test_mirrored_pair_of_arms_leaves_the_head_unrotated():
    mirror = np.diag([-1.0, -1.0, 1.0])
    arms = {"right": (_arm(1.0), np.array([0.02, 0.0, 0.0]), np.eye(3)),
            "left": (_arm(-1.0), np.array([-0.02, 0.0, 0.0]), mirror)}
    run = _free_head(arms, 1e-6)
    head = run["head"]
    assert np.abs(head.velocity[:, 1]).max() > 0.01  # it recoils along y
    assert np.abs(run["right"].angular_velocity).max() > 1.0
    assert np.abs(head.angular_velocity).max() < 1e-4
    np.testing.assert_allclose(run["left"].tip[:, 0], -run["right"].tip[:, 0], atol=1e-6)
    # The rod's Result on a free body: its base moves with the head's clamp (v + w x p, Rj = I).
    clamp = head.velocity + np.cross(head.angular_velocity, [0.02, 0.0, 0.0])
    np.testing.assert_allclose(run["right"].velocity[:, 0], clamp, atol=1e-12)
    # A run continued from the middle frame ends where the whole run did.
    half = rodmol.simulate(run.assembly.system, 0.07, rtol=1e-6, output_dt=0.01)
    rest = rodmol.simulate(half.assembly.system, 0.15, rtol=1e-6, output_dt=0.01, initial=half)
    assert rest.t[0] == pytest.approx(0.07)
    np.testing.assert_allclose(rest["right"].tip[-1], run["right"].tip[-1], atol=2e-6 * 0.2)
    distance, angle = run.pose_drift("right")
    assert distance.max() < 1e-5 * 0.2 and angle.max() < 1e-4
    # The sparse direct solver of the whole Newton matrix agrees with the preconditioned GMRES.
    direct = _free_head(arms, 1e-6, linsolver="sparse")
    assert run.stats["linear_solver"] == "gmres" and direct.stats["linear_solver"] == "sparse"
    np.testing.assert_allclose(direct["right"].positions, run["right"].positions, atol=2e-6 * 0.2)
    np.testing.assert_allclose(direct["head"].velocity, head.velocity, atol=1e-5)


@pytest.mark.parametrize("linsolver", ["gmres", "sparse"])
def test_a_failing_input_ends_the_run_with_the_frames_before_it(linsolver):
    """Under "sparse" an exception raised through scikit-sundae's SuperLU_MT path crashed the process."""
    def tension(t):
        if t > 0.055:
            raise RuntimeError("sensor lost")
        return 0.1

    arm = _arm().replace(cables=[rodmol.Cable((0.005, 0.0), 0.2, tension=tension)])
    head = rodmol.RigidBody(0.05, (2e-5, 2e-5, 2e-5))
    system = rodmol.System({"arm": arm}, {"head": head}, [rodmol.Joint(("head", (0.0, 0.0, 0.0)), ("arm", "base"))])
    with pytest.warns(RuntimeWarning, match="sensor lost"):
        run = rodmol.simulate(system, 0.2, output_dt=0.01, linsolver=linsolver)
    assert not run.success and isinstance(run.error, rodmol.UserFunctionError)
    assert run.stats["linear_solver"] == linsolver
    assert 0.04 <= run.t[-1] <= 0.05 and "after t = " in run.message
    assert run["arm"].positions.shape[0] == len(run.t) and np.all(np.isfinite(run.states))


def test_progress_sees_every_output_and_the_wall_time_budget_stops_the_run():
    seen = []
    run = rodmol.simulate(rodmol.System({"arm": _arm()}), 0.05, output_dt=0.01,
                          progress=lambda t, t_end: seen.append((t, t_end)))
    assert run.success and [t for t, _ in seen] == pytest.approx(list(run.t)) and {e for _, e in seen} == {0.05}
    with pytest.warns(RuntimeWarning, match="wall-time budget"):
        stopped = rodmol.simulate(rodmol.System({"arm": _arm()}), 10.0, max_wall_time=1e-9)
    assert not stopped.success and len(stopped.t) == 1


@pytest.mark.parametrize("kwargs, match", [
    (dict(resume=True), "needs `out`"),
    (dict(resume="force"), "needs `out`"),
    (dict(backend="rk45"), "unknown `backend` 'rk45'"),
    (dict(linsolver="band"), "linsolver"),
    (dict(krylov_dim=3), "unknown option"),
])
def test_what_systems_do_not_do_yet_is_refused_before_any_work(kwargs, match):
    with pytest.raises(rodmol.ParameterError, match=match):
        rodmol.simulate(rodmol.System({"arm": _arm()}), 0.1, **kwargs)


def test_sinking_body_starts_at_its_net_weight_over_its_mass_and_ends_at_its_terminal_speed():
    # A stiff rod (its axial waves cross it in 0.1 ms) of the fluid's density hanging straight
    # down (no net weight, drag or added mass) rides along: the body starts at
    # a = (m - rho V) g / (m + m_added + m_rod) and ends where its drag d v^2 balances its net
    # weight. The rod's mass is 0.55% of the total: the first check sees it.
    fluid = rodmol.Medium(rho=1000.0)
    rod = rodmol.Rod(0.1, radius=0.005, material=rodmol.Material(E=1e9, nu=0.5, mu=1e4, rho=1000.0))
    mass, volume, added, drag, g = 1.0, 5e-4, 0.3, 10.0, 9.81
    body = rodmol.RigidBody(mass, (1e-3, 1e-3, 1e-3), volume=volume, added_mass=(added,) * 3 + (0.0,) * 3,
                            drag=(drag,) * 3 + (0.0,) * 3)
    down = np.array([[0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [-1.0, 0.0, 0.0]])  # the rod's x along -z
    system = rodmol.System({"tail": rodmol.Model(rod, 6)}, {"body": body},
                           [rodmol.Joint(("body", (0.0, 0.0, 0.0), down), ("tail", "base"))],
                           medium=fluid, gravity=(0.0, 0.0, -g))
    run = rodmol.simulate(system, 1.0, rtol=1e-7, output_times=[0.002])
    weight = (mass - 1000.0 * volume) * g
    rod_mass = 1000.0 * np.pi * 0.005**2 * 0.1  # the nodes' and the base half cell the body carries
    speed = -run["body"].velocity[:, 2]
    assert speed[1] / 0.002 == pytest.approx(weight / (mass + added + rod_mass), rel=2e-3)
    assert speed[-1] == pytest.approx(np.sqrt(weight / drag), rel=1e-4)
    np.testing.assert_allclose(run["body"].position[-1, :2], 0.0, atol=1e-9)


def test_the_equilibrium_of_a_system_on_a_fixed_body_is_each_rods_own_on_its_clamp():
    """With every body's pose given, no rod acts on another: the system's rest
    state is each rod's single-rod equilibrium clamped where its joint puts it,
    and a run from it stays there. A free body is refused, naming it."""
    from rodmol.discretise.assembly import Assembly

    material = rodmol.Material(E=2e5, nu=0.5, mu=300.0, rho=1100.0)
    rod = rodmol.Rod(0.2, radius=(0.01, 0.005), material=material)
    arms = {name: rodmol.Model(rod, 8, cables=[rodmol.Cable((side * 0.004, 0.0), 0.2, tension=0.1)])
            for name, side in (("up", 1.0), ("down", -1.0))}
    turn = np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])
    frame = rodmol.RigidBody(1.0, (1e-3, 1e-3, 1e-3), motion="fixed", position=(0.1, 0.2, 0.3), rotation=turn)
    joints = [rodmol.Joint(("frame", (0.02, 0.0, 0.0)), ("up", "base")),
              rodmol.Joint(("frame", (-0.02, 0.0, 0.0), np.diag([-1.0, -1.0, 1.0])), ("down", "base"))]
    system = rodmol.System(arms, {"frame": frame}, joints, gravity=(0.0, 0.0, -9.81))
    y = rodmol.equilibrium(system)
    parts = Assembly(system).parts
    for name in arms:
        alone = system.rods[name].replace(base=system.base_motion(name))
        assert np.allclose(y[parts[name]], rodmol.equilibrium(alone), rtol=0.0, atol=1e-12)
    run = rodmol.simulate(system, 0.05, initial="equilibrium", output_dt=0.05)
    for name in arms:
        tip = run[name].tip
        assert np.linalg.norm(tip[-1] - tip[0]) < 1e-8  # m: at rest (it sags by cm under gravity)
        assert np.linalg.norm(tip[0] - run[name].positions[0, 0] - 0.2 * turn[:, 0] * (1 if name == "up" else -1)) > 0.01
    free = rodmol.System(arms, {"head": rodmol.RigidBody(1.0, (1e-3, 1e-3, 1e-3))},
                         [rodmol.Joint(("head", (0.0, 0.0, 0.0)), ("up", "base"))])
    with pytest.raises(rodmol.EquilibriumError, match="free body 'head' is held by nothing"):  # it falls
        rodmol.simulate(free, 0.1, initial="equilibrium")
