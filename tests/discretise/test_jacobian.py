"""The compiled Jacobian, its structure and the block preconditioner.

For every external load kind (and the bare paper arm) at a generic state --
contact active on some nodes and sliding, so that the friction law is not
trivial -- the compiled one-sided-difference Jacobian equals a central
finite-difference Jacobian of the full right-hand side on the whole pattern,
and that central Jacobian has no entry outside ``system.pattern()``.
"""

import numpy as np
import oracle
import pytest
import scipy.linalg

import rodmol
from rodmol.arm import paper_rod
from rodmol.discretise import external, load_entries, preconditioner
from rodmol.discretise.layout import FIELDS, HEADER, merge
from rodmol.discretise.schemes import SCHEMES
from rodmol.discretise.system import SemiDiscrete
from rodmol.solve.rest_equations import RestEquations

L = paper_rod().length
N = 8
LAW = dict(stiffness=2e4, damping=40.0, friction=0.6, slip_speed=1e-3)
TENSIONS = {11: 1.0, 3: 0.5}

#: Load lists of the cases, each on the paper arm with two cables.
CASES = {
    "bare paper arm": [],
    "point force, global": [rodmol.PointForce(0.37 * L, (0.3, -0.2, 0.1))],
    "point force, local": [rodmol.PointForce(L, (0.3, -0.2, 0.1), frame="local")],
    "point moment, global": [rodmol.PointMoment(0.6 * L, (0.01, 0.02, -0.03))],
    "point moment, local": [rodmol.PointMoment(L, (0.01, 0.02, -0.03), frame="local")],
    "distributed force, global": [rodmol.DistributedForce((0.5, -1.0, 0.2))],
    "distributed force, local": [rodmol.DistributedForce(lambda s, t: np.outer(1 + s, [0.2, 0.5, -0.3]),
                                                         frame="local")],
    "distributed moment, global": [rodmol.DistributedMoment((0.02, -0.01, 0.03))],
    "distributed moment, local": [rodmol.DistributedMoment((0.02, -0.01, 0.03), frame="local")],
    "plane contact": [rodmol.PlaneContact((0.0, -0.02, 0.0), (0.0, np.cos(0.3), np.sin(0.3)), **LAW)],
    "sphere contact": [rodmol.SphereContact((0.2, -0.05, 0.0), 0.03, **LAW)],
    "capsule contact": [rodmol.CapsuleContact((0.05, -0.04, -0.05), (0.35, -0.04, 0.06), 0.02, **LAW)],
    # Holds at a modest stiffness: the generic state is far from their point, and the
    # default penalty's forces there would swamp the difference quotients in round-off.
    "pin": [rodmol.Hold(L, position=(0.9 * L, 0.02, -0.01), stiffness=1e3, damping=2.0)],
    "clamp": [rodmol.Hold(L / 2, kind="clamp", stiffness=1e3, damping=2.0)],
}


def _model(name):
    return rodmol.paper_arm(N, tensions=TENSIONS, loads=CASES[name])


def central_jacobian(system, t, y, scale):
    """d f / d y by central differences of the full right-hand side, column by column."""
    jac = np.empty((y.size, y.size))
    for j in range(y.size):
        h = 1e-6 * max(abs(y[j]), scale[j])
        yp, ym = y.copy(), y.copy()
        yp[j] += h
        ym[j] -= h
        jac[:, j] = (system(t, yp) - system(t, ym)) / (yp[j] - ym[j])
    return jac


def _field_index(n):
    """The field name (u0/Q0 for the header) of every state entry."""
    names = np.empty(HEADER + 19 * n, dtype=object)
    names[:3], names[3:HEADER] = "u0", "Q0"
    for f, sl in FIELDS.items():
        for b in range(n):
            names[HEADER + 19 * b + sl.start:HEADER + 19 * b + sl.stop] = f
    return names


