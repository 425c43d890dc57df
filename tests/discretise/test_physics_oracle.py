"""The compiled right-hand side against the independent numpy oracle
(tests/oracle.py), and each compiled physics function against a direct formula.

The states are generic: a perturbed equilibrium (or straight rod) with
non-unit quaternions, nonzero velocities and, for contact models, nodes placed
outside, inside the smoothing layer and deep in the obstacle, some of them
moving away fast enough that the damping cancels the penalty.
"""

import numpy as np
import oracle
import pytest

import rodmol
from rodmol.arm import paper_rod
from rodmol.discretise import external, physics
from rodmol.discretise import system as system_module
from rodmol.discretise.schemes import SCHEMES

L = paper_rod().length
WAVY_BASE = rodmol.BaseMotion(
    velocity=lambda t: np.array([0.02 * np.sin(3 * t), 0.05 * np.cos(2 * t), -0.01]),
    angular_velocity=lambda t: np.array([0.3 * np.cos(t), -0.2, 0.1 * t]))
generic_state = oracle.generic_state
CONTACT_LAW = dict(stiffness=2e4, damping=40.0, friction=0.6, slip_speed=1e-3)


def _distributed(s, t):
    return np.stack([0.1 * np.sin(s / L + t), -0.3 * s / L, 0.05 * np.cos(2 * t) + 0 * s], axis=1)


