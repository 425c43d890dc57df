"""Penalty joints of systems (rodmol.Joint at a rod's tip or node s): a
swinging payload against the Euler-Bernoulli beam with a tip mass, a
parallel robot against a shooting solution of the Cosserat rod equations,
a closed loop that keeps its momentum, and a tip held to the world that is
the rod's own Hold."""

import functools

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.optimize import brentq, curve_fit, root
from scipy.spatial.transform import Rotation

import rodmol
from rodmol._differences import central_columns
from rodmol.discretise.assembly import Assembly

# ---------------------------------------------------------------- the payload

# A slender steel-like cantilever (L / r = 100) carrying at its tip a payload of
# mass M (its own mass is 0.3 kg too) and rotary inertia J about the bending axes.
BEAM_L, BEAM_R, BEAM_E, BEAM_RHO = 1.0, 0.01, 1e9, 1000.0
PAYLOAD_M, PAYLOAD_J = 0.3, 2e-4


def _tip_mass_determinant(beta, mass, inertia, ei, mass_per_length, length):
    """The frequency determinant of a clamped-free Euler-Bernoulli beam with
    a tip mass and rotary inertia: w = a (cos - cosh) + b (sin - sinh) of
    beta x meets w = w' = 0 at the clamp; at the tip the bending moment
    turns the payload, EI w'' = J omega^2 w', and the shear accelerates it,
    EI w''' = -M omega^2 w, omega^2 = EI beta^4 / (rho A)."""
    w2 = ei * beta**4 / mass_per_length
    c, s, ch, sh = np.cos(beta * length), np.sin(beta * length), np.cosh(beta * length), np.sinh(beta * length)
    w, slope = (c - ch, s - sh), (beta * (-s - sh), beta * (c - ch))
    curvature, shear = (beta**2 * (-c - ch), beta**2 * (-s - sh)), (beta**3 * (s - sh), beta**3 * (-c - ch))
    moment = [ei * curvature[i] - inertia * w2 * slope[i] for i in range(2)]
    force = [ei * shear[i] + mass * w2 * w[i] for i in range(2)]
    return moment[0] * force[1] - moment[1] * force[0]


def _first_root(f, upper):
    grid = np.linspace(1e-3 * upper, upper, 2000)
    values = [f(x) for x in grid]
    k = next(i for i in range(len(grid) - 1) if values[i] * values[i + 1] < 0.0)
    return brentq(f, grid[k], grid[k + 1], xtol=1e-15)


def _beam_constants():
    area, second = np.pi * BEAM_R**2, np.pi * BEAM_R**4 / 4.0
    return BEAM_E * second, BEAM_RHO * area


def euler_bernoulli_omega(mass, inertia):
    """First angular frequency [rad/s] of the cantilever with the tip payload."""
    ei, rho_a = _beam_constants()
    beta = _first_root(lambda b: _tip_mass_determinant(b, mass, inertia, ei, rho_a, BEAM_L), 3.0 / BEAM_L)
    return beta**2 * np.sqrt(ei / rho_a)


def _payload_system(n, gravity=0.0):
    material = rodmol.Material(E=BEAM_E, nu=0.5, mu=0.0, rho=BEAM_RHO)
    beam = rodmol.Model(rodmol.Rod(BEAM_L, radius=BEAM_R, material=material), n)
    payload = rodmol.RigidBody(PAYLOAD_M, (1e-5, PAYLOAD_J, PAYLOAD_J), position=(BEAM_L, 0.0, 0.0))
    return rodmol.System({"beam": beam}, {"payload": payload},
                         [rodmol.Joint(("payload", (0.0, 0.0, 0.0)), ("beam", "tip"), kind="clamp")],
                         gravity=(0.0, -gravity, 0.0))


def _lowest_frequency(system):
    """The smallest nonzero |Im| of the eigenvalues of the assembly's
    Jacobian (central differences) at rest: the semi-discrete first
    bending frequency, free of any time-integration error."""
    assembly = Assembly(system)
    y, scale = assembly.undeformed_state(), assembly.atol_scale()
    jac = central_columns(lambda z: assembly(0.0, z).copy(), y, range(assembly.size), 1e-6 * scale)
    imag = np.abs(np.linalg.eigvals(jac).imag)
    return imag[imag > 1e-3].min()