def blockwise_error(got, expected, n):
    """Worst difference, relative to the largest entry of each (row field,
    column field) sub-block, so that small couplings (friction, dead loads)
    are judged on their own scale, not on the elastic one."""
    names = _field_index(n)
    worst, where = 0.0, None
    for rf in np.unique(names):
        for cf in np.unique(names):
            rows, cols = names == rf, names == cf
            e = expected[np.ix_(rows, cols)]
            scale = np.max(np.abs(e))
            if scale == 0.0:
                assert np.all(got[np.ix_(rows, cols)] == 0.0), (rf, cf)
                continue
            err = np.max(np.abs(got[np.ix_(rows, cols)] - e)) / scale
            if err > worst:
                worst, where = err, (rf, cf)
    return worst, where


_STATES = {}


def _state(name):
    """A generic state of the case (cached), contact active and sliding."""
    if name not in _STATES:
        model = _model(name)
        _STATES[name] = oracle.generic_state(model, np.random.default_rng(sum(map(ord, name))))
    return _STATES[name]


def test_every_load_kind_is_covered():
    kinds = set()
    for name in CASES:
        kinds |= set(int(k) for k in load_entries.of_model(_model(name)).kind)
    assert kinds == set(external.DEPENDS)


@pytest.mark.parametrize("scheme", list(SCHEMES))
@pytest.mark.parametrize("name", list(CASES))
def test_compiled_jacobian_matches_central_differences(name, scheme):
    model = _model(name)
    system = rodmol.SemiDiscrete(model, scheme)
    y, t = _state(name), 0.3
    scale = system.atol_scale()
    expected = central_jacobian(system, t, y, scale)
    pattern = system.pattern()
    # The structure is complete: nothing outside the declared pattern.
    outside = np.argwhere((expected != 0.0) & ~pattern)
    assert len(outside) == 0, [(system.layout.entry_name(i), system.layout.entry_name(j))
                               for i, j in outside[:5]]
    got = system.jacobian(scale, "band").dense(t, y)
    assert np.all(got[~pattern] == 0.0)
    worst, where = blockwise_error(got, expected, model.n_elements)
    print(f"{name}: worst sub-block-relative difference {worst:.1e} at {where}")
    # One-sided increments sqrt(eps) L ~ 6e-9 m against a smoothing depth of
    # 1% of the radius (4e-5 m at the tip): the contact rows' truncation error
    # reaches ~1e-5 of their size; everything else agrees to ~2e-6.
    assert worst < 1e-4, (worst, where)


@pytest.mark.parametrize("name", [n for n in CASES if n != "bare paper arm"])
def test_load_part_of_the_jacobian(name):
    """J(arm with the load) - J(bare arm) at the same state is the load's own
    Jacobian: compiled and central differences agree on it relative to its
    own size, and it is not empty (the state does activate the load)."""
    y, t = _state(name), 0.3
    loaded = rodmol.SemiDiscrete(_model(name))
    bare = rodmol.SemiDiscrete(rodmol.paper_arm(N, tensions=TENSIONS))
    scale = loaded.atol_scale()
    expected = central_jacobian(loaded, t, y, scale) - central_jacobian(bare, t, y, scale)
    got = loaded.jacobian(scale, "band").dense(t, y) - bare.jacobian(scale, "band").dense(t, y)
    size = np.max(np.abs(expected))
    dead_or_contact = any(not isinstance(ld, (rodmol.PointForce, rodmol.PointMoment, rodmol.DistributedForce,
                                              rodmol.DistributedMoment)) or ld.frame == "global"
                          for ld in CASES[name])
    if not dead_or_contact:
        # A follower load does not depend on the state: the difference is round-off.
        floor = np.max(np.abs(bare.jacobian(scale, "band").dense(t, y)))
        assert size < 1e-9 * floor and np.max(np.abs(got)) < 1e-7 * floor
        return
    assert size > 0.0
    err = np.max(np.abs(got - expected)) / size
    print(f"{name}: load Jacobian max {size:.3g}, relative difference {err:.1e}")
    assert err < 1e-4


def test_friction_is_sliding_at_the_test_state():
    """The contact cases slide well above the slip speed on their active nodes."""
    for name in ("plane contact", "sphere contact", "capsule contact"):
        model = _model(name)
        y = _state(name)
        data = oracle.Sampled(model)
        fld = oracle.unpack(y, N)
        obstacle = model.loads[0]
        f, _ = oracle.contact_loads(obstacle, data, fld["u"], oracle.rotation_matrices(fld["Q"]),
                                    fld["v"], fld["w"])
        active = np.linalg.norm(f, axis=1) > 0
        assert np.count_nonzero(active) >= 2, name


