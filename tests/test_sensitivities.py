"""Forward sensitivities (simulate(..., sensitivities=[keys]), rodmol.sensitivities) against
central differences of the public simulate at tight tolerances, for each kind of parameter,
on the paper's arm and on a System; and what they refuse before any work."""

import numpy as np
import pytest

import rodmol
from rodmol import named_parameters
from rodmol.errors import ParameterError

RUN = dict(rtol=1e-8, output_dt=0.05)
#: The reference: central differences of runs at this rtol, step REFERENCE_STEP * scale.
REFERENCE_RTOL, REFERENCE_STEP = 1e-10, 1e-3
#: The agreement asserted, relative to the largest derivative (measured: 1e-7 .. 4e-6).
AGREEMENT = 1e-4
KNOTS = [(0.0, 0.0), (0.2, 2.0), (0.5, 2.0)]


def _arm(knots=KNOTS):
    return rodmol.paper_arm(8, tensions={11: knots})


def _system():
    material = rodmol.Material(E=1e5, nu=0.5, mu=300.0, rho=1080.0)
    cable = rodmol.Cable((0.005, 0.0), 0.2, name="c", tension=[(0.0, 0.0), (0.1, 0.2)])
    arm = rodmol.Model(rodmol.Rod(0.2, radius=0.01, material=material), 6, cables=[cable])
    head = rodmol.RigidBody(0.05, (2e-5, 3e-5, 4e-5), centre_of_mass=(0.0, 0.004, 0.0))
    return rodmol.System({"arm": arm}, {"head": head}, [rodmol.Joint(("head", (0.02, 0.0, 0.01)), ("arm", "base"))],
                         gravity=(0.0, -9.81, 0.0), medium="water")


def _reference(model, key, component, t_end, field, **options):
    """d field / d p[component] by central differences of two runs of simulate."""
    p = named_parameters.parameter(model, key)
    h = REFERENCE_STEP * p.scale
    up, down = p.value.copy(), p.value.copy()
    up[component] += h
    down[component] -= h
    runs = [rodmol.simulate(p.at(model, v), t_end, **{**RUN, "rtol": REFERENCE_RTOL, **options}) for v in (up, down)]
    return (field(runs[0]) - field(runs[1])) / (2.0 * h)


def _agree(sensitivity, reference):
    error = np.max(np.abs(sensitivity - reference)) / np.max(np.abs(reference))
    print(f"relative error {error:.2e}")
    assert np.max(np.abs(reference)) > 0 and error < AGREEMENT


@pytest.fixture(scope="module")
def arm_run():
    return rodmol.simulate(_arm(), 0.5, initial="straight", sensitivities=["material.E", "medium.Cy,Cz", "tension.11",
                                                                           "material.mu"], **RUN)


@pytest.mark.parametrize("key, component", [("material.E", 0), ("medium.Cy,Cz", 0), ("tension.11", 1),
                                            ("tension.11", 2), ("material.mu", 0)])
def test_a_rods_sensitivities_are_central_differences_of_its_runs(arm_run, key, component):
    derivative = arm_run.sensitivity(key)
    knots = key.startswith("tension")
    for field in (lambda r: r.tip, lambda r: r.markers, lambda r: r.internal_moment):
        reference = _reference(_arm(), key, component, 0.5, field, initial="straight")
        _agree(field(derivative)[component] if knots else field(derivative), reference)


def test_a_knot_tensions_derivative_has_an_axis_over_its_knots(arm_run):
    derivative = arm_run.sensitivity("tension.11")
    t = arm_run.t
    assert derivative.tip.shape == (3, len(t), 3)
    # The tension at t is linear in the knot values: its derivative is each knot's hat function.
    hats = np.array([np.interp(t, [0.0, 0.2, 0.5], np.eye(3)[k]) for k in range(3)])
    np.testing.assert_allclose(derivative.tensions[:, :, 10], hats, atol=1e-6)
    np.testing.assert_allclose(derivative.t, t)
    # A knot after the last frame's time moves nothing before it, and the first frame is the rest shape.
    assert np.all(derivative.tip[:, 0] == 0.0)