def _models():
    arm = rodmol.paper_arm
    tilted = np.array([0.0, np.cos(0.3), np.sin(0.3)])
    timoshenko = rodmol.Rod(0.3, 0.01, rodmol.Material(E=2e5, G=2e3, mu=50.0, rho=1100.0))
    return {
        "paper arm, cables": arm(9, tensions={11: 1.0, 3: 0.5}),
        "paper arm, no cables, air": arm(6, medium="air"),
        "routed cables (helix, knots, spacer disks)": rodmol.Model(paper_rod(), 8, medium="water", cables=[
            rodmol.Cable(lambda s: (0.003 * np.cos(20 * s), 0.003 * np.sin(20 * s)), 0.3, 0.8, name="helix"),
            rodmol.Cable([(0.0, 0.008, 0.0), (0.2, 0.002, 0.001), (0.4, 0.0, 0.002)], L, 0.5, name="knots"),
            rodmol.Cable((0.0, 0.03), 0.25, 0.3, name="disks", outside_body=True)]),
        "friction (routed, moving base)": rodmol.Model(paper_rod(), 8, medium="water", base=WAVY_BASE, cables=[
            rodmol.Cable((0.006, 0.002), 0.3, 1.2, name="a", friction=0.3, slip_speed=0.01),
            rodmol.Cable([(0.0, -0.008, 0.0), (L, -0.002, 0.002)], L, 0.7, name="b", friction=0.1),
            rodmol.Cable((0.0, 0.005), 0.2, 0.4, name="c")]),
        "componentwise drag": arm(7, tensions={11: 1.0}, drag_law="componentwise",
                                  drag_coefficients=(0.3, 2.0, 5.0)),
        "per-component viscosity": rodmol.Model(rodmol.Rod(0.3, (0.01, 0.006), rodmol.Material(
            E=2e5, nu=0.3, mu=40.0, rho=1100.0, viscosity=dict(shear_extension=(0.0, 5.0, 7.0)))), 7,
            cables=[rodmol.Cable((0.0, 0.004), 0.25, 0.4)]),
        "moving base": arm(8, tensions={11: 1.0}, base=WAVY_BASE),
        "Munk moment": arm(7, tensions={7: 0.8, 2: 0.3}, munk_moment=True),
        "timed tensions (knots, callable)": arm(6, tensions={1: [(0.0, 0.0), (1.0, 2.0)],
                                                             10: lambda t: 0.4 + 0.1 * t}),
        "precurved, pretwisted and stretched rod (points, callable), routed cable": rodmol.Model(
            rodmol.Rod(0.3, (0.01, 0.006), rodmol.Material(E=2e5, nu=0.4, mu=40.0, rho=1100.0),
                       rest_curvature=lambda s: np.stack([2.0 + 0 * s, -3.0 * s, 4.0 + 10.0 * s], axis=-1),
                       rest_stretch=[(0.0, 1.05, 0.01, -0.02), (0.3, 0.95, -0.01, 0.03)]), 7,
            medium="water", cables=[rodmol.Cable(lambda s: (0.003 * np.cos(20 * s), 0.003 * np.sin(20 * s)),
                                                 0.25, 0.6, name="helix")]),
        "Timoshenko rod, G given, buoyancy only": rodmol.Model(timoshenko, 7, medium_density=500.0,
                                                               cables=[rodmol.Cable((0.0, 0.004), 0.3, 0.4)]),
        "point loads, global": arm(8, loads=[rodmol.PointForce(0.37 * L, (0.1, -0.2, 0.05)),
                                              rodmol.PointMoment(L, (0.01, 0.02, -0.03))]),
        "point loads, local": arm(8, loads=[rodmol.PointForce(L, (0.1, -0.2, 0.05), frame="local"),
                                             rodmol.PointMoment(0.51 * L, (0.01, 0.02, -0.03),
                                                                frame="local")]),
        "distributed loads, global": arm(7, loads=[rodmol.DistributedForce(_distributed),
                                                    rodmol.DistributedMoment((0.01, 0.0, -0.02))]),
        "distributed loads, local": arm(7, loads=[
            rodmol.DistributedForce((0.2, 0.1, -0.1), frame="local"),
            rodmol.DistributedMoment(lambda s, t: np.outer(1 + s, [0.01, -0.02, t]), frame="local")]),
        "time-dependent point loads (knots, callable)": arm(6, tensions={11: 0.5}, loads=[
            rodmol.PointForce(0.8 * L, [(0.0, 0.0, 0.0, 0.0), (0.5, 0.3, -0.2, 0.1), (2.0, 0.0, 0.1, 0.0)]),
            rodmol.PointMoment(0.2 * L, lambda t: np.array([0.01 * t, 0.0, -0.02]), frame="local"),
            rodmol.PointForce(0.5 * L, [(0.0, 1.0, 0.0, 0.0), (1.0, 0.0, 1.0, 0.0)], frame="local")]),
        "plane contact": arm(10, medium="air", loads=[
            rodmol.PlaneContact((0.0, -0.02, 0.0), tilted, **CONTACT_LAW)]),
        "plane contact, given smoothing depth": arm(8, loads=[
            rodmol.PlaneContact((0.0, -0.02, 0.0), (0.0, 1.0, 0.0), smoothing_depth=2e-4, **CONTACT_LAW)]),
        "sphere contact": arm(10, loads=[rodmol.SphereContact((0.2, -0.05, 0.0), 0.03, **CONTACT_LAW)]),
        "capsule contact": arm(10, base=WAVY_BASE, loads=[
            rodmol.CapsuleContact((0.05, -0.04, -0.05), (0.35, -0.04, 0.06), 0.02, **CONTACT_LAW)]),
    }


MODELS = _models()


def assert_rates_agree(got, expected, n, rtol):
    """Field by field (u, Q, q, k, v, w and the header), relative to each field's size."""
    lay = rodmol.StateLayout(n)
    worst = 0.0
    for name in ("u", "Q", "q", "k", "v", "w"):
        a, b = lay.field(got, name), lay.field(expected, name)
        scale = np.max(np.abs(b))
        err = np.max(np.abs(a - b)) / scale if scale > 0 else np.max(np.abs(a))
        assert err <= rtol, (name, err)
        worst = max(worst, err)
    np.testing.assert_allclose(got[:7], expected[:7], rtol=rtol, atol=1e-300)
    return worst


@pytest.mark.parametrize("scheme", list(SCHEMES))
@pytest.mark.parametrize("name", list(MODELS))
def test_compiled_rhs_equals_oracle(name, scheme):
    model = MODELS[name]
    system = rodmol.SemiDiscrete(model, scheme)
    rng = np.random.default_rng(sum(map(ord, name)))
    worst = 0.0
    for t in (0.0, 0.37, 1.3):
        y = generic_state(model, rng)
        got = system(t, y, np.full(y.size, np.nan))
        expected = oracle.rates(model, t, y, scheme=scheme)
        worst = max(worst, assert_rates_agree(got, expected, model.n_elements, 1e-10))
    print(f"{name}: worst field-relative difference {worst:.2e}")