@pytest.mark.parametrize("scheme", list(SCHEMES))
@pytest.mark.parametrize("gamma", [1e-6, 1e-4, 1e-3, 1e-2, 1e-1])
def test_block_preconditioner_inverts_the_newton_matrix(gamma, scheme):
    name = "capsule contact"
    system = rodmol.SemiDiscrete(_model(name), scheme)
    y, t = _state(name), 0.7
    bp = system.preconditioner(system.atol_scale())
    bp.jacobian.evaluate(t, y, system(t, y))
    jac = bp.jacobian.dense(t, y)
    bp.factor(gamma)
    r = np.random.default_rng(12).normal(size=y.size)
    x = bp.apply(r)
    newton = np.eye(y.size) - gamma * jac
    residual = np.max(np.abs(newton @ x - r)) / np.max(np.abs(r))
    backward = np.max(np.abs(newton @ x - r)) / (np.max(np.abs(newton)) * np.max(np.abs(x)) + np.max(np.abs(r)))
    print(f"gamma {gamma:g}: residual {residual:.1e}, backward error {backward:.1e}, "
          f"cond {np.linalg.cond(newton):.1e}")
    direct = np.linalg.solve(newton, r)
    residual_lu = np.max(np.abs(newton @ direct - r)) / np.max(np.abs(r))
    print(f"    dense LU residual {residual_lu:.1e}")
    assert backward < 1e-14
    if gamma <= 1e-3:
        # As exact as a direct solve (I - gamma J has a condition number up to 4e9 here).
        assert residual < max(1e-9, 10 * residual_lu)
    else:
        # A large step (cond 4e9 to 3e10): the elimination without pivoting across
        # blocks loses 1-3 digits against LU (3.6e-8 vs 5.8e-11); still an excellent
        # preconditioner, GMRES removes the rest.
        assert residual < 1e-6


@pytest.mark.parametrize("scheme", list(SCHEMES))
def test_preconditioner_accepts_every_load_kind(scheme):
    for name in CASES:
        preconditioner.check_structure(rodmol.SemiDiscrete(_model(name), scheme).depends)


@pytest.mark.parametrize("scheme", list(SCHEMES))
@pytest.mark.parametrize("extra", [{"v": {2: ("q",)}}, {"q": {0: ("u",)}}, {"u": {-1: ("v",)}},
                                   {"w": {1: ("Q",)}}])
def test_check_structure_refuses_an_outside_coupling(extra, scheme):
    with pytest.raises(ValueError, match="cannot solve exactly"):
        preconditioner.check_structure(merge(SCHEMES[scheme].depends, extra))


@pytest.mark.parametrize("scheme", list(SCHEMES))
@pytest.mark.parametrize("name", ["bare paper arm", "point moment, global", "capsule contact"])
def test_bandwidths_are_the_patterns(name, scheme):
    system = rodmol.SemiDiscrete(_model(name), scheme)
    pattern = system.pattern()
    declared = system.bandwidths()
    assert declared == scipy.linalg.bandwidth(pattern.astype(float))
    assert declared == scipy.linalg.bandwidth(pattern[HEADER:, HEADER:].astype(float))
    jacband = pytest.importorskip("sksundae.jacband")
    assert tuple(jacband.bandwidth(pattern)) == declared
    # The numerical pattern at a generic state spans the same band.
    y = _state(name)
    numerical = central_jacobian(system, 0.3, y, system.atol_scale()) != 0.0
    assert scipy.linalg.bandwidth(numerical.astype(float)) == declared


def test_bandwidths_do_not_depend_on_n():
    bands = {rodmol.SemiDiscrete(rodmol.paper_arm(n, loads=CASES["plane contact"])).bandwidths()
             for n in (3, 8, 40)}
    assert len(bands) == 1


def test_jacobian_templates_agree():
    name = "sphere contact"
    system = rodmol.SemiDiscrete(_model(name))
    y, t = _state(name), 0.3
    scale = system.atol_scale()
    band = system.jacobian(scale, "band").dense(t, y)
    for matrix in ("dense", "sparse"):
        np.testing.assert_array_equal(system.jacobian(scale, matrix).dense(t, y), band)
    sparse = system.jacobian(scale, "sparse")
    np.testing.assert_array_equal(sparse.sparsity.toarray() != 0, system.pattern())


