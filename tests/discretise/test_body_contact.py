"""Contact of free rigid bodies with obstacles (rodmol.discretise.body_contact):
a sphere resting on the floor in water on every solver path, a box levelling
out on its four corners, a box sliding to a stop under Coulomb friction, a
bouncing sphere losing energy to the damping only, and the equilibrium of a
box on the floor held by a rod against its settled run."""

import numpy as np
import pytest

import rodmol
from rodmol.discretise.assembly import Assembly
from rodmol.discretise.body_contact import BodyContacts
from rodmol.discretise.rotations import from_rotation_vector, matrices

G, M, R, K, H = 9.81, 1.0, 0.05, 1e4, 1e-5  # gravity, mass [kg], size [m], stiffness [N/m], smoothing [m]
CRITICAL = 2.0 * np.sqrt(K * M)  # critical damping of the body on one point [N s/m]
BOX = np.array([(x, y, -R) for x in (-R, R) for y in (-R, R)])  # the bottom corners, body frame


def _system(body, medium=None, rods=None, joints=()):
    """``body`` as "body" with a short rod clamped to the world, away from it (a system holds a rod)."""
    if rods is None:
        material = rodmol.Material(E=1e6, nu=0.5, mu=1e3, rho=1000.0)
        rods = {"rod": rodmol.Model(rodmol.Rod(0.1, radius=0.01, material=material), 4,
                                    base=rodmol.BaseMotion(position=(0.0, 0.0, 1.0)))}
    return rodmol.System(rods, {"body": body}, joints, medium=medium, gravity=(0.0, 0.0, -G))


def _floor(damping=CRITICAL, friction=0.0):
    return rodmol.PlaneContact((0.0, 0.0, 0.0), (0.0, 0.0, 1.0), stiffness=K, damping=damping,
                               friction=friction, smoothing_depth=H)


def _box(contacts, **options):
    """A 1 kg cube of side 2R, origin at its centre, on its bottom corners."""
    return rodmol.RigidBody(M, (M * (2 * R) ** 2 / 6,) * 3, contacts=contacts, contact_points=BOX, **options)


def _body_states(system, run):
    """(n_t, 13) the body's (x, Q, v, w) at the frames of ``run``."""
    part = Assembly(system).bodies["body"]
    return run.states[:, part.slice], BodyContacts(system.bodies["body"])


@pytest.mark.parametrize("options", [{}, {"linsolver": "sparse"}, {"backend": "galpha", "rtol": 1e-8}, {"backend": "rk23"}],
                         ids=["gmres", "sparse", "galpha", "rk23"])
def test_sphere_rests_in_water_at_its_net_weight_over_the_stiffness(options):
    # Beyond the smoothing depth h the penalty is k (d - h/2): the sphere sinks until
    # k (d - h/2) is its weight less buoyancy, and the floor carries exactly that.
    volume = 4.0 / 3.0 * np.pi * R**3
    ball = rodmol.RigidBody(M, (0.4 * M * R * R,) * 3, volume=volume, contacts=(_floor(),),
                            contact_points=[(0.0, 0.0, 0.0)], contact_radius=R, position=(0.0, 0.0, R))
    system = _system(ball, medium="water")
    net = (M - system.medium.rho * volume) * G
    assert 0.4 * M * G < net < 0.6 * M * G  # buoyancy matters
    run = rodmol.simulate(system, 0.3, output_dt=0.1, **options)
    assert run.success
    depth = R - run["body"].position[-1, 2]
    np.testing.assert_allclose(depth, net / K + H / 2, rtol=1e-4)
    states, contacts = _body_states(system, run)
    np.testing.assert_allclose(contacts.forces(states[-1]), [(0.0, 0.0, net)], atol=1e-4 * net)