def test_oracle_sees_contact_in_every_regime():
    """The states above do exercise the contact law: nodes outside, in the
    smoothing layer, beyond it, and with the damping cancelling the penalty."""
    model = MODELS["plane contact"]
    data = oracle.Sampled(model)
    rng = np.random.default_rng(5)
    y = generic_state(model, rng)
    u = rodmol.StateLayout(model.n_elements).field(y, "u")
    depth, _ = oracle.contact_geometry(model.loads[0], u, data.radius)
    h = 0.01 * data.radius
    assert np.any(depth < 0) and np.any((depth > 0) & (depth < h)) and np.any(depth > h)
    system = rodmol.SemiDiscrete(model)
    _, loads = system.frames([0.0], [y])
    assert np.count_nonzero(np.linalg.norm(loads[0, :, :3], axis=1)) >= 2


def test_contact_loads_are_recorded_as_the_oracle_computes_them():
    model = MODELS["capsule contact"]
    system = rodmol.SemiDiscrete(model, "upwind")
    y = generic_state(model, np.random.default_rng(2))
    _, loads = system.frames([0.4], [y])
    fld = oracle.unpack(y, model.n_elements)
    f, m = oracle.external_loads(model, oracle.Sampled(model), 0.4, fld["Q"], fld["u"], fld["v"], fld["w"])
    np.testing.assert_allclose(loads[0, :, :3], f, rtol=1e-12, atol=1e-12 * np.max(np.abs(f)))
    np.testing.assert_allclose(loads[0, :, 3:], m, rtol=1e-12, atol=1e-12 * np.max(np.abs(m)))
    assert np.max(np.abs(f)) > 0


def test_oracle_constants_are_the_systems():
    assert oracle.RESTORING == system_module.QUATERNION_RESTORING_RATE
    assert oracle.DRAG_SMOOTHING_SPEED == system_module.DRAG_SMOOTHING_SPEED
    from rodmol import loads
    assert oracle.SMOOTHING_FRACTION == loads.SMOOTHING_FRACTION


def test_compiled_rhs_accepts_read_only_and_writable_states():
    model = MODELS["paper arm, cables"]
    system = rodmol.SemiDiscrete(model)
    y = generic_state(model, np.random.default_rng(0))
    frozen = y.copy()
    frozen.flags.writeable = False  # as CVODE hands it over
    np.testing.assert_array_equal(system(0.2, y), system(0.2, frozen))


def test_rates_of_frames_match_single_calls():
    model = MODELS["moving base"]
    system = rodmol.SemiDiscrete(model)
    rng = np.random.default_rng(3)
    t = np.array([0.0, 0.5, 1.0])
    states = np.array([generic_state(model, rng) for _ in t])
    rates = system.rates(t, states)
    for i in range(3):
        np.testing.assert_array_equal(rates[i], system(t[i], states[i]))


def test_tensions_match_the_model():
    model = MODELS["timed tensions (knots, callable)"]
    system = rodmol.SemiDiscrete(model)
    for t in (0.0, 0.3, 0.999, 1.0, 7.0):
        np.testing.assert_allclose(system.tensions(t, None), model.tensions(t), rtol=1e-15)


@pytest.mark.parametrize("name", ["paper arm, cables", "timed tensions (knots, callable)", "feedback and constant"])
def test_tension_history_is_the_tensions_frame_by_frame(name):
    # A constant is read once for all frames, so the history must still match the
    # frame-by-frame evaluation (feedback laws read each frame's own state).
    model = MODELS.get(name) or rodmol.paper_arm(6, tensions={2: 0.7, 11: lambda t, state: 1.0 + state.tip[1] * t})
    system = rodmol.SemiDiscrete(model)
    rng = np.random.default_rng(5)
    t = np.array([0.0, 0.4, 1.3])
    states = np.array([generic_state(model, rng) for _ in t])
    expected = np.array([system.tensions(ti, yi) for ti, yi in zip(t, states)])
    assert np.any(np.ptp(expected, axis=0) > 0) == (name != "paper arm, cables")  # some vary in time
    np.testing.assert_array_equal(system.tension_history(t, states), expected)
    assert system.tension_history(t[:0], states[:0]).shape == (0, len(model.cables))


