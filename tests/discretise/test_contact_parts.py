"""Rods touching rigid bodies (rodmol.Contact, rodmol.discretise.contact_parts):
a ball resting on a clamped beam weighs on it with its weight on every solver
path, a rod pushing a free ball in zero gravity gives it the momentum it
loses, a fixed body's shape is the rod's fixed obstacle, the equilibrium of a
held ball on a beam is its settled run, and the Jacobian's pattern holds the
coupling."""

import numpy as np
import pytest

import rodmol
from rodmol.discretise.assembly import Assembly
from rodmol.discretise.contact_parts import ContactPart
from rodmol.discretise.rotations import matrices

G, L, RADIUS, N = 9.81, 0.2, 0.01, 10
BALL_R, BALL_M = 0.03, 0.02
MATERIAL = rodmol.Material(E=1e6, nu=0.5, mu=5e3, rho=1000.0)


def _beam(n=N, material=MATERIAL, **options):
    return rodmol.Model(rodmol.Rod(L, radius=RADIUS, material=material), n, **options)


def _ball(**options):
    return rodmol.RigidBody(BALL_M, (0.4 * BALL_M * BALL_R**2,) * 3, **options)


def _shape(stiffness=2e3, damping=100.0, **options):
    return rodmol.SphereContact((0.0, 0.0, 0.0), BALL_R, stiffness=stiffness, damping=damping, **options)


def _reaction(assembly, name, t, y):
    """(6,) the force [N] and moment [N m] about the origin of the rods' contacts on body ``name``, global."""
    part = assembly.bodies[name]
    body = assembly.body_state(part, t, y)
    total = np.zeros(6)
    for joint in part.joints:
        if not isinstance(joint, ContactPart):
            continue
        force, moment = joint.wrench(y, body, joint.row.copy(), joint.value.copy())
        total += (*force, *moment)
    rot = matrices(body[3:7])
    return np.concatenate([rot @ total[:3], np.cross(body[:3], rot @ total[:3]) + rot @ total[3:]])


def _ball_on_beam():
    # Clamped at both ends; the ball between the two nodes next to midspan (the rod's contact
    # sees its sections at the nodes: a ball on one node would roll off it).
    ball = _ball(position=(L / 2 + L / N / 2, RADIUS + BALL_R, 0.0))
    return rodmol.System({"beam": _beam()}, {"ball": ball}, [rodmol.Joint(("beam", "tip"), "world")],
                         contacts=[rodmol.Contact("ball", "beam", _shape())], gravity=(0.0, -G, 0.0))


# CVODE at rtol 1e-7: at its default (3e-5) the force at rest, which its error test does not see,
# carries its error (up to 9.5e-4 of the weight on the sparse path, with any stiffness of the tip's
# clamp from 1e5 to 1e7 N/m; 2e-5 and below at rtol 1e-8).
@pytest.mark.parametrize("options", [{"rtol": 1e-7}, {"linsolver": "sparse", "rtol": 1e-7}, {"backend": "galpha"}],
                         ids=["gmres", "sparse", "galpha"])
def test_ball_resting_on_a_clamped_beam_weighs_on_it_with_its_weight(options):
    system = _ball_on_beam()
    run = rodmol.simulate(system, 1.5, output_dt=0.25, **options)
    assert run.success
    assembly = Assembly(system)
    on_ball = np.array([_reaction(assembly, "ball", t, y)[:3] for t, y in zip(run.t, run.states)])
    beam = run["beam"]  # its contact forces as its Result records them, off the tip's hold
    on_beam = np.einsum("tni,n->ti", beam.external_force[:, 1:-1], beam.node_length[1:-1])
    weight = BALL_M * G
    assert np.abs(on_ball[1:, 1]).min() > 0.5 * weight  # in contact from the first frame on
    np.testing.assert_allclose(on_beam, -on_ball, atol=1e-6 * weight)
    np.testing.assert_allclose(on_ball[-1], [0.0, weight, 0.0], atol=2e-4 * weight)
    assert run["ball"].position[-1, 1] < RADIUS + BALL_R  # it pressed the beam down


