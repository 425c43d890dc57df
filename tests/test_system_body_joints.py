"""Joints of bodies (rodmol.Joint between two bodies or a body and the
world) and pinned rod bases: a compound pendulum against its period, two
bodies clamped together against the one body of their combined mass
properties, a free body clamped to the world against the fixed body, a
simply supported beam against the beam formulas and the static
equilibrium of a pinned-clamped beam against its settled run."""

import numpy as np
import pytest

import rodmol
from rodmol.discretise.assembly import Assembly
from rodmol.discretise.rotations import matrices

GRAVITY = 9.81


def _far_rod():
    """A short rod hanging from a point far from the bodies (a system holds at least one rod), damped
    to rest at once (its swing would set the time steps); it sets the body joints' default frequency."""
    material = rodmol.Material(E=1e6, nu=0.5, mu=1e4, rho=1000.0)
    down = ((0.0, 1.0, 0.0), (-1.0, 0.0, 0.0), (0.0, 0.0, 1.0))  # its x axis along -y, with gravity
    return rodmol.Model(rodmol.Rod(0.1, radius=0.01, material=material), 4,
                        base=rodmol.BaseMotion(position=(1.0, 0.0, 0.0), rotation=down))


def _turn_z(angle):
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def _angle_z(rotations):
    return np.arctan2(rotations[:, 1, 0], rotations[:, 0, 0])


def _downward_crossings(t, angle):
    """Times [s] where ``angle`` falls through zero (linear between frames)."""
    return np.array([t[i] - angle[i] * (t[i + 1] - t[i]) / (angle[i + 1] - angle[i])
                     for i in range(len(t) - 1) if angle[i] > 0.0 >= angle[i + 1]])


# A pendulum body: its origin the pivot, its centre of mass d below it.
PEND_M, PEND_D, PEND_IC = 0.5, 0.1, 2e-3


def test_a_body_pinned_to_the_world_off_its_centre_swings_with_the_compound_pendulum_period():
    amplitude = 0.05
    pendulum = rodmol.RigidBody(PEND_M, (PEND_IC,) * 3, centre_of_mass=(0.0, -PEND_D, 0.0),
                                rotation=_turn_z(amplitude))
    system = rodmol.System({"far": _far_rod()}, {"pendulum": pendulum},
                           [rodmol.Joint(("pendulum", (0.0, 0.0, 0.0)), "world", kind="pin")])
    i_pivot = PEND_IC + PEND_M * PEND_D**2
    # The small-oscillation period, with the amplitude's first correction (1 + a^2 / 16).
    period = 2.0 * np.pi * np.sqrt(i_pivot / (PEND_M * GRAVITY * PEND_D)) * (1.0 + amplitude**2 / 16.0)
    result = rodmol.simulate(system, 1.3 * period, output_dt=period / 400, rtol=1e-9)
    assert result.success, result.message
    angle = _angle_z(result["pendulum"].rotation)
    downward = _downward_crossings(result.t, angle)  # at a quarter and five quarters of a period
    assert len(downward) == 2
    assert abs((downward[1] - downward[0]) / period - 1.0) < 1e-4
    assert np.max(np.abs(angle)) <= amplitude * (1.0 + 1e-6)  # no damping drives it, no energy gained
    # The pivot drifts by the joint's load over its stiffness, m g / (m omega^2), well below a micron.
    assert np.max(np.linalg.norm(result["pendulum"].position, axis=1)) < 1e-6


