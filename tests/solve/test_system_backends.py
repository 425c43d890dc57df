"""The galpha and RK23 backends on systems of rods and a free body
(rodmol.solve.system_stepping): against CVODE, the energy and momentum kept
by the undamped midpoint rule, the system's Jacobian against dense
differences, and bad options refused as for a rod."""

import numpy as np
import pytest

import rodmol
from rodmol.discretise.assembly import Assembly
from rodmol.discretise.system_jacobian import SystemJacobian

GRAVITY_OFF = (0.0, 0.0, 0.0)
TILT = np.array([[1.0, 0.0, 0.0], [0.0, 0.8, -0.6], [0.0, 0.6, 0.8]])


def _head_with_two_arms(mu=300.0, tension=0.2, left=None):
    """Two 0.2 m arms, each pulled by a cable on its +y side (none if ``tension``
    is None; the left arm's ``left`` if given), clamped off a free 50 g head at
    different points and angles, in vacuum."""
    material = rodmol.Material(E=1e5, nu=0.5, mu=mu, rho=1080.0)
    arms, joints = {}, []
    for name, point, turn in (("right", (0.02, 0.0, 0.0), np.eye(3)),
                              ("left", (-0.02, 0.0, 0.01), np.diag([-1.0, -1.0, 1.0]) @ TILT)):
        pull = left if name == "left" and left is not None else tension
        cables = [] if pull is None else [rodmol.Cable((0.005, 0.0), 0.2, name="c", tension=pull)]
        arms[name] = rodmol.Model(rodmol.Rod(0.2, radius=0.01, material=material), 8, cables=cables)
        joints.append(rodmol.Joint(("head", point, turn), (name, "base")))
    head = rodmol.RigidBody(0.05, (2e-5, 3e-5, 4e-5), centre_of_mass=(0.0, 0.004, 0.0))
    return rodmol.System(arms, {"head": head}, joints, gravity=GRAVITY_OFF)


def _ramp(t):
    return 0.2 * min(t / 0.05, 1.0)


def test_rk23_agrees_with_cvode_on_a_free_head_with_two_pulled_arms():
    system = _head_with_two_arms(tension=_ramp)
    cvode = rodmol.simulate(system, 0.15, rtol=1e-7, output_dt=0.05)
    rk23 = rodmol.simulate(system, 0.15, rtol=1e-7, output_dt=0.05, backend="rk23")
    assert rk23.success and rk23.stats["steps"] > 0
    assert np.abs(cvode["head"].velocity).max() > 1e-3  # the head recoils
    for name in ("right", "left"):
        np.testing.assert_allclose(rk23[name].positions, cvode[name].positions, rtol=0, atol=1e-6 * 0.2)
    np.testing.assert_allclose(rk23["head"].velocity, cvode["head"].velocity, rtol=0, atol=1e-6)
    np.testing.assert_allclose(rk23["head"].angular_velocity, cvode["head"].angular_velocity, rtol=0, atol=1e-5)


def _energy(run):
    """Kinetic and strain energy [J] of the rods (nodes 1..N, rodmol.energy) and
    the head's kinetic energy (with the rods' base half cells it carries)."""
    assembly = run.assembly
    total = sum(rodmol.energy(sd.model, run[name])["total"] for name, sd in assembly.rods.items())
    part = assembly.bodies["head"]
    vw = run.states[:, np.r_[part.fields["v"], part.fields["w"]]]
    return total + 0.5 * np.einsum("ti,ij,tj->t", vw, part.rigid_mass, vw)


def test_undamped_midpoint_keeps_the_energy_and_momentum_and_converges_to_cvode():
    """Pulled, then released without cables and without viscosity: the
    implicit midpoint rule (rho_inf = 1) keeps the energy to 1e-8 (CVODE at
    rtol 1e-8 drifts by about 1e-6), the momentum as well as CVODE does (both
    drift by 5e-6 of the arms' m v: the measure's quadrature, not the
    schemes), and its swing converges to CVODE's at second order in dt
    (position errors 1.0e-4, 2.9e-5 m at dt = 1e-3, 5e-4 s)."""
    pulled = rodmol.simulate(_head_with_two_arms(mu=0.0), 0.03, rtol=1e-7, output_dt=0.03)
    free = _head_with_two_arms(mu=0.0, tension=None)

    def run(backend, **options):
        result = rodmol.simulate(free, 0.15, initial=pulled, output_dt=0.005, rtol=1e-8, backend=backend,
                                 **options)
        assert result.success
        return result

    cvode = run("cvode")
    coarse, fine = (run("galpha", rho_inf=1.0, dt=dt) for dt in (1e-3, 5e-4))
    assert fine.stats["linear_solver"] == "sparse" and fine.stats["steps"] == 240
    energy, energy_cvode = _energy(fine), _energy(cvode)
    assert energy[0] > 1e-4
    assert np.abs(energy / energy[0] - 1.0).max() < 1e-8
    assert np.abs(energy / energy[0] - 1.0).max() < np.abs(energy_cvode / energy_cvode[0] - 1.0).max() / 100

    def drift(result):
        return [np.abs(m - m[0]).max() for m in result.momentum()]

    for kept, reference in zip(drift(fine), drift(cvode)):
        assert kept < 1.5 * reference + 1e-10
        assert kept < 1e-5 * 1080.0 * np.pi * 1e-4 * 0.2 * 0.1  # the arm's mass times 0.1 m/s
    assert np.abs(cvode["head"].velocity).max() > 1e-2  # the head swings
    errors = [max(np.abs(r[name].positions - cvode[name].positions).max() for name in ("right", "left"))
              for r in (coarse, fine)]
    assert errors[1] < 2e-4 * 0.2
    assert errors[0] / errors[1] > 3.0  # second order: 4, less CVODE's own error
    np.testing.assert_allclose(fine["head"].velocity, cvode["head"].velocity, rtol=0, atol=5e-4)