def test_frequency_determinant_reproduces_the_closed_form_tip_mass_equation():
    # Without rotary inertia: 1 + cos cosh + mu bL (cos sinh - sin cosh) = 0, mu = M / (rho A L).
    ei, rho_a = _beam_constants()
    mu = PAYLOAD_M / (rho_a * BEAM_L)
    closed = _first_root(lambda x: 1 + np.cos(x) * np.cosh(x) + mu * x * (np.cos(x) * np.sinh(x) - np.sin(x)
                                                                            * np.cosh(x)), 3.0)
    assert euler_bernoulli_omega(PAYLOAD_M, 0.0) == pytest.approx(closed**2 * np.sqrt(ei / rho_a) / BEAM_L**2,
                                                                   rel=1e-12)
    assert euler_bernoulli_omega(PAYLOAD_M, PAYLOAD_J) < euler_bernoulli_omega(PAYLOAD_M, 0.0)  # J slows it


def test_payload_on_a_clamped_tip_swings_at_the_euler_bernoulli_frequency():
    reference = euler_bernoulli_omega(PAYLOAD_M, PAYLOAD_J)
    omega = {n: _lowest_frequency(_payload_system(n)) for n in (8, 16, 32)}
    orders = [np.log2(abs(omega[a] - omega[b]) / abs(omega[b] - omega[c])) for a, b, c in [(8, 16, 32)]]
    assert min(orders) >= 1.8  # measured 2.01: the joint's compliance, F / k with k ~ 1 / ds, is O(ds^2) too
    extrapolated = (4.0 * omega[32] - omega[16]) / 3.0
    # Measured -1.3e-4: the Cosserat rod's shear and its sections' rotary inertia, O((r / L)^2), which
    # Euler-Bernoulli leaves out.
    assert extrapolated / reference - 1.0 == pytest.approx(0.0, abs=3e-4)
    # Swinging under a small weight from straight: the payload's height oscillates about its static
    # deflection at the first frequency (a sinusoid fits it to 7e-4 of its range: the other modes are small).
    run = rodmol.simulate(_payload_system(16, gravity=0.5), 1.0, output_dt=0.005, rtol=1e-6)
    assert run.success and run.stats["linear_solver"] == "gmres"
    height = run["payload"].position[:, 1]

    def swing(t, mean, a, b, w):
        return mean + a * np.cos(w * t) + b * np.sin(w * t)

    fit, _ = curve_fit(swing, run.t, height, p0=(height.mean(), -height.mean(), 0.0, reference))
    assert np.ptp(height) > 0.01
    assert fit[3] == pytest.approx(omega[16], rel=1e-4)  # measured 1.8e-5
    gap = np.linalg.norm(run["beam"].integrated_positions[:, -1] - run["payload"].position, axis=1)
    assert gap.max() < 1e-8 * BEAM_L  # the joint's drift F / k


# ---------------------------------------------------------------- the parallel robot

LEG_L, LEG_R, LEG_E, LEG_RHO, LEG_NU = 0.2, 0.005, 2e8, 1000.0, 0.5
PLATFORM_M, PLATFORM_COM, BASE_RADIUS = 0.5, np.array([0.02, 0.01, 0.0]), 0.05
ROBOT_GRAVITY = np.array([-9.81, 0.0, -3.0])  # sideways and down: the legs bend and the platform tilts
UP = np.array([[0.0, 0.0, -1.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]])  # a leg's x axis along global z
LEG_POINTS = np.array([[BASE_RADIUS * np.cos(a), BASE_RADIUS * np.sin(a), 0.0]
                       for a in 2 * np.pi * np.arange(3) / 3 + 0.3])


def _hat(u):
    return np.array([[0.0, -u[2], u[1]], [u[2], 0.0, -u[0]], [-u[1], u[0], 0.0]])