# ----------------------------------------------------------------------------- solvers built on them

SOLVERS = {"gmres": dict(linsolver="gmres"),
           "band": dict(linsolver="band", jacobian="sundials"),
           "band, compiled J": dict(linsolver="band", jacobian="compiled"),
           "sparse": dict(linsolver="sparse"),
           "dense": dict(linsolver="dense")}


@pytest.mark.parametrize("case", ["bending scenario", "falling onto a sphere"])
def test_linear_solvers_agree(case):
    """Every linear solver (the block-preconditioned GMRES, band LU with
    SUNDIALS' or the compiled Jacobian, sparse, dense) integrates to the same
    tip: the Jacobians and the preconditioner are right where it matters."""
    if case == "bending scenario":
        model, initial, t_end = rodmol.scenarios.get("bending").model(14), "equilibrium", 0.3
    else:
        # N = 24: at N = 12 the centred scheme (rightly) stops where the tip
        # wraps the sphere by pi/2 per element; the upwind scheme smears it.
        model = rodmol.paper_arm(24, medium="air", loads=[
            rodmol.SphereContact((0.3, -0.06, 0.0), 0.04, stiffness=2e4, damping=20.0, friction=0.4)])
        initial, t_end = "straight", 0.4
    tips = {}
    for label, options in SOLVERS.items():
        result = rodmol.simulate(model, t_end, initial=initial, rtol=1e-7, output_dt=t_end / 8, **options)
        assert result.success, (label, result.message)
        tips[label] = result.integrated_positions[:, -1]
        if model.loads:  # the arm does hit the sphere
            assert np.max(np.abs(result.external_force)) > 1.0
        if label == "gmres":
            assert result.stats["prec_solves"] > 0 and result.stats["jac_evals"] > 0
    spread = max(np.max(np.abs(tip - tips["band"])) for tip in tips.values())
    print(f"{case}: largest difference between linear solvers {spread:.1e} m")
    # Different linear solvers take different steps: the spread is a time
    # error of rtol 1e-7 (measured 1.2e-6 m on the sphere, centred scheme).
    assert spread < 5e-6 * model.rod.length


def test_steps_do_not_depend_on_output_times():
    """A step is counted once, however many output times it spans."""
    model = rodmol.scenarios.get("bending").model(8)
    counts = set()
    for output_dt in (0.2, 0.01, 0.001):
        result = rodmol.simulate(model, 0.4, rtol=1e-6, output_dt=output_dt)
        counts.add((result.stats["steps"], result.stats["rhs_evals"]))
        assert 0 < result.stats["h_min"] <= result.stats["h_median"] <= result.stats["h_max"]
    assert len(counts) == 1


@pytest.mark.parametrize("scheme", ["centred", "upwind"])
def test_banded_differences_equal_one_column_at_a_time(scheme):
    """The rest equations' Jacobian by grouped columns (the layout's colouring)
    is the one-column-at-a-time difference Jacobian exactly, inside and outside
    the band: no group mixes two columns that share a row."""
    model = rodmol.scenarios.get("reaching").model(N)
    system = SemiDiscrete(model, scheme)
    equations = RestEquations(system, 3.0)
    y = rodmol.equilibrium(system, 3.0)
    z = equations.unknowns(y) + 1e-3 * np.random.default_rng(1).standard_normal(equations.unknowns(y).size)
    f0, h = equations.residual(z), 1.5e-8 * np.maximum(np.abs(z), 1.0)
    dense = np.empty((z.size, z.size))
    for j in range(z.size):
        zp = z.copy()
        zp[j] += h[j]
        dense[:, j] = (equations.residual(zp) - f0) / h[j]
    lo, up = equations.bands
    banded = np.zeros_like(dense)
    ab = equations.differences(equations.residual, z, f0)
    for j in range(z.size):
        rows = np.arange(max(0, j - up), min(z.size, j + lo + 1))
        banded[rows, j] = ab[up + rows - j, j]
    np.testing.assert_array_equal(banded, dense)