# ----------------------------------------------------------------------------- unit tests

RNG = np.random.default_rng(42)


def _vec():
    return tuple(float(x) for x in RNG.normal(size=3))


def _close(got, expected, rtol=1e-14):
    np.testing.assert_allclose(np.asarray(got, dtype=float), np.asarray(expected, dtype=float),
                               rtol=rtol, atol=rtol * max(1.0, float(np.max(np.abs(expected)))))


def test_vector_helpers():
    a, b = _vec(), _vec()
    _close(physics.cross(a, b), np.cross(a, b))
    _close(physics.dot(a, b), np.dot(a, b))
    _close(physics.add(a, b), np.add(a, b))
    _close(physics.sub(a, b), np.subtract(a, b))
    _close(physics.scale(2.5, a), 2.5 * np.array(a))
    _close(physics.mul(a, b), np.multiply(a, b))


def test_rotation_and_frame_changes():
    quat = tuple(float(x) for x in 1.7 * RNG.normal(size=4))  # not unit: normalised on the fly
    r = oracle.rotation_matrices(np.array(quat))
    got = np.array(physics.rotation(quat)).reshape(3, 3)
    _close(got, r)
    _close(got @ got.T, np.eye(3))
    x = _vec()
    _close(physics.to_global(tuple(got.ravel()), x), r @ x)
    _close(physics.to_local(tuple(got.ravel()), x), r.T @ x)


def test_quaternion_rate():
    quat = tuple(float(x) for x in RNG.normal(size=4))
    w = _vec()
    _close(physics.quaternion_rate(quat, w, 1.0), oracle.quaternion_rate(np.array(quat), np.array(w)))
    # The kinematic part is Q (x) (0, w) / 2.
    from rodmol.discretise import rotations
    pure = rotations.multiply(np.array(quat), np.array([0.0, *w])) / 2
    _close(physics.quaternion_rate(quat, w, 0.0), pure)


def test_strain_rate_terms():
    q, k, v, w = _vec(), _vec(), _vec(), _vec()
    tq, tk = physics.strain_rate_terms(q, k, v, w)
    _close(tq, np.cross(k, v) - np.cross(w, q))
    _close(tk, np.cross(k, w))


def test_kelvin_voigt():
    kl, kth, vl, vth = (tuple(abs(x) for x in _vec()) for _ in range(4))
    q, k, q_t, k_t, rest_q, rest_k = _vec(), _vec(), _vec(), _vec(), _vec(), _vec()
    n, m = physics.kelvin_voigt(kl, kth, vl, vth, q, k, q_t, k_t, rest_q, rest_k)
    _close(n, np.multiply(kl, np.subtract(q, rest_q)) + np.multiply(vl, q_t))
    _close(m, np.multiply(kth, np.subtract(k, rest_k)) + np.multiply(vth, k_t))


def test_cable_stress():
    q = (1.02, 0.01, -0.03)
    k, p, dp = _vec(), (0.0, 0.004, -0.002), (0.0, 0.03, 0.01)
    n_a, m_a = physics.cable_stress(q, k, p, dp, 1.7)
    c = np.array(q) + np.cross(k, p) + dp
    _close(n_a, 1.7 * c / np.linalg.norm(c))
    _close(m_a, np.cross(p, 1.7 * c / np.linalg.norm(c)))