def test_two_bodies_clamped_together_swing_as_one_body_of_their_combined_mass_properties():
    m_a, m_b, i_a, i_b = PEND_M, 0.3, PEND_IC, 5e-4
    c_a, c_b = np.array([0.0, -PEND_D, 0.0]), np.array([0.0, -2.0 * PEND_D, 0.0])  # the pivot's frame
    start = _turn_z(0.4)  # a large swing: the clamp holds both bodies' turning as one
    a = rodmol.RigidBody(m_a, (i_a,) * 3, centre_of_mass=c_a, rotation=start)
    b = rodmol.RigidBody(m_b, (i_b, i_b, 2 * i_b), position=start @ c_b, rotation=start)
    pair = rodmol.System({"far": _far_rod()}, {"a": a, "b": b},
                         [rodmol.Joint(("a", (0.0, 0.0, 0.0)), "world", kind="pin"),
                          rodmol.Joint(("a", c_b), ("b", (0.0, 0.0, 0.0)))])
    mass = m_a + m_b
    centre = (m_a * c_a + m_b * c_b) / mass
    shift = [np.sum((c - centre) ** 2) * np.eye(3) - np.outer(c - centre, c - centre) for c in (c_a, c_b)]
    inertia = i_a * np.eye(3) + m_a * shift[0] + np.diag((i_b, i_b, 2 * i_b)) + m_b * shift[1]
    one = rodmol.System({"far": _far_rod()}, {"a": rodmol.RigidBody(mass, inertia, centre_of_mass=centre,
                                                                    rotation=start)},
                        [rodmol.Joint(("a", (0.0, 0.0, 0.0)), "world", kind="pin")])
    runs = [rodmol.simulate(s, 0.5, output_dt=0.01, rtol=1e-9) for s in (pair, one)]
    assert all(run.success for run in runs)
    angles = [_angle_z(run["a"].rotation) for run in runs]
    assert np.ptp(angles[1]) > 0.7  # it swings through
    np.testing.assert_allclose(angles[0], angles[1], atol=2e-6)
    # b's origin stays at a's point (the clamp's drift) and turns with a.
    rotations = runs[0]["a"].rotation
    np.testing.assert_allclose(runs[0]["b"].position, rotations @ c_b, atol=1e-6)  # F / k: 6.1e-7 m
    np.testing.assert_allclose(runs[0]["b"].rotation, rotations, atol=1e-6)


def _wall_system(motion, joint=()):
    arm = rodmol.Model(rodmol.Rod(0.2, radius=0.01, material=rodmol.Material(E=1e5, nu=0.5, mu=100.0,
                                                                              rho=1000.0)), 8)
    wall = rodmol.RigidBody(1.0, (1e-3, 1e-3, 1e-3), motion=motion, position=(0.0, 0.1, 0.0))
    return rodmol.System({"arm": arm}, {"wall": wall},
                         [rodmol.Joint(("wall", (0.0, -0.1, 0.0)), ("arm", "base")), *joint])


def test_a_free_body_clamped_to_the_world_moves_its_rod_as_the_fixed_body_does():
    # The default clamp (k = m omega^2 = 1.6e7 N/m for the 1 kg wall) and one 100 times as stiff.
    clamped = [_wall_system("free", [rodmol.Joint(("wall", (0.0, 0.0, 0.0)), "world", stiffness=k)])
               for k in (None, 1.6e9)]
    runs = [rodmol.simulate(s, 0.2, output_dt=0.02, rtol=1e-7) for s in (*clamped, _wall_system("fixed"))]
    assert all(run.success for run in runs)
    tips = [run["arm"].tip for run in runs]
    assert np.max(np.abs(tips[2][:, 1])) > 5e-3  # the arm sags and swings
    # The clamp's compliance: 8.6e-7 m, then 1.2e-8 m.
    np.testing.assert_allclose(tips[0], tips[2], atol=2e-6)
    np.testing.assert_allclose(tips[1], tips[2], atol=1e-7)
    # The wall sinks by its weight over the stiffness, 6.1e-7 m, then 100 times less.
    np.testing.assert_allclose(runs[0]["wall"].position, runs[2]["wall"].position, atol=7e-7)
    np.testing.assert_allclose(runs[1]["wall"].position, runs[2]["wall"].position, atol=7e-9)


# A stiff slender beam under its own weight: a sag of 5e-5 m, 5e-3 of its radius, so that the
# stretching a sag between two fixed pins needs (membrane force ~ (sag / r)^2) stays below 1e-4.
BEAM_L, BEAM_R, BEAM_E, BEAM_RHO = 1.0, 0.01, 1e11, 1000.0


def _beam(n, tip, mu=1e9, young=BEAM_E):
    material = rodmol.Material(E=young, nu=0.5, mu=mu, rho=BEAM_RHO)
    model = rodmol.Model(rodmol.Rod(BEAM_L, radius=BEAM_R, material=material), n)
    return rodmol.System({"beam": model}, joints=[rodmol.Joint(("beam", "base"), "world", kind="pin"),
                                                  rodmol.Joint(("beam", "tip"), "world", kind=tip)],
                         gravity=(0.0, -GRAVITY, 0.0))


def _beam_load(young=BEAM_E):
    """(w [N/m], EI [N m^2]) of the beam."""
    return BEAM_RHO * np.pi * BEAM_R**2 * GRAVITY, young * np.pi * BEAM_R**4 / 4.0