def test_tilted_box_levels_out_on_its_four_corners_carrying_a_quarter_each():
    tilt = matrices(from_rotation_vector((0.03, 0.02, 0.0)))
    box = _box((_floor(damping=CRITICAL / 2),), position=(0.0, 0.0, R + 0.004), rotation=tilt)
    system = _system(box)
    run = rodmol.simulate(system, 1.0, output_dt=0.1, rtol=1e-7)
    assert run.success
    assert run["body"].rotation[0][2, 2] < 1.0 - 1e-4  # it started tilted
    # (no law turns it about the vertical: the rocking leaves it a small yaw)
    np.testing.assert_allclose(run["body"].rotation[-1][:, 2], (0.0, 0.0, 1.0), atol=1e-8)
    np.testing.assert_allclose(run["body"].position[-1, 2], R - M * G / (4 * K) - H / 2, atol=1e-9)
    states, contacts = _body_states(system, run)
    np.testing.assert_allclose(contacts.forces(states[-1]), np.tile((0.0, 0.0, M * G / 4), (4, 1)),
                               atol=1e-5 * M * G)


def test_box_sliding_with_friction_decelerates_at_mu_g_and_stops():
    # Kinetic friction mu N on the four corners, whatever their shares of N = M g: the box slows at
    # mu g, stops at v0 / (mu g) after v0^2 / (2 mu g), and stays (below slip_speed it is viscous).
    mu, v0 = 0.5, 0.4
    box = _box((_floor(friction=mu),), position=(0.0, 0.0, R - M * G / (4 * K) - H / 2))
    system = _system(box)
    y0 = Assembly(system).undeformed_state()
    part = Assembly(system).bodies["body"]
    y0[part.fields["v"]] = (v0, 0.0, 0.0)
    stop = v0 / (mu * G)
    run = rodmol.simulate(system, 2.0 * stop, initial=y0, output_times=np.linspace(0.0, 2.0 * stop, 21), rtol=1e-7)
    assert run.success
    sliding = run.t < 0.9 * stop
    np.testing.assert_allclose(run["body"].velocity[sliding, 0], v0 - mu * G * run.t[sliding], atol=1e-4 * v0)
    states, contacts = _body_states(system, run)
    floor = np.array([contacts.forces(s).sum(axis=0) for s in states[sliding]])
    np.testing.assert_allclose(floor, np.tile((-mu * M * G, 0.0, M * G), (len(floor), 1)), atol=1e-4 * M * G)
    # Stopped, it rocks back from the pitch of the braking (the origin, R above the corners,
    # moves as R w_y) and settles: nothing slides.
    assert np.abs(run["body"].velocity[-1]).max() < 5e-4 * v0
    # Its centre of mass stops after v0^2 / (2 mu g), the box pitched forward by the braking
    # moment mu M g R over the corners' 4 K R^2; levelling, its origin moves back by R theta.
    pitch = mu * M * G * R / (4 * K * R**2)
    np.testing.assert_allclose(run["body"].position[-1, 0], v0**2 / (2 * mu * G) - R * pitch, rtol=1e-3)


def test_spinning_ball_set_down_rolls_off_at_two_sevenths_of_its_spin():
    # Friction acts at the surface point R below the centre and the normal force through the
    # centre, so the angular momentum about the contact line is kept: I w0 = I w + M R v, and
    # sliding stops at v = R w, v = I R w0 / (I + M R^2) = 2/7 R w0 for a solid ball.
    mu, w0 = 0.5, 20.0
    ball = rodmol.RigidBody(M, (0.4 * M * R * R,) * 3, contacts=(_floor(friction=mu),),
                            contact_points=[(0.0, 0.0, 0.0)], contact_radius=R,
                            position=(0.0, 0.0, R - M * G / K - H / 2))
    system = _system(ball)
    part = Assembly(system).bodies["body"]
    y0 = Assembly(system).undeformed_state()
    y0[part.fields["w"]] = (0.0, w0, 0.0)
    rolling = 2.0 / 7.0 * R * w0
    run = rodmol.simulate(system, 0.2, initial=y0, output_times=np.linspace(0.0, 0.2, 41), rtol=1e-7)
    assert run.success
    v = np.einsum("nij,nj->ni", run["body"].rotation, run["body"].velocity)[:, 0]  # global: the ball turns
    w = run["body"].angular_velocity[:, 1]  # about its y axis, the global one
    sliding = run.t < 0.9 * rolling / (mu * G)
    np.testing.assert_allclose(v[sliding], mu * G * run.t[sliding], atol=1e-4 * rolling)
    np.testing.assert_allclose(v[-5:], rolling, rtol=1e-4)
    np.testing.assert_allclose(w[-5:] * R, rolling, rtol=1e-4)


