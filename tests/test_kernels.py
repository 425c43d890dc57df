"""The compiled right-hand side, Jacobian and block preconditioner against the
numpy reference, the solvers built on them, and the spatial order of the scheme.
"""

import numpy as np
import pytest

import rodmol
from rodmol.discretise import jacobian
from rodmol.discretise import upwind as kernels
from rodmol.arm import paper_rod
from rodmol.solve.backends import cvode, rk23
from rodmol.errors import ParameterError
from rodmol.discretise.system import SemiDiscrete
from rodmol.simulate import default_atol

pytestmark = pytest.mark.skipif(not kernels.AVAILABLE, reason="numba is not installed")

WAVY_BASE = rodmol.BaseMotion(velocity=lambda t: np.array([0.02 * np.sin(3 * t), 0.05 * np.cos(2 * t), -0.01]),
                        angular_velocity=lambda t: np.array([0.3 * np.cos(t), -0.2, 0.1 * t]))


def _feedback(t, state):
    # The equilibrium hands state=None; afterwards the tip height feeds back.
    return 0.5 + (0.0 if state is None else 3.0 * abs(state.tip[1]))


def _models():
    rod = paper_rod()
    L = rod.length
    return {
        "water, one cable (bending)": rodmol.scenarios.get("bending").model(12),
        "water, three cables held": rodmol.scenarios.get("fetching").model(9),
        "air, no cables": rodmol.Model(rod, 7, medium="air"),
        # Anchors between nodes (a fractional cell) and exactly at the tip.
        "anchors between nodes and at the tip": rodmol.Model(
            rod, 10, medium="water",
            cables=[rodmol.Cable((0.003, 0.0), 0.37 * L, 1.5, name="mid-cell"),
                    rodmol.Cable((0.0, -0.002), L, lambda t: 0.7 + 0.2 * t, name="tip"),
                    rodmol.Cable((-0.006, 0.0), 0.25 * L, [(0.0, 0.0), (1.0, 2.0)], name="table")]),
        "moving base, Munk moment": rodmol.scenarios.get("reaching").model(
            8, base=WAVY_BASE, munk_moment=True),
        "no viscosity, no drag, no added mass": rodmol.scenarios.get("bending").model(
            6, viscosity=False, drag=False, added_mass=False),
        "feedback tension": rodmol.paper_arm(6, tensions={3: _feedback, 11: 1.0}),
        "no gravity, buoyancy only": rodmol.Model(rod, 5, gravity=(0.0, 0.0, 0.0), medium_density=500.0,
                                                  cables=[rodmol.Cable((0.0, 0.003), L, 0.4)]),
    }


MODELS = _models()


def _random_state(model, rng, scale=1.0):
    """A state well away from rest: bent, twisted, moving, with |Q| != 1."""
    n = model.n_elements
    lay = SemiDiscrete(model, kernel="numpy").layout
    quat = rng.normal(size=(n, 4)) * 0.3 + np.array([1.0, 0, 0, 0])
    quat0 = np.array([1.0, 0.01, -0.02, 0.03])
    q = np.array([1.0, 0.0, 0.0]) + 0.05 * scale * rng.normal(size=(n, 3))
    k = 3.0 * scale * rng.normal(size=(n, 3))
    v = 0.3 * scale * rng.normal(size=(n, 3))
    w = 2.0 * scale * rng.normal(size=(n, 3))
    u = rng.normal(size=(n, 3)) * 0.2
    return lay.pack(rng.normal(size=3) * 0.01, quat0, u, quat, q, k, v, w)


@pytest.mark.parametrize("name", sorted(MODELS))
def test_compiled_rhs_equals_numpy_reference(name):
    model = MODELS[name]
    fast, ref = SemiDiscrete(model), SemiDiscrete(model, kernel="numpy")
    assert fast.kernel == "numba"
    rng = np.random.default_rng(abs(hash(name)) % 2**32)
    for t in (0.0, 0.37, 1.9):
        y = _random_state(model, rng)
        expected = ref(t, y)
        out = np.full(y.size, np.nan)
        got = fast(t, y, out)
        assert got is out
        # Round-off: the two evaluate the same expressions in different orders.
        scale = np.maximum(np.abs(expected), 1e-300)
        assert np.all(np.abs(got - expected) <= 1e-12 * np.max(np.abs(expected)) + 1e-12 * scale)


def test_compiled_rhs_accepts_read_only_and_writable_states():
    model = MODELS["water, one cable (bending)"]
    system = SemiDiscrete(model)
    y = _random_state(model, np.random.default_rng(0))
    frozen = y.copy()
    frozen.flags.writeable = False  # as CVODE hands it over
    np.testing.assert_array_equal(system(0.2, y), system(0.2, frozen))


def test_rates_of_frames_match_single_calls():
    model = MODELS["moving base, Munk moment"]
    system = SemiDiscrete(model)
    rng = np.random.default_rng(3)
    t = np.array([0.0, 0.5, 1.0])
    states = np.array([_random_state(model, rng) for _ in t])
    rates = system.rates(t, states)
    for i in range(3):
        np.testing.assert_array_equal(rates[i], system(t[i], states[i]))


def test_tensions_match_the_model():
    model = MODELS["anchors between nodes and at the tip"]
    system = SemiDiscrete(model)
    for t in (0.0, 0.3, 0.999, 1.0, 7.0):
        np.testing.assert_allclose(system.tensions(t, None), model.tensions(t), rtol=1e-15)


def test_unknown_kernel_is_an_error():
    with pytest.raises(ParameterError, match="kernel"):
        SemiDiscrete(MODELS["air, no cables"], kernel="fortran")