def _end_angles(system, y):
    """(base, tip) section angles about z [rad] of the state ``y``, and the nodes' positions."""
    assembly = Assembly(system)
    sd, base = assembly.rods["beam"], assembly.bodies["beam.base"]
    rod = y[assembly.parts["beam"]]
    tip = matrices(sd.layout.quaternions(rod)[-1])
    base = matrices(y[base.fields["Q"]])
    return np.arctan2(base[1, 0], base[0, 0]), np.arctan2(tip[1, 0], tip[0, 0]), sd.layout.integrated_positions(rod)


def test_a_beam_pinned_at_both_ends_sags_as_the_simply_supported_beam():
    n = 16
    system = _beam(n, "pin")
    w, ei = _beam_load()
    sag, slope = 5.0 * w * BEAM_L**4 / (384.0 * ei), w * BEAM_L**3 / (24.0 * ei)
    runs = [rodmol.simulate(system, 0.3, output_dt=0.3, rtol=1e-8, linsolver=lin) for lin in ("gmres", "sparse")]
    assert all(run.success for run in runs)
    base, tip, nodes = _end_angles(system, runs[0].states[-1])
    # The grid's error at N = 16 (second order: 2.4e-2, 5.9e-3, 1.1e-3 at N = 8, 16, 32); a clamped
    # base would sag 2/5 as far and turn by half.
    assert abs(-nodes[n // 2, 1] / sag - 1.0) < 1e-2
    assert abs(-base / slope - 1.0) < 1e-2 and abs(tip / slope - 1.0) < 1e-2
    assert abs(base + tip) < 1e-3 * slope  # symmetric
    # Sparse LU agrees (GMRES's preconditioner takes the pinned base's coupling to its rod), to
    # CVODE's tolerance on the sag (the positions' absolute tolerance, rtol L, is 2e-4 of it).
    base_lu, tip_lu, nodes_lu = _end_angles(system, runs[1].states[-1])
    np.testing.assert_allclose([base_lu, tip_lu], [base, tip], rtol=1e-3)
    np.testing.assert_allclose(nodes_lu[:, 1], nodes[:, 1], atol=1e-3 * sag)


@pytest.mark.filterwarnings("ignore::RuntimeWarning")
def test_the_equilibrium_of_a_pinned_clamped_beam_is_its_settled_run():
    system = _beam(8, "clamp")
    at_rest = rodmol.equilibrium(system)
    settled = rodmol.simulate(system, 0.3, output_dt=0.3, rtol=1e-9).states[-1]
    base, tip, nodes = _end_angles(system, at_rest)
    base_run, tip_run, nodes_run = _end_angles(system, settled)
    w, ei = _beam_load()
    assert abs(-base / (w * BEAM_L**3 / (48.0 * ei)) - 1.0) < 5e-2  # the propped cantilever's, at N = 8
    assert abs(tip) < 1e-2 * abs(base)  # clamped: 7.6e-3 of the base's at N = 8
    np.testing.assert_allclose(nodes[:, 1], nodes_run[:, 1], atol=1e-4 * np.max(np.abs(nodes[:, 1])))
    assert abs(base_run / base - 1.0) < 1e-4


def test_the_fixed_step_and_explicit_backends_swing_the_pendulum_as_cvode():
    pendulum = rodmol.RigidBody(PEND_M, (PEND_IC,) * 3, centre_of_mass=(0.0, -PEND_D, 0.0), rotation=_turn_z(0.3))
    system = rodmol.System({"far": _far_rod()}, {"pendulum": pendulum},
                           [rodmol.Joint(("pendulum", (0.0, 0.0, 0.0)), "world", kind="pin")])
    # 0.02 s: RK23's steps are bounded by the rods' and the joint's fastest modes (1.6e4 steps for 0.1 s).
    runs = {backend: rodmol.simulate(system, 0.02, output_dt=0.01, backend=backend, **options)
            for backend, options in (("cvode", dict(rtol=1e-8)), ("galpha", dict(dt=5e-4)), ("rk23", {}))}
    assert all(run.success for run in runs.values())
    angles = {backend: _angle_z(run["pendulum"].rotation) for backend, run in runs.items()}
    assert angles["cvode"][-1] < 0.3 - 3e-3  # it swings down (by 4e-3 rad)
    np.testing.assert_allclose(angles["rk23"], angles["cvode"], atol=1e-6)
    np.testing.assert_allclose(angles["galpha"], angles["cvode"], atol=1e-6)