def test_body_force_and_torque():
    mass, inertia, added, drag = (tuple(abs(x) for x in _vec()) for _ in range(4))
    quat = tuple(float(x) for x in RNG.normal(size=4))
    r = tuple(np.array(physics.rotation(quat)))
    rm = np.array(r).reshape(3, 3)
    g, v, w = (0.0, -9.81, 0.0), _vec(), _vec()
    f = physics.body_force(mass, 0.3, drag, r, g, v, w, 1e-12)
    speed = np.sqrt(np.dot(v, v) + 1e-12)
    _close(f, -np.cross(w, np.multiply(mass, v)) + 0.3 * rm.T @ g - speed * np.multiply(drag, v))
    gyro = -np.cross(w, np.multiply(inertia, w))
    _close(physics.body_torque(inertia, added, False, v, w), gyro)
    _close(physics.body_torque(inertia, added, True, v, w), gyro - np.cross(v, np.multiply(added, v)))


def _contact_row(kind, geometry, radius=0.01, smoothing=1e-4, law=(2e4, 40.0, 0.6, 1e-3)):
    row = np.zeros(external.N_PARAMS)
    row[:len(geometry)] = geometry
    row[external.P_STIFFNESS:external.P_SLIP + 1] = law
    row[external.P_RADIUS], row[external.P_SMOOTHING] = radius, smoothing
    return row


def test_contact_depth_plane_and_capsule():
    n = np.array([0.0, 0.6, 0.8])
    plane = _contact_row(external.PLANE, [0.1, 0.2, 0.3, *n])
    u = (0.5, 0.2, 0.3 + 0.005)
    depth, normal = external.contact_depth(external.PLANE, plane, u)
    _close(depth, 0.01 - n @ (np.array(u) - [0.1, 0.2, 0.3]))
    _close(normal, n)
    capsule = _contact_row(external.CAPSULE, [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.05])
    for u, closest in (((0.3, 0.04, 0.02), (0.3, 0, 0)), ((-0.2, 0.01, 0.0), (0, 0, 0)),
                       ((1.5, 0.0, -0.03), (1, 0, 0))):
        d = np.subtract(u, closest)
        depth, normal = external.contact_depth(external.CAPSULE, capsule, u)
        _close(depth, 0.05 + 0.01 - np.linalg.norm(d))
        _close(normal, d / np.linalg.norm(d))
    sphere = _contact_row(external.CAPSULE, [0.2, 0.0, 0.0, 0.2, 0.0, 0.0, 0.05])
    depth, normal = external.contact_depth(external.CAPSULE, sphere, (0.2, 0.03, 0.04))
    _close(depth, 0.06 - 0.05)
    _close(normal, (0.0, 0.6, 0.8))


def test_penalty_is_c1():
    h = 1e-3
    for d in (-1e-3, 0.0, 0.3e-3, 1e-3, 5e-3):
        _close(external.penalty(d, h), [float(x) for x in oracle.penalty(d, h)])
    # Force and slope continuous at first touch and at the smoothing depth.
    eps = 1e-9
    for d0 in (0.0, h):
        lo, hi = external.penalty(d0 - eps, h), external.penalty(d0 + eps, h)
        assert abs(hi[0] - lo[0]) < 1e-8 and abs(hi[1] - lo[1]) < 1e-5


def test_contact_energy_integrates_the_penalty():
    row = _contact_row(external.PLANE, [0.0, 0.0, 0.0, 0.0, 1.0, 0.0])
    h, k = row[external.P_SMOOTHING], row[external.P_STIFFNESS]
    for depth in (0.5 * h, h, 7 * h):
        u = (0.0, 0.01 - depth, 0.0)
        x = np.linspace(0.0, depth, 20001)
        measure, _ = oracle.penalty(x, h)
        _close(external.contact_energy(external.PLANE, row, u), k * np.trapezoid(measure, x), rtol=1e-7)
    assert external.contact_energy(external.PLANE, row, (0.0, 0.02, 0.0)) == 0.0
    assert external.contact_energy(external.DEAD_FORCE, row, (0.0, 0.0, 0.0)) == 0.0