def _fd_jacobian(system, t, y, scale):
    """Central differences of the numpy reference, column by column."""
    n = y.size
    jac = np.empty((n, n))
    for j in range(n):
        h = 1e-6 * max(abs(y[j]), scale[j])
        yp, ym = y.copy(), y.copy()
        yp[j] += h
        ym[j] -= h
        jac[:, j] = (system(t, yp) - system(t, ym)) / (2 * h)
    return jac


@pytest.mark.parametrize("name", ["anchors between nodes and at the tip", "moving base, Munk moment"])
def test_compiled_jacobian_matches_finite_differences(name):
    model = MODELS[name]
    system, ref = SemiDiscrete(model), SemiDiscrete(model, kernel="numpy")
    y = _random_state(model, np.random.default_rng(7), scale=0.3)
    scale = default_atol(model, 1.0)
    expected = _fd_jacobian(ref, 0.4, y, scale)
    for matrix in ("band", "dense", "sparse"):
        got = jacobian.CompiledJacobian(system, scale, matrix).dense(0.4, y)
        # One-sided differences (the solver's) against central ones.
        assert np.max(np.abs(got - expected)) <= 1e-5 * np.max(np.abs(expected)), matrix
    # The sparse structure is layout.pattern(), and nothing lies outside it.
    pattern = system.layout.pattern()
    sparsity = jacobian.CompiledJacobian(system, scale, "sparse").sparsity.toarray() != 0
    np.testing.assert_array_equal(sparsity, pattern)
    assert np.all(expected[~pattern] == 0.0)


@pytest.mark.parametrize("gamma", [1e-6, 1e-3, 5e-2])
def test_block_preconditioner_solves_the_newton_matrix(gamma):
    model = MODELS["water, three cables held"]
    system = SemiDiscrete(model)
    y = _random_state(model, np.random.default_rng(11), scale=0.3)
    pre = jacobian.BlockPreconditioner(system, default_atol(model, 1.0))
    jnew = [0]
    pre.setup(0.7, y, system(0.7, y), False, jnew, gamma)
    assert jnew == [1] and pre.jac_evals == 1
    jac = pre.jacobian.dense(0.7, y)
    newton = np.eye(y.size) - gamma * jac
    r = np.random.default_rng(12).normal(size=y.size)
    x = pre.apply(r)
    # Exact up to the conditioning of I - gamma J (1e7 for the largest gamma).
    assert np.max(np.abs(newton @ x - r)) <= 1e-9 * np.max(np.abs(r))
    # A setup with jok reuses the Jacobian and only refactors.
    pre.setup(0.7, y, system(0.7, y), True, jnew, 2 * gamma)
    assert jnew == [0] and pre.jac_evals == 1 and pre.setups == 2


def _short_run(model, t_end=0.3, **options):
    system = SemiDiscrete(model)
    y0 = rodmol.equilibrium(model)
    t_out = np.linspace(0.0, t_end, 16)
    rtol = 1e-7
    return cvode(system, y0, t_out, rtol=rtol, atol=default_atol(model, rtol), **options), system, y0, t_out


def test_linear_solvers_agree():
    model = rodmol.scenarios.get("bending").model(14)
    runs = {}
    for label, options in {"gmres": dict(linsolver="gmres"),
                           "band": dict(linsolver="band", jacobian="sundials"),
                           "band, compiled J": dict(linsolver="band", jacobian="compiled"),
                           "sparse": dict(linsolver="sparse"),
                           "dense": dict(linsolver="dense")}.items():
        raw, *_ = _short_run(model, **options)
        assert raw.success, (label, raw.message)
        runs[label] = raw
    tip = {k: r.y[:, -19:-16] for k, r in runs.items()}
    for label in runs:
        assert np.max(np.abs(tip[label] - tip["band"])) < 2e-6 * model.rod.length, label
    assert runs["gmres"].stats["prec_solves"] > 0 and runs["gmres"].stats["jac_evals"] > 0


def test_rk23_uses_the_same_right_hand_side():
    model = rodmol.scenarios.get("bending").model(6)
    raw, system, y0, t_out = _short_run(model, t_end=0.05)
    rtol = 1e-7
    explicit = rk23(system, y0, t_out, rtol=rtol, atol=default_atol(model, rtol))
    assert explicit.success
    assert np.max(np.abs(explicit.y - raw.y)[:, -19:-16]) < 1e-6 * model.rod.length


def test_steps_do_not_depend_on_output_times():
    """A step is counted once, however many output times it spans."""
    model = rodmol.scenarios.get("bending").model(8)
    system = SemiDiscrete(model)
    y0 = rodmol.equilibrium(model)
    rtol = 1e-6
    counts = set()
    for n_out in (3, 41, 401):
        raw = cvode(system, y0, np.linspace(0.0, 0.4, n_out), rtol=rtol, atol=default_atol(model, rtol))
        counts.add((raw.stats["steps"], raw.stats["rhs_evals"]))
        assert 0 < raw.stats["h_min"] <= raw.stats["h_median"] <= raw.stats["h_max"]
    assert len(counts) == 1


def test_equilibrium_converges_at_first_order_in_space():
    """Successive refinements of the paper arm's equilibrium under gravity and
    buoyancy (the paper's initial state): the tip's differences shrink by
    2^p with p -> 1 (the scheme is O(ds)); measured 0.93, 0.97, 0.98."""
    tips = [rodmol.equilibrium(rodmol.paper_arm(n))[-19:-16] for n in (32, 64, 128, 256)]
    d = [np.linalg.norm(b - a) for a, b in zip(tips, tips[1:])]
    orders = np.log2(np.array(d[:-1]) / np.array(d[1:]))
    assert np.all((orders > 0.85) & (orders < 1.15)), orders