@functools.cache  # two tests read it
def parallel_robot_shooting():
    """The platform's equilibrium pose (position [m], rotation vector) by
    shooting, after Till et al.: each leg a Cosserat rod ODE from its base,
    p' = R v, R' = R u^, n' = -rho A g, m' = -p' x n, with v = Kse^-1 R^T n
    + e1 and u = Kbt^-1 R^T m (global n, m); unknowns each leg's base n, m
    and the platform pose; equations each leg's tip meeting its platform
    point with the platform's orientation, and the platform's balance of
    forces and moments under its weight at its centre of mass."""
    g_mod = LEG_E / (2 * (1 + LEG_NU))
    area, second = np.pi * LEG_R**2, np.pi * LEG_R**4 / 4
    kse, kbt = np.array([LEG_E, g_mod, g_mod]) * area, np.array([2 * g_mod, LEG_E, LEG_E]) * second

    def rates(s, y):
        rot, n, m = y[3:12].reshape(3, 3), y[12:15], y[15:18]
        dp = rot @ (rot.T @ n / kse + np.array([1.0, 0.0, 0.0]))
        return np.concatenate([dp, (rot @ _hat(rot.T @ m / kbt)).ravel(), -LEG_RHO * area * ROBOT_GRAVITY,
                               -np.cross(dp, n)])

    def residual(x):
        position, rotation = x[18:21], Rotation.from_rotvec(x[21:24]).as_matrix()
        weight = PLATFORM_M * ROBOT_GRAVITY
        equations, force, moment = [], weight.copy(), np.cross(rotation @ PLATFORM_COM, weight)
        for i, point in enumerate(LEG_POINTS):
            start = np.concatenate([point, UP.ravel(), x[6 * i:6 * i + 6]])
            tip = solve_ivp(rates, (0.0, LEG_L), start, method="DOP853", rtol=1e-11, atol=1e-13).y[:, -1]
            p, rot, n, m = tip[:3], tip[3:12].reshape(3, 3), tip[12:15], tip[15:18]
            error = (rotation @ UP).T @ rot
            equations += [p - position - rotation @ point,
                          0.5 * np.array([error[2, 1] - error[1, 2], error[0, 2] - error[2, 0],
                                          error[1, 0] - error[0, 1]])]
            force -= n  # the leg pulls the platform with minus its tip's internal force
            moment += np.cross(p - position, -n) - m
        return np.concatenate(equations + [force, moment])

    guess = np.zeros(24)
    guess[18:21] = (0.0, 0.0, LEG_L)
    solution = root(residual, guess, method="hybr", options=dict(xtol=1e-13))
    assert solution.success and np.abs(solution.fun).max() < 1e-10
    return solution.x[18:21], solution.x[21:24]