@pytest.mark.parametrize("options", [{"rtol": 1e-7}, {"backend": "galpha"}], ids=["cvode", "galpha"])
def test_rod_pushing_a_free_ball_in_zero_gravity_gives_it_the_momentum_it_loses(options):
    # A cable curls an arm on a free head toward a free ball: a closed system, whose total
    # momentum stays zero while the ball gains some (the rod's force and the ball's are equal
    # and opposite, at the same point).
    tension = rodmol.Cable((0.005, 0.0), L, tension=lambda t: 2.0 * min(t / 0.05, 1.0))
    arm = _beam(n=8, cables=[tension])
    head = rodmol.RigidBody(0.05, (2e-5, 3e-5, 4e-5))
    ball = _ball(position=(L, RADIUS + BALL_R + 0.001, 0.003))
    shape = _shape(stiffness=1e3, damping=1.0, friction=0.3, slip_speed=1e-3)
    system = rodmol.System({"arm": arm}, {"head": head, "ball": ball}, [rodmol.Joint(("head", (0, 0, 0)), ("arm", "base"))],
                           contacts=[rodmol.Contact("ball", ["arm"], shape)], gravity=(0.0, 0.0, 0.0))
    run = rodmol.simulate(system, 0.3, output_dt=0.02, **options)
    assert run.success
    gained = BALL_M * np.abs(run["ball"].velocity).max()
    assert gained > 1e-4  # the ball was pushed
    assert np.abs(run["ball"].angular_velocity).max() > 0.1  # by friction too
    linear, angular = run.momentum()
    assert np.abs(linear).max() < 1e-4 * gained and np.abs(angular).max() < 1e-4 * gained * L


def test_a_fixed_body_is_the_rods_fixed_obstacle_exactly():
    # The shape placed by a fixed body at its pose (identity rotation) is the SphereContact
    # at that point: the same parameter rows, the same right-hand side, the same run.
    centre = np.array([0.15, -(RADIUS + BALL_R) + 0.004, 0.0])
    shape = _shape(friction=0.4)
    body = rodmol.RigidBody(1.0, (1e-3,) * 3, position=centre, motion="fixed")
    obstacle = rodmol.SphereContact(centre, BALL_R, stiffness=2e3, damping=100.0, friction=0.4)
    loaded = rodmol.System({"arm": _beam(loads=[obstacle])}, {"b": body}, gravity=(0.0, -G, 0.0))
    touched = rodmol.System({"arm": _beam()}, {"b": body}, gravity=(0.0, -G, 0.0),
                            contacts=[rodmol.Contact("b", "arm", shape)])
    runs = [rodmol.simulate(system, 0.2, output_dt=0.05) for system in (loaded, touched)]
    assert all(run.success for run in runs)
    assert np.abs(runs[0]["arm"].external_force).max() > 1.0  # it touched
    np.testing.assert_allclose(runs[1].states, runs[0].states, rtol=0, atol=1e-10)
    one, other = Assembly(loaded), Assembly(touched)
    for t, y in zip(runs[0].t, runs[0].states):
        np.testing.assert_array_equal(other(t, y), one(t, y))


def test_a_fixed_turned_body_carries_its_plane_where_its_pose_puts_it():
    # A floor given in the frame of a body turned about z and x: the rows are the floor's
    # to rounding, the right-hand side to 1e-10 (the depth's rounding over its millimetres),
    # the run to 1e-8 L.
    c, s = np.cos(0.4), np.sin(0.4)
    turn = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]) @ np.array([[1.0, 0.0, 0.0], [0.0, c, -s],
                                                                              [0.0, s, c]])
    origin, point, normal = np.array([0.1, -0.05, 0.02]), np.array([0.0, -0.006, 0.0]), np.array([0.0, 1.0, 0.1])
    floor = dict(stiffness=2e3, damping=100.0, friction=0.4)
    body = rodmol.RigidBody(1.0, (1e-3,) * 3, position=origin, rotation=turn, motion="fixed")
    loaded = rodmol.System({"arm": _beam(loads=[rodmol.PlaneContact(point, normal, **floor)])}, {"b": body},
                           gravity=(0.0, -G, 0.0))
    shape = rodmol.PlaneContact(turn.T @ (point - origin), turn.T @ normal, **floor)
    touched = rodmol.System({"arm": _beam()}, {"b": body}, gravity=(0.0, -G, 0.0),
                            contacts=[rodmol.Contact("b", "arm", shape)])
    runs = [rodmol.simulate(system, 0.2, output_dt=0.05, rtol=1e-9) for system in (loaded, touched)]
    assert all(run.success for run in runs)
    assert np.abs(runs[0]["arm"].external_force).max() > 1.0  # it touched
    one, other = Assembly(loaded), Assembly(touched)
    for t, y in zip(runs[0].t, runs[0].states):
        expected = one(t, y)
        np.testing.assert_allclose(other(t, y), expected, rtol=1e-10, atol=1e-10 * np.abs(expected).max())
    np.testing.assert_allclose(runs[1]["arm"].positions, runs[0]["arm"].positions, rtol=0, atol=1e-8 * L)