def test_the_state_and_its_derivatives_are_the_plain_runs():
    plain = rodmol.simulate(_arm(), 0.5, initial="straight", linsolver="gmres", **RUN)
    with_sensitivities = rodmol.simulate(_arm(), 0.5, initial="straight", sensitivities=["material.E"], **RUN)
    np.testing.assert_allclose(with_sensitivities.tip, plain.tip, atol=1e-7 * 0.4)  # rtol L


def test_initial_sensitivities_of_the_equilibrium():
    knots = [(0.0, 0.5), (0.2, 2.0), (0.5, 2.0)]  # pulled at t = 0: the equilibrium depends on it
    run = rodmol.simulate(_arm(knots), 0.3, sensitivities=["material.E", "tension.11"], **RUN)
    for key, component in (("material.E", 0), ("tension.11", 0)):
        reference = _reference(_arm(knots), key, component, 0.3, lambda r: r.tip)
        tip = run.sensitivity(key).tip
        tip = tip[component] if key.startswith("tension") else tip
        _agree(tip[0], reference[0])  # the equilibrium's own
        _agree(tip, reference)


@pytest.fixture(scope="module")
def system_run():
    return rodmol.simulate(_system(), 0.3, sensitivities=["bodies.head.mass", "rods.arm.material.E",
                                                          "rods.arm.tension.c", "medium.Cy"], **RUN)


@pytest.mark.parametrize("key, component", [("bodies.head.mass", 0), ("rods.arm.material.E", 0),
                                            ("rods.arm.tension.c", 1), ("medium.Cy", 0)])
def test_a_systems_sensitivities_are_central_differences_of_its_runs(system_run, key, component):
    derivative = system_run.sensitivity(key)
    knots = "tension" in key
    for field in (lambda r: r["arm"].tip, lambda r: r["head"].position):
        reference = _reference(_system(), key, component, 0.3, field)
        _agree(field(derivative)[component] if knots else field(derivative), reference)


def test_rk23_integrates_the_same_sensitivities():
    keys = ["material.E"]
    cvode = rodmol.simulate(_arm(), 0.1, initial="straight", sensitivities=keys, **RUN)
    rk23 = rodmol.simulate(_arm(), 0.1, initial="straight", sensitivities=keys, backend="rk23", **RUN)
    _agree(rk23.sensitivity("material.E").tip, cvode.sensitivity("material.E").tip)


@pytest.mark.parametrize("options, words", [
    (dict(sensitivities=["discretization.n_elements"]), "structure"),
    (dict(sensitivities=["material.Q"]), "material.Q"),
    (dict(sensitivities=["medium.drag"]), "switch"),
    (dict(sensitivities="material.E"), "non-empty list"),
    (dict(sensitivities=[]), "non-empty list"),
    (dict(sensitivities=["material.E"], backend="galpha"), "backend='galpha'"),
    (dict(sensitivities=["material.E"], out="never-written"), "not streamed"),
    (dict(sensitivities=["material.E"], linsolver="band"), "linsolver"),
])
def test_what_sensitivities_cannot_do_is_refused_before_any_work(options, words, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    with pytest.raises(ParameterError, match=words):
        rodmol.simulate(_arm(), 0.5, **options)
    assert not (tmp_path / "never-written").exists()


def test_a_sensitivity_not_asked_for_is_refused_naming_those_that_were(arm_run):
    with pytest.raises(ParameterError, match="'material.rho'.*'material.E'"):
        arm_run.sensitivity("material.rho")


def test_a_run_that_fails_keeps_the_sensitivities_of_its_frames():
    def fails_late(t):
        if t > 0.2:
            raise RuntimeError("sensor lost")
        return 0.5

    arm = rodmol.paper_arm(8, tensions={11: KNOTS, 2: fails_late})
    with pytest.warns(RuntimeWarning, match="sensor lost"):
        run = rodmol.simulate(arm, 0.5, initial="straight", sensitivities=["material.E"], **RUN)
    assert not run.success and 0.15 <= run.t[-1] <= 0.2
    tip = run.sensitivity("material.E").tip
    assert tip.shape == run.tip.shape and np.all(np.isfinite(tip)) and np.any(tip != 0.0)