def test_parallel_robot_settles_at_the_shooting_equilibrium():
    position, rotation = parallel_robot_shooting()
    # Kelvin-Voigt damping near critical for the platform's sway (about 30 rad/s); no effect at rest.
    material = rodmol.Material(E=LEG_E, nu=LEG_NU, mu=2e6, rho=LEG_RHO)
    leg = rodmol.Rod(LEG_L, radius=LEG_R, material=material)
    legs = {f"leg{i}": rodmol.Model(leg, 32, base=rodmol.BaseMotion(position=tuple(p), rotation=UP))
            for i, p in enumerate(LEG_POINTS)}
    platform = rodmol.RigidBody(PLATFORM_M, (1e-3, 1e-3, 2e-3), centre_of_mass=PLATFORM_COM,
                                position=(0.0, 0.0, LEG_L))
    joints = [rodmol.Joint(("platform", tuple(p)), (f"leg{i}", "tip")) for i, p in enumerate(LEG_POINTS)]
    system = rodmol.System(legs, {"platform": platform}, joints, gravity=tuple(ROBOT_GRAVITY))
    run = rodmol.simulate(system, 1.5, output_dt=0.05)
    assert run.success and run.stats["prec_solves"] < 2 * run.stats["rhs_evals"]  # GMRES: few iterations
    displacement = position - (0.0, 0.0, LEG_L)
    assert np.linalg.norm(displacement) > 0.05 * LEG_L  # a finite deflection: 12 mm sideways
    # Measured at N = 32: 1.2e-4 of the displacement, 2.6e-4 of the rotation (1.2e-2 and 7.6e-3 at N = 8):
    # the grid's error and what is left of the settling.
    np.testing.assert_allclose(run["platform"].position[-1], position, atol=1e-3 * np.linalg.norm(displacement))
    turned = Rotation.from_matrix(run["platform"].rotation[-1]).as_rotvec()
    np.testing.assert_allclose(turned, rotation, atol=1e-3 * np.linalg.norm(rotation))
    for i, point in enumerate(LEG_POINTS):
        held = run["platform"].position[-1] + run["platform"].rotation[-1] @ point
        assert np.linalg.norm(run[f"leg{i}"].integrated_positions[-1, -1] - held) < 1e-6 * LEG_L
    # The legs' Results record their joints' forces at each frame: settled, the platform's weight.
    tips = sum(run[f"leg{i}"].external_force[-1, -1] * run[f"leg{i}"].node_length[-1] for i in range(3))
    np.testing.assert_allclose(tips, PLATFORM_M * ROBOT_GRAVITY, atol=1e-3 * PLATFORM_M * 9.81)


# ---------------------------------------------------------------- loops and holds

def _soft_arm(n=6, tension=0.0):
    material = rodmol.Material(E=1e5, nu=0.5, mu=300.0, rho=1080.0)
    cables = [rodmol.Cable((0.005, 0.0), 0.2, tension=lambda t: tension * min(t / 0.05, 1.0))] if tension else []
    return rodmol.Model(rodmol.Rod(0.2, radius=0.01, material=material), n, cables=cables)


def test_closed_loop_between_two_free_bodies_keeps_zero_momentum():
    # Two arms from a free head to a free bar, both ends clamped: a loop with no world in it. One
    # arm's cable bends the loop; each joint's pair of wrenches is equal and opposite, the force
    # acting where the node is, so the momenta stay zero to the time integration's tolerance.
    head = rodmol.RigidBody(0.05, (2e-5, 3e-5, 4e-5))
    bar = rodmol.RigidBody(0.02, (1e-5, 1e-5, 1e-5), position=(0.22, 0.0, 0.0), centre_of_mass=(0.0, 0.02, 0.0))
    joints = [rodmol.Joint(("head", (0.02, 0.0, 0.0)), ("a", "base")),
              rodmol.Joint(("head", (0.02, 0.04, 0.0)), ("b", "base")),
              rodmol.Joint(("bar", (0.0, 0.0, 0.0)), ("a", "tip")),
              rodmol.Joint(("bar", (0.0, 0.04, 0.0)), ("b", "tip"), kind="pin")]
    system = rodmol.System({"a": _soft_arm(tension=0.3), "b": _soft_arm()}, {"head": head, "bar": bar}, joints,
                           gravity=(0.0, 0.0, 0.0))
    run = rodmol.simulate(system, 0.15, output_dt=0.01, rtol=1e-7)
    assert run.success
    assert np.abs(run["bar"].angular_velocity).max() > 0.1  # the loop moves
    linear, angular = run.momentum()
    scale = 1080.0 * np.pi * 1e-4 * 0.2 * np.abs(run["a"].velocity).max()
    assert np.abs(linear).max() < 1e-5 * scale and np.abs(angular).max() < 1e-5 * scale * 0.2
    tip = run["a"].integrated_positions[:, -1]
    assert np.linalg.norm(tip - run["bar"].position, axis=1).max() < 1e-5 * 0.2