def test_a_rod_on_a_body_carried_along_with_it_slides_as_at_rest():
    # Galilean invariance: a cantilever lying with friction on a driven ball, its base, its nodes
    # and the ball all moving at V from the start, is the one at rest carried at V (no fluid:
    # nothing else reads the absolute velocity). The law's damping and friction act on the sliding relative to the
    # ball: on the absolute velocity the ball would brake the rod.
    speed = np.array([0.05, 0.0, 0.02])
    centre = np.array([0.15, -(RADIUS + BALL_R) + 0.002, 0.0])
    runs = []
    for v in (np.zeros(3), speed):
        ball = _ball(motion=rodmol.BaseMotion(lambda t, v=v: tuple(v), lambda t: (0.0, 0.0, 0.0), position=centre))
        arm = _beam(base=rodmol.BaseMotion(lambda t, v=v: tuple(v), lambda t: (0.0, 0.0, 0.0)))
        shape = _shape(friction=0.5, slip_speed=1e-3)
        system = rodmol.System({"arm": arm}, {"ball": ball}, contacts=[rodmol.Contact("ball", "arm", shape)],
                               gravity=(0.0, -G, 0.0))
        assembly = Assembly(system)
        y0, sd = assembly.undeformed_state(), assembly.rods["arm"]
        rod = y0[assembly.parts["arm"]]
        sd.layout.field(rod, "v")[:] = v  # moving with its base from the start (local = global: straight along x)
        y0[assembly.parts["arm"]] = rod
        runs.append(rodmol.simulate(system, 0.3, output_dt=0.05, rtol=1e-8, initial=y0))
    at_rest, carried = runs
    assert at_rest.success and carried.success
    assert np.abs(at_rest["arm"].external_force).max() > 1.0  # it lies on the ball
    shift = carried.t[:, None, None] * speed
    np.testing.assert_allclose(carried["arm"].positions - shift, at_rest["arm"].positions, atol=1e-6 * L)


def _held_ball_on_a_beam():
    # The ball hangs at the tip of a horizontal holder and rests on a clamped beam across under it.
    stiff = rodmol.Material(E=1e7, nu=0.5, mu=5e3, rho=1000.0)
    holder = _beam(n=6, material=stiff)
    ball = _ball(position=(L + BALL_R, 0.0, 0.0))
    across = rodmol.BaseMotion(position=(L + BALL_R, -(RADIUS + BALL_R) + 1e-3, -L / 2),
                               rotation=((0.0, 0.0, -1.0), (0.0, 1.0, 0.0), (1.0, 0.0, 0.0)))
    beam = _beam(n=6, material=stiff, base=across)
    return rodmol.System({"holder": holder, "beam": beam}, {"ball": ball},
                         [rodmol.Joint(("ball", (-BALL_R, 0.0, 0.0)), ("holder", "tip")),
                          rodmol.Joint(("beam", "tip"), "world")],
                         contacts=[rodmol.Contact("ball", "beam", _shape(stiffness=5e3))], gravity=(0.0, -G, 0.0))


