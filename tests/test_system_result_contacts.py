"""A body's recorded contact forces (BodyResult contact_force, rod_contact_force):
a ball resting on a floor carries its weight less buoyancy, a ball resting on a
beam feels minus the beam's recorded contact forces, and a run streamed to
files and a finished run written out read back the same arrays."""

import numpy as np
import pytest

import rodmol

G, L, RADIUS, N = 9.81, 0.2, 0.01, 8
BALL_R, BALL_M = 0.03, 0.02
MATERIAL = rodmol.Material(E=1e6, nu=0.5, mu=5e3, rho=1000.0)


def _beam(n=N):
    return rodmol.Model(rodmol.Rod(L, radius=RADIUS, material=MATERIAL), n)


def _ball(mass=BALL_M, radius=BALL_R, **options):
    return rodmol.RigidBody(mass, (0.4 * mass * radius**2,) * 3, **options)


def _ball_on_beam():
    # Clamped at its base, held at its tip; the ball between the two nodes next to midspan.
    ball = _ball(position=(L / 2 + L / N / 2, RADIUS + BALL_R, 0.0))
    shape = rodmol.SphereContact((0.0, 0.0, 0.0), BALL_R, stiffness=2e3, damping=100.0)
    return rodmol.System({"beam": _beam()}, {"ball": ball}, [rodmol.Joint(("beam", "tip"), "world")],
                         contacts=[rodmol.Contact("ball", "beam", shape)], gravity=(0.0, -G, 0.0))


def test_a_ball_resting_on_a_floor_records_its_weight_less_buoyancy():
    mass, radius = 1.0, 0.05
    volume = 4.0 / 3.0 * np.pi * radius**3
    floor = rodmol.PlaneContact((0.0, -0.2, 0.0), (0.0, 1.0, 0.0), stiffness=1e4, damping=200.0)
    # Turned, so that the body frame is not the global one.
    turn = np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])
    ball = _ball(mass, radius, volume=volume, position=(0.3, -0.2 + radius, 0.0), rotation=turn,
                 contacts=[floor], contact_points=[(0.0, 0.0, 0.0)], contact_radius=radius)
    system = rodmol.System({"arm": _beam(2)}, {"ball": ball}, medium="water", gravity=(0.0, -G, 0.0))
    run = rodmol.simulate(system, 0.4, output_dt=0.1)
    assert run.success
    b = run["ball"]
    on_ball = np.einsum("nij,nj->ni", b.rotation, b.contact_force)  # global
    resting = (mass - system.medium.rho * volume) * G  # weight less buoyancy [N]
    np.testing.assert_allclose(on_ball[-1], [0.0, resting, 0.0], rtol=1e-4, atol=1e-9 * resting)
    np.testing.assert_allclose(b.contact_moment[-1], 0.0, atol=1e-9)  # through the centre, no friction
    assert not np.any(b.rod_contact_force)  # no rod touches it


@pytest.fixture(scope="module")
def ball_on_beam():
    system = _ball_on_beam()
    return system, rodmol.simulate(system, 0.6, output_dt=0.1)


def test_a_ball_on_a_beam_feels_minus_the_beams_recorded_contact_forces(ball_on_beam):
    _, run = ball_on_beam
    assert run.success
    ball, beam = run["ball"], run["beam"]
    on_ball = np.einsum("nij,nj->ni", ball.rotation, ball.rod_contact_force)  # global
    # The beam's contact forces as its Result records them, off the clamp and the tip's hold.
    on_beam = np.einsum("tni,n->ti", beam.external_force[:, 1:-1], beam.node_length[1:-1])
    weight = BALL_M * G
    assert np.abs(on_ball[1:, 1]).min() > 0.3 * weight  # in contact from the first frame on
    np.testing.assert_allclose(on_ball, -on_beam, rtol=0, atol=1e-9 * weight)
    np.testing.assert_allclose(on_ball[-1], [0.0, weight, 0.0], atol=2e-2 * weight)
    # Normal forces only (no friction), along lines through the ball's centre: no moment about it.
    np.testing.assert_allclose(ball.rod_contact_moment, 0.0, atol=1e-9 * weight * BALL_R)
    assert not np.any(ball.contact_force)  # no obstacle of its own


def test_a_streamed_run_and_a_written_one_read_back_the_same_contact_forces(ball_on_beam, tmp_path):
    system, run = ball_on_beam
    streamed = rodmol.simulate(system, 0.6, output_dt=0.1, out=tmp_path / "streamed")
    rodmol.write_series(run, tmp_path / "written")
    fields = ("contact_force", "contact_moment", "rod_contact_force", "rod_contact_moment")
    for result in (streamed, rodmol.load_result(tmp_path / "streamed"), rodmol.load_result(tmp_path / "written")):
        for field in fields:
            np.testing.assert_array_equal(getattr(result["ball"], field), getattr(run["ball"], field))
    assert np.any(run["ball"].rod_contact_force)