def test_tip_jointed_to_the_world_or_a_fixed_body_is_the_rods_hold():
    # The world: the rod's own Hold (one law, one implementation); a fixed body at the tip's rest
    # pose: the same hold, its held point written by the assembly.
    model = _soft_arm(tension=0.3)
    alone = rodmol.simulate(model.replace(loads=[rodmol.Hold(0.2, "clamp")]), 0.1, initial="straight",
                            rtol=1e-7)
    post = rodmol.RigidBody(1.0, (1e-3, 1e-3, 1e-3), motion="fixed", position=(0.2, 0.0, 0.0))
    for bodies, end in (({}, "world"), ({"post": post}, ("post", (0.0, 0.0, 0.0)))):
        run = rodmol.simulate(rodmol.System({"arm": model}, bodies, [rodmol.Joint(end, ("arm", "tip"))]), 0.1,
                              rtol=1e-7)
        assert run.success
        np.testing.assert_allclose(run["arm"].positions, alone.positions, atol=1e-6 * 0.2)
    assert np.ptp(alone.positions[:, 3, 1]) > 1e-3  # the cable bends it between its held ends


def test_tip_clamped_to_a_driven_gripper_follows_it_and_settles_as_the_displaced_hold():
    # A gripper moves the tip 1 cm sideways in 0.5 s and stops: the rod settles where a Hold clamped
    # 1 cm aside holds it (its static equilibrium). In motion the joint's damping acts on the velocity
    # relative to the gripper: damping the absolute velocity would drag the tip c V / k = 2e-5 m behind.
    model = _soft_arm().replace(gravity=(0.0, 0.0, 0.0))

    def velocity(t):
        return (0.0, 0.02 * (1.0 - np.cos(2.0 * np.pi * t / 0.5)) if t < 0.5 else 0.0, 0.0)

    grip = rodmol.RigidBody(0.1, (1e-4, 1e-4, 1e-4), motion=rodmol.BaseMotion(velocity=velocity,
                                                                                position=(0.2, 0.0, 0.0)))
    system = rodmol.System({"arm": model}, {"grip": grip}, [rodmol.Joint(("grip", (0.0, 0.0, 0.0)), ("arm", "tip"))],
                           gravity=(0.0, 0.0, 0.0))
    run = rodmol.simulate(system, 2.0, output_dt=0.05, rtol=1e-7)
    assert run.success
    np.testing.assert_allclose(run["grip"].position[-1], (0.2, 0.01, 0.0), atol=1e-7)  # its pose integrated
    gap = np.linalg.norm(run["arm"].integrated_positions[:, -1] - run["grip"].position, axis=1)
    assert gap.max() < 2e-6  # measured 3.8e-7
    held = model.replace(loads=[rodmol.Hold(0.2, "clamp", position=(0.2, 0.01, 0.0))])
    rest = rodmol.simulate(held, 0.01, initial=rodmol.equilibrium(held))
    np.testing.assert_allclose(run["arm"].positions[-1], rest.positions[0], atol=1e-5 * 0.2)  # measured 7e-7 m