def test_equilibrium_of_a_held_ball_on_a_beam_is_its_settled_run():
    system = _held_ball_on_a_beam()
    rest = rodmol.equilibrium(system)
    settled = rodmol.simulate(system, 2.0, output_dt=1.0, rtol=1e-9)
    assert settled.success
    assembly = Assembly(system)
    part = assembly.bodies["ball"]
    carried = _reaction(assembly, "ball", 0.0, rest)[1]
    assert carried > BALL_M * G  # the beam carries the ball and props the holder
    np.testing.assert_allclose(settled.states[-1, part.slice][:7], rest[part.slice][:7], atol=1e-7)
    np.testing.assert_allclose(_reaction(assembly, "ball", 2.0, settled.states[-1])[1], carried, rtol=1e-4)


def test_the_pattern_holds_every_entry_the_coupling_makes():
    # The contact rows of the beam's nodes read the ball's pose and velocities, the ball's
    # velocity rows the nodes' u, Q, v, w: full differences find nothing outside the pattern.
    system = _ball_on_beam()
    run = rodmol.simulate(system, 0.1, output_dt=0.1, linsolver="sparse")
    assembly = Assembly(system)
    y = run.states[-1].copy()
    y[assembly.bodies["ball"].fields["v"]] = (0.01, -0.02, 0.005)  # sliding: friction and damping read them
    y[assembly.bodies["ball"].fields["w"]] = (0.3, 0.2, -0.5)
    f0 = assembly(0.1, y).copy()
    pattern = assembly.pattern().toarray()
    seen = np.zeros_like(pattern)
    for j in range(assembly.size):
        z = y.copy()
        step = 1e-7 * max(abs(y[j]), 1e-2)
        z[j] += step
        seen[:, j] = np.abs(assembly(0.1, z) - f0) > 0.0
    body = assembly.bodies["ball"].slice
    assert seen[:body.start, body].any() and seen[body, :body.start].any()  # the coupling is there
    assert not (seen & ~pattern).any()


def test_a_contact_moves_its_rows_in_one_call_as_each_node_alone():
    # On the right-hand side the first node's part moves every row of its rod in one compiled
    # call and carries the total reaction; alone (scratch rows, a frame's replay) each part
    # moves its own row: the same rows and the same total.
    system = _ball_on_beam()
    assembly = Assembly(system)
    part = assembly.bodies["ball"]
    y = assembly.undeformed_state()
    y[part.fields["x"]] += (0.0, -0.003, 0.001)  # into the beam, moving and turning
    y[part.fields["v"]], y[part.fields["w"]] = (0.02, -0.01, 0.005), (0.3, -0.2, 0.5)
    body = assembly.body_state(part, 0.0, y)
    parts = [joint for joint in part.joints if isinstance(joint, ContactPart)]
    alone = [np.concatenate(joint.wrench(y, body, joint.row.copy(), joint.value.copy())) for joint in parts]
    scratch = [joint.row.copy() for joint in parts]
    for joint, row in zip(parts, scratch):
        joint.wrench(y, body, row, joint.value.copy())
    together = sum(np.concatenate(joint.wrench(y, body, joint.row, joint.value)) for joint in parts)
    np.testing.assert_array_equal([joint.row for joint in parts], scratch)
    assert sum(np.abs(a[:3]).max() > 0.0 for a in alone) >= 2  # two nodes touch
    np.testing.assert_allclose(together, np.sum(alone, axis=0), rtol=1e-14, atol=1e-16)


@pytest.mark.parametrize("kwargs, match", [
    (dict(contacts=[rodmol.Contact("cup", "beam", _shape())]), "body 'cup'"),
    (dict(contacts=[rodmol.Contact("ball", ("beam", "arm"), _shape())]), "rod 'arm'"),
    (dict(contacts=[_shape()]), r"contacts\[0\]"),
])
def test_contacts_naming_what_is_not_there_are_refused(kwargs, match):
    with pytest.raises(rodmol.ParameterError, match=match):
        rodmol.System({"beam": _beam()}, {"ball": _ball()}, **kwargs)


def test_a_contact_shape_must_be_a_contact_load():
    with pytest.raises(rodmol.ParameterError, match="shape"):
        rodmol.Contact("ball", "beam", rodmol.PointForce(0.1, (0.0, 1.0, 0.0)))