@pytest.mark.parametrize("damping", [0.0, 0.3 * CRITICAL])
def test_bouncing_sphere_loses_energy_to_the_damping_only(damping):
    ball = rodmol.RigidBody(M, (0.4 * M * R * R,) * 3, contacts=(_floor(damping=damping),),
                            contact_points=[(0.0, 0.0, 0.0)], contact_radius=R, position=(0.0, 0.0, R + 0.02))
    system = _system(ball)
    run = rodmol.simulate(system, 0.2, output_dt=0.002, rtol=1e-8, atol=1e-9)
    assert run.success
    states, contacts = _body_states(system, run)
    z, v = run["body"].position[:, 2], run["body"].velocity
    energy = M * G * z + 0.5 * M * (v**2).sum(axis=1) + [contacts.energy(s) for s in states]
    touching = z < R
    first = np.argmax(touching)
    left = first + np.argmax(~touching[first:])  # the first frame off the floor again
    flight = slice(left, left + np.argmax(touching[left:]) if touching[left:].any() else None)
    assert first > 0 and left > first and len(z[flight]) > 10
    if damping == 0.0:
        np.testing.assert_allclose(energy, energy[0], rtol=1e-5)
        np.testing.assert_allclose(z[flight].max(), R + 0.02, rtol=1e-4)
    else:
        assert np.all(np.diff(energy) < 1e-6 * energy[0])
        assert energy[-1] < energy[0] - 0.1 * M * G * 0.02
        assert z[flight].max() < R + 0.02 * 0.9


def test_equilibrium_of_a_box_on_the_floor_held_by_a_rod_agrees_with_the_settled_run():
    # A rod clamped to the world at one side of the box and to the box at its tip holds it
    # sideways (friction holds nothing at rest); the floor takes part of its weight.
    # Started near its rest depth: the law's stiffness is 0 at first touch, where the
    # continuation from the undeformed rod would begin.
    material = rodmol.Material(E=2e6, nu=0.5, mu=2e3, rho=1000.0)
    z0 = R - M * G / (4 * K) - H / 2
    rod = rodmol.Model(rodmol.Rod(0.2, radius=0.01, material=material), 6)
    rods = {"rod": rod.replace(base=rodmol.BaseMotion(position=(0.0, 0.0, z0)))}
    box = _box((_floor(),), position=(0.2 + R, 0.0, z0))
    joints = [rodmol.Joint(("body", (-R, 0.0, 0.0)), ("rod", "tip"))]
    system = _system(box, rods=rods, joints=joints)
    rest = rodmol.equilibrium(system)
    settled = rodmol.simulate(system, 3.0, output_dt=1.0, rtol=1e-9)
    assert settled.success
    part = Assembly(system).bodies["body"]
    start = rodmol.simulate(system, 0.2, initial=rest, output_dt=0.1)
    pose = rest[part.slice][:7]
    assert pose[2] < R - 1e-4  # in the floor
    np.testing.assert_allclose(settled.states[-1, part.slice][:7], pose, atol=1e-7)
    np.testing.assert_allclose(start.states[:, part.slice][:, :7], np.tile(pose, (len(start.t), 1)), atol=1e-9)
    assert np.abs(Assembly(system)(0.0, rest)).max() < 1e-6


def test_a_free_body_on_contacts_alone_has_no_rest_named_before_any_work():
    box = _box((_floor(),), position=(0.0, 0.0, R))
    with pytest.raises(rodmol.EquilibriumError, match="'body' is held by nothing.*contacts"):
        rodmol.equilibrium(_system(box))