def test_two_half_beams_joined_at_their_tips_fall_as_one_clamped_clamped_beam():
    # Two cantilevers from opposite walls, their tips clamped to each other (each rod's hold held by
    # the other's node), against one rod of the whole span with its tip clamped by a Hold: at the middle
    # the two tip nodes' half cells make the one node's cell, so the grids match, and the runs agree.
    span, n = 0.5, 16
    material = rodmol.Material(E=1e7, nu=0.5, mu=7e4, rho=1000.0)
    half = rodmol.Rod(span / 2, radius=0.01, material=material)
    left = rodmol.Model(half, n // 2)
    right = rodmol.Model(half, n // 2, base=rodmol.BaseMotion(position=(span, 0.0, 0.0),
                                                                rotation=np.diag([-1.0, -1.0, 1.0])))
    system = rodmol.System({"left": left, "right": right}, joints=[rodmol.Joint(("left", "tip"), ("right", "tip"))],
                           gravity=(0.0, -9.81, 0.0))
    run = rodmol.simulate(system, 0.3, output_dt=0.02)
    assert run.success and run.stats["linear_solver"] == "gmres"
    whole = rodmol.Model(rodmol.Rod(span, radius=0.01, material=material), n, gravity=(0.0, -9.81, 0.0),
                         loads=[rodmol.Hold(span, "clamp")])
    one = rodmol.simulate(whole, 0.3, output_dt=0.02, initial="straight")
    middle = run["left"].integrated_positions[:, -1]
    assert -middle[:, 1].min() > 0.005  # it sags and swings
    np.testing.assert_allclose(middle, one.integrated_positions[:, n // 2], atol=2e-5)  # measured 1.2e-5 m
    np.testing.assert_allclose(run["right"].integrated_positions[:, -1], middle, atol=1e-5)  # the joint's gap
    # GMRES (the joint's blocks in its preconditioner) and the sparse direct solver: the same
    # trajectories to the time integration's error, which falls with the tolerance.
    for rtol, atol in ((1e-6, 2e-6), (1e-9, 3e-9)):  # measured 4.2e-7 and 1.4e-9 m (2.2e-10 m at 8x softer joints)
        runs = [rodmol.simulate(system, 0.3, output_dt=0.02, rtol=rtol, linsolver=lin) for lin in ("gmres", "sparse")]
        assert all(r.success for r in runs)
        for rod in ("left", "right"):
            np.testing.assert_allclose(runs[0][rod].integrated_positions, runs[1][rod].integrated_positions,
                                       rtol=0, atol=atol)


def test_rods_of_different_sections_joined_tip_to_tip_keep_zero_momentum():
    # Two free bodies, each carrying one rod, the rods' tips clamped to each other: a thin rod and one
    # of twice the radius. Each side's hold would take its own rod's law (k from E A / ds, k_r from the
    # radius): the joint shares one, so the pair stays equal and opposite and the momenta stay zero.
    material = rodmol.Material(E=1e5, nu=0.5, mu=300.0, rho=1080.0)
    pull = rodmol.Cable((0.005, 0.0), 0.2, tension=lambda t: 0.3 * min(t / 0.05, 1.0))
    thin = rodmol.Model(rodmol.Rod(0.2, radius=0.01, material=material), 4, cables=[pull])
    thick = rodmol.Model(rodmol.Rod(0.2, radius=0.02, material=material), 5)
    turn = np.diag([-1.0, -1.0, 1.0])
    bodies = {"left": rodmol.RigidBody(0.05, (2e-5, 3e-5, 4e-5)),
              "right": rodmol.RigidBody(0.05, (2e-5, 3e-5, 4e-5), position=(0.4, 0.0, 0.0))}
    joints = [rodmol.Joint(("left", (0.0, 0.0, 0.0)), ("thin", "base")),
              rodmol.Joint(("right", (0.0, 0.0, 0.0), turn), ("thick", "base")),
              rodmol.Joint(("thin", "tip"), ("thick", "tip"))]
    system = rodmol.System({"thin": thin, "thick": thick}, bodies, joints, gravity=(0.0, 0.0, 0.0))
    runs = [rodmol.simulate(system, 0.05, output_dt=0.01, rtol=1e-7, linsolver=lin) for lin in ("gmres", "sparse")]
    for run in runs:
        assert run.success
        linear, angular = run.momentum()
        scale = 1080.0 * np.pi * 1e-4 * 0.2 * np.abs(run["thin"].velocity).max()
        assert np.abs(run["thin"].velocity).max() > 1e-3  # it moves
        assert np.abs(linear).max() < 1e-5 * scale and np.abs(angular).max() < 1e-5 * scale * 0.2
    # A loop of rods and free bodies: GMRES and the sparse solver take the same trajectory to the tolerance.
    for rod in ("thin", "thick"):
        moved = np.abs(runs[1][rod].integrated_positions - runs[1][rod].integrated_positions[0]).max()
        difference = np.abs(runs[0][rod].integrated_positions - runs[1][rod].integrated_positions).max()
        assert difference < 1e-5 * moved, (rod, difference, moved)


def _parallel_robot(n, mu=2e6):
    material = rodmol.Material(E=LEG_E, nu=LEG_NU, mu=mu, rho=LEG_RHO)
    leg = rodmol.Rod(LEG_L, radius=LEG_R, material=material)
    legs = {f"leg{i}": rodmol.Model(leg, n, base=rodmol.BaseMotion(position=tuple(p), rotation=UP))
            for i, p in enumerate(LEG_POINTS)}
    platform = rodmol.RigidBody(PLATFORM_M, (1e-3, 1e-3, 2e-3), centre_of_mass=PLATFORM_COM,
                                position=(0.0, 0.0, LEG_L))
    joints = [rodmol.Joint(("platform", tuple(p)), (f"leg{i}", "tip")) for i, p in enumerate(LEG_POINTS)]
    return rodmol.System(legs, {"platform": platform}, joints, gravity=tuple(ROBOT_GRAVITY))


def test_parallel_robot_equilibrium_is_the_settled_pose_and_the_shooting_one():
    position, rotation = parallel_robot_shooting()
    system = _parallel_robot(8)
    rest = rodmol.equilibrium(system)
    part = Assembly(system).bodies["platform"]
    pose = rest[part.fields["x"]]
    turned = Rotation.from_quat(np.roll(rest[part.fields["Q"]], -1)).as_rotvec()
    displacement = position - (0.0, 0.0, LEG_L)
    # The grid's error at N = 8, measured: 1.23e-2 of the displacement, 7.5e-3 of the rotation (the
    # settled run's at N = 8, test above).
    assert np.linalg.norm(pose - position) < 2e-2 * np.linalg.norm(displacement)
    assert np.linalg.norm(turned - rotation) < 1.5e-2 * np.linalg.norm(rotation)
    # The settled run on the same grid: the same discrete statics, what is left of its settling.
    run = rodmol.simulate(system, 1.5, output_dt=0.5)
    assert run.success
    # Measured: 2.4e-5 of the displacement, 1.3e-4 of the rotation.
    np.testing.assert_allclose(run["platform"].position[-1], pose, atol=1e-4 * np.linalg.norm(displacement))
    settled = Rotation.from_matrix(run["platform"].rotation[-1]).as_rotvec()
    np.testing.assert_allclose(settled, turned, atol=5e-4 * np.linalg.norm(rotation))
    # Started from it, a run stays put (measured: 1.6e-12 of the displacement).
    still = rodmol.simulate(system, 0.1, initial="equilibrium", output_dt=0.05)
    assert still.success
    np.testing.assert_allclose(still["platform"].position, np.tile(pose, (len(still.t), 1)),
                               atol=1e-9 * np.linalg.norm(displacement))


def test_two_half_beams_joined_at_their_tips_rest_as_one_clamped_clamped_beam():
    # The equilibrium solves joined rods together: each alone would rest with its tip held where it
    # is at rest (the straight beam), 6 mm above the joined beams' sag.
    span, n = 0.5, 16
    material = rodmol.Material(E=1e7, nu=0.5, mu=7e4, rho=1000.0)
    half = rodmol.Rod(span / 2, radius=0.01, material=material)
    right = rodmol.BaseMotion(position=(span, 0.0, 0.0), rotation=np.diag([-1.0, -1.0, 1.0]))
    system = rodmol.System({"left": rodmol.Model(half, n // 2), "right": rodmol.Model(half, n // 2, base=right)},
                           joints=[rodmol.Joint(("left", "tip"), ("right", "tip"))], gravity=(0.0, -9.81, 0.0))
    rest = rodmol.equilibrium(system)
    parts = Assembly(system).parts
    middle = rodmol.StateLayout(n // 2).field(rest[parts["left"]], "u")[-1]
    whole = rodmol.Model(rodmol.Rod(span, radius=0.01, material=material), n, gravity=(0.0, -9.81, 0.0),
                         loads=[rodmol.Hold(span, "clamp")])
    one = rodmol.StateLayout(n).field(rodmol.equilibrium(whole), "u")[n // 2 - 1]
    assert middle[1] < -0.005
    np.testing.assert_allclose(middle, one, atol=2e-5)  # measured 6.3e-6 m