@pytest.mark.parametrize("kind", [external.PLANE, external.CAPSULE])
def test_contact_law(kind):
    geometry = ([0.0, -0.02, 0.0, 0.0, 1.0, 0.0] if kind == external.PLANE
                else [-0.1, -0.05, 0.0, 0.3, -0.05, 0.0, 0.04])
    row = _contact_row(kind, geometry)
    obstacle = (rodmol.PlaneContact(geometry[:3], geometry[3:6], 2e4, 40.0, 0.6, 1e-3, 1e-4)
                if kind == external.PLANE else
                rodmol.CapsuleContact(geometry[:3], geometry[3:6], geometry[6], 2e4, 40.0, 0.6, 1e-3, 1e-4))

    class Data:
        radius = np.array([0.01])

    for depth in (-1e-4, 0.5e-4, 3e-3):
        quat = tuple(float(x) for x in RNG.normal(size=4))
        r = np.array(physics.rotation(quat)).reshape(3, 3)
        u = (0.1, -0.02 + 0.01 - depth, 0.003) if kind == external.PLANE else (0.1, -0.05 + 0.05 - depth, 0.0)
        v, w = (0.05, 0.01, -0.02), (0.3, -0.2, 0.5)
        f, m = external.contact(kind, row, u, tuple(r.ravel()), v, w)
        ef, em = oracle.contact_loads(obstacle, Data, np.array([u]), r[None], np.array([v]), np.array([w]))
        _close(f, ef[0], 1e-13)
        _close(m, em[0], 1e-13)
        if depth < 0 or depth > 1e-3:  # (shallow: the damping may cancel the penalty)
            assert (np.linalg.norm(f) > 0) == (depth > 0)
        # load() dispatches contact kinds to contact()
        lf, lm = external.load(kind, row, (0.0, 0.0, 0.0), u, quat, v, w)
        _close(lf, f)
        _close(lm, m)


def test_contact_releases_when_damping_exceeds_penalty():
    row = _contact_row(external.PLANE, [0.0, 0.0, 0.0, 0.0, 1.0, 0.0])
    ident = (1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0)
    u = (0.0, 0.01 - 2e-4, 0.0)  # penetrates by twice the smoothing depth
    f, m = external.contact(external.PLANE, row, u, ident, (0.0, 10.0, 0.0), (0.0, 0.0, 0.0))
    assert f == (0.0, 0.0, 0.0) and m == (0.0, 0.0, 0.0)


def test_point_and_distributed_load_kinds():
    quat = tuple(float(x) for x in RNG.normal(size=4))
    r = np.array(physics.rotation(quat)).reshape(3, 3)
    value, zero, p = _vec(), np.zeros(3), np.zeros(external.N_PARAMS)
    u, v, w = _vec(), _vec(), _vec()
    for kind, (ef, em) in {external.FOLLOWER_FORCE: (value, zero), external.FOLLOWER_MOMENT: (zero, value),
                           external.DEAD_FORCE: (r.T @ value, zero),
                           external.DEAD_MOMENT: (zero, r.T @ value)}.items():
        f, m = external.load(kind, p, value, u, quat, v, w)
        _close(f, ef)
        _close(m, em)


def test_dependency_tables_of_the_kinds():
    assert external.dependency_table([]) == {}
    assert external.dependency_table([external.FOLLOWER_FORCE]) == {}
    table = external.dependency_table([external.DEAD_FORCE, external.PLANE])
    assert set(table["v"][0]) == {"u", "Q", "v", "w"} and table["v"] == table["w"]


@pytest.mark.parametrize("name", [n for n in MODELS if MODELS[n].loads or MODELS[n].munk_moment
                                  or not MODELS[n].base.fixed])
def test_the_comparison_sees_the_loads(name, monkeypatch):
    """Without its loads (or Munk moment, or base motion) the oracle would disagree:
    the agreement above is not blind to them."""
    model = MODELS[name]
    system = rodmol.SemiDiscrete(model)
    y = generic_state(model, np.random.default_rng(1))
    got = system(0.37, y)
    if model.loads:
        monkeypatch.setattr(oracle, "external_loads",
                            lambda model, data, *a: (np.zeros((data.n, 3)), np.zeros((data.n, 3))))
    elif model.munk_moment:
        monkeypatch.setattr(model, "munk_moment", False)
    else:
        monkeypatch.setattr(model, "base", rodmol.BaseMotion())
    with pytest.raises(AssertionError):
        assert_rates_agree(got, oracle.rates(model, 0.37, y), model.n_elements, 1e-6)