def test_galpha_holds_a_payload_on_an_undamped_steel_beam_as_cvode_does():
    """A 0.3 kg payload held at the tip of an undamped 1 m beam (E = 1 GPa) by a
    penalty joint, swinging under gravity: its coupling blocks are in the
    sparse Newton matrix, and galpha follows CVODE's sparse run."""
    beam = rodmol.Model(rodmol.Rod(1.0, radius=0.01, material=rodmol.Material(E=1e9, nu=0.5, mu=0.0, rho=1000.0)),
                        10)
    body = rodmol.RigidBody(0.3, (1e-5, 2e-4, 2e-4), position=(1.0, 0.0, 0.0))
    joint = rodmol.Joint(("payload", (0.0, 0.0, 0.0)), ("beam", "tip"), stiffness=100.0 * 1e9 * np.pi * 1e-4 / 0.1)
    system = rodmol.System({"beam": beam}, {"payload": body}, [joint], gravity=(0.0, -0.5, 0.0))
    cvode = rodmol.simulate(system, 0.2, rtol=1e-6, output_dt=0.05, linsolver="sparse")
    galpha = rodmol.simulate(system, 0.2, rtol=1e-6, output_dt=0.05, backend="galpha", dt=1e-3)
    assert galpha.success
    assert np.abs(cvode["payload"].position[:, 1]).max() > 1e-4  # it sags and swings
    np.testing.assert_allclose(galpha["beam"].positions, cvode["beam"].positions, rtol=0, atol=2e-6)
    np.testing.assert_allclose(galpha["payload"].position, cvode["payload"].position, rtol=0, atol=2e-6)


def test_system_jacobian_matches_dense_differences():
    """The coloured differences on the assembly's pattern give every entry of
    the dense one-column-at-a-time differences: the pattern and the colouring hold."""
    assembly = Assembly(_head_with_two_arms(tension=_ramp))
    y = rodmol.simulate(assembly.system, 0.04, rtol=1e-6, output_dt=0.04).states[-1]
    scale = assembly.atol_scale()
    jacobian = SystemJacobian(assembly, scale)
    assert len(jacobian.groups) < assembly.size / 4
    fy = assembly(0.04, y).copy()
    dense = np.empty((assembly.size, assembly.size))
    for j in range(assembly.size):
        z = y.copy()
        step = np.sqrt(np.finfo(float).eps) * max(abs(y[j]), scale[j])
        z[j] += step
        dense[:, j] = (assembly(0.04, z) - fy) / step
    np.testing.assert_allclose(jacobian.dense(0.04, y), dense, rtol=1e-6, atol=1e-6 * np.abs(dense).max())


@pytest.mark.parametrize("backend", ["rk23", "galpha", "cvode"])
def test_an_overloaded_arm_stops_the_run_naming_it(backend):
    """Every rod's state is watched on its own part: the left arm, pulled by
    100 N, turns by more than a quarter turn per element and the run ends
    there with the frames before, naming it."""
    system = _head_with_two_arms(left=lambda t: 100.0 * min(t / 0.05, 1.0))
    with pytest.warns(RuntimeWarning, match=r"rod 'left': element \d+ turns by"):
        run = rodmol.simulate(system, 0.2, output_dt=0.01, backend=backend)
    assert not run.success and 0.0 < run.t[-1] < 0.05
    assert np.all(np.isfinite(run.states))


@pytest.mark.parametrize("backend, option, value, words", [
    ("galpha", "dt", 0.0, "`dt` must be > 0"),
    ("galpha", "rho_inf", 1.5, "`rho_inf` must lie in [0, 1], got 1.5"),
    ("galpha", "rhoinf", 0.5, "did you mean 'rho_inf'"),
    ("galpha", "dt", 1e-9, "asks for 1e+08 steps"),
    ("rk23", "linsolver", "sparse", "unknown option `linsolver` for backend 'rk23'"),
])
def test_bad_options_are_refused_as_for_a_rod(backend, option, value, words):
    with pytest.raises(rodmol.ParameterError) as info:
        rodmol.simulate(_head_with_two_arms(), 0.1, backend=backend, **{option: value})
    assert words in str(info.value)
