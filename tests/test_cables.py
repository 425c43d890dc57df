"""Water and cables: tendon bending, global balance, added mass, the paper's tests,
bad inputs and a moving base.

Every expected value below is derived here from the continuum model (see the
docstrings), never copied from a rodmol run.
"""

import math

import numpy as np
import pytest

import rodmol
from rodmol.discretise.sampling import Sampled

#: The paper's silicone (Table I).
SILICONE = rodmol.Material(E=110e3, nu=0.5, mu=300.0, rho=1080.0)
NO_GRAVITY = (0.0, 0.0, 0.0)
RHO_WATER, B_Y = 1022.0, 1.5  # Table III
L_ARM = 0.418  # m, Table I


# ---------------------------------------------------------------------------
# helpers (independent of rodmol's own reconstruction code)


def static_fields(model, y):
    """(positions (N+1, 3), q (N, 3), k (N, 3)) of a state vector of ``model``."""
    lay = rodmol.StateLayout(model.n_elements)
    positions = np.vstack([y[:3], lay.field(y, "u")])
    return positions, lay.field(y, "q").copy(), lay.field(y, "k").copy()


def exp_so3(theta):
    """exp([theta]x) for rotation vectors (..., 3), by Rodrigues' formula."""
    angle = np.linalg.norm(theta, axis=-1)[..., None, None]
    small = angle < 1e-12
    safe = np.where(small, 1.0, angle)
    k = np.zeros(theta.shape[:-1] + (3, 3))
    k[..., 0, 1], k[..., 0, 2] = -theta[..., 2], theta[..., 1]
    k[..., 1, 0], k[..., 1, 2] = theta[..., 2], -theta[..., 0]
    k[..., 2, 0], k[..., 2, 1] = -theta[..., 1], theta[..., 0]
    a = np.where(small, 1.0, np.sin(safe) / safe)
    b = np.where(small, 0.5, (1.0 - np.cos(safe)) / safe**2)
    return np.eye(3) + a * k + b * (k @ k)


def tip_from_strains(result, ds):
    """Tip (n_t, 3) rebuilt from the strains: u' = R q, R' = R [k] (midpoint rule per cell).

    This is the shape the internal stresses belong to; it is independent of
    the time-integrated positions.
    """
    q, k = result.linear_strain[:, :-1], result.curvature[:, :-1]
    rot, u = result.rotations[:, 0].copy(), result.positions[:, 0].copy()
    for i in range(q.shape[1]):
        half = exp_so3(0.5 * ds * k[:, i])
        u = u + ds * np.einsum("tij,tj->ti", rot @ half, q[:, i])
        rot = rot @ half @ half
    return u


def fit_circle(points):
    """Least-squares (Kasa) circle through 2-D points: centre (2,), radius, max residual."""
    x, y = points[:, 0], points[:, 1]
    a = np.column_stack([2 * x, 2 * y, np.ones_like(x)])
    (cx, cy, c), *_ = np.linalg.lstsq(a, x**2 + y**2, rcond=None)
    radius = math.sqrt(c + cx**2 + cy**2)
    residual = np.max(np.abs(np.hypot(x - cx, y - cy) - radius))
    return np.array([cx, cy]), radius, residual


def tendon_arc(L, r, T, p, s_bar):
    """Continuum solution of a uniform rod bent by one tendon, no other load.

    With the total stress zero everywhere (free tip, no external load), the
    body carries N_el = -T tau, M_el = -p x T tau on [0, s_bar). Trying
    q = (1 + eps, 0, 0), k = (0, k_y, k_z) gives q + k x p = (1 + eps + k_y p_z
    - k_z p_y, 0, 0), so tau = e_x, hence gamma = 0, eps = -T / EA and
    M_el = (0, -T p_z, T p_y): k_y = -T p_z / (E J), k_z = T p_y / (E J).
    The centreline is a circle of curvature |k| / (1 + eps) in the plane of
    e_x and the bending direction n = (0, p_y, p_z) / |p|.
    """
    A, J = math.pi * r**2, math.pi * r**4 / 4
    eps = -T / (SILICONE.E * A)
    ky, kz = -T * p[1] / (SILICONE.E * J), T * p[0] / (SILICONE.E * J)
    kappa_material = math.hypot(ky, kz)
    n = np.array([0.0, p[0], p[1]]) / math.hypot(*p)
    rho = (1 + eps) / kappa_material  # radius of the arc [m]

    def centreline(s):
        s = np.asarray(s, dtype=float)
        phi = kappa_material * np.minimum(s, s_bar)
        arc = rho * np.sin(phi)[..., None] * np.array([1.0, 0, 0]) + (
            rho * (1 - np.cos(phi)))[..., None] * n
        straight = np.maximum(s - s_bar, 0.0)[..., None] * (
            np.cos(phi)[..., None] * np.array([1.0, 0, 0]) + np.sin(phi)[..., None] * n)
        return arc + straight

    return dict(eps=eps, ky=ky, kz=kz, kappa=kappa_material / (1 + eps), rho=rho, n=n,
                angle=kappa_material * s_bar, centreline=centreline)


# ---------------------------------------------------------------------------
# (a) constant-curvature tendon bending


L_A, R_A, T_A = 0.3, 0.01, 1.0


@pytest.mark.parametrize("offset", [(0.005, 0.0), (0.0, -0.005), (0.003, 0.004)],
                         ids=["+y", "-z", "oblique"])
def test_tendon_bends_rod_into_circular_arc(offset):
    """Anchor on a grid node (s_bar = 0.2 m, N = 30): uniform strains with
    eps = -T/EA, gamma = 0, k = (0, -T p_z, T p_y)/(E J) up to the anchor, a
    circle of curvature |k|/(1+eps), and a straight rest part beyond."""
    n_el, s_bar = 30, 0.2
    rod = rodmol.Rod(L_A, R_A, SILICONE)
    model = rodmol.Model(rod, n_el, gravity=NO_GRAVITY,
                         cables=[rodmol.Cable(offset, s_bar, T_A, name="tendon")])
    pos, q, k = static_fields(model, rodmol.equilibrium(model))
    ex = tendon_arc(L_A, R_A, T_A, offset, s_bar)
    on_path = model.s_nodes[:-1] < s_bar - 1e-9  # strain nodes 0..19

    # Strains: eps = -0.028937 (axial compliance), no shear, k from the moment balance.
    np.testing.assert_allclose(q[on_path], np.tile([1 + ex["eps"], 0, 0], (20, 1)),
                               rtol=0, atol=1e-10)
    np.testing.assert_allclose(k[on_path], np.tile([0, ex["ky"], ex["kz"]], (20, 1)),
                               rtol=1e-9, atol=1e-9)
    # Beyond the anchor the rod carries no stress: rest strains, zero curvature.
    np.testing.assert_allclose(q[~on_path], np.tile([1.0, 0, 0], (10, 1)), rtol=0, atol=1e-12)
    np.testing.assert_allclose(k[~on_path], 0.0, atol=1e-10)

    # Nodes 0..20 on a circle: project on the bending plane (e_x, n).
    e_x, n = np.array([1.0, 0, 0]), ex["n"]
    binormal = np.cross(e_x, n)
    assert np.max(np.abs(pos @ binormal)) < 1e-12  # planar
    plane = np.column_stack([pos @ e_x, pos @ n])
    centre, radius, residual = fit_circle(plane[:21])
    assert residual < 1e-10
    # The discrete arc is a regular polygon inscribed in a circle of radius
    # rho (theta/2)/sin(theta/2), theta = ds |k| = 0.058: within 1.4e-4 of rho.
    assert radius == pytest.approx(ex["rho"], rel=1e-3)
    np.testing.assert_allclose(centre, [0.0, ex["rho"]], atol=2e-4 * ex["rho"])
    # Node positions against the continuum arc and straight part.
    np.testing.assert_allclose(pos, ex["centreline"](model.s_nodes), atol=1e-4)
    # Straight beyond the anchor, along the tangent at angle k s_bar.
    tangent = np.cos(ex["angle"]) * e_x + np.sin(ex["angle"]) * n
    steps = np.diff(pos[20:], axis=0)
    np.testing.assert_allclose(steps, np.tile(model.ds * tangent, (10, 1)), atol=1e-12)


def test_tendon_curvature_scales_with_tension_and_offset():
    """k_z = T p_y / (E J_z) is linear in T and p_y; eps = -T/EA does not depend on p_y."""
    rod = rodmol.Rod(L_A, R_A, SILICONE)
    for tension, py in ((0.5, 0.005), (2.0, 0.0025), (2.0, 0.008)):
        model = rodmol.Model(rod, 10, gravity=NO_GRAVITY,
                             cables=[rodmol.Cable((py, 0.0), L_A, tension, name="tip")])
        _, q, k = static_fields(model, rodmol.equilibrium(model))
        A, J = math.pi * R_A**2, math.pi * R_A**4 / 4
        np.testing.assert_allclose(k[:, 2], tension * py / (SILICONE.E * J), rtol=1e-9)
        np.testing.assert_allclose(q[:, 0], 1 - tension / (SILICONE.E * A), rtol=1e-12)


def test_anchor_between_nodes_converges_smoothly():
    """s_bar = 0.2017 m, N = 20..32. The anchor cell carries the fraction
    (s_bar - s_j)/ds of the tendon, so the total bending angle is exactly
    k_z s_bar for every N, and the tip error stays below 3% of ds (snapping the
    anchor to the nearest node would move the tip by up to
    k_z (ds/2) (L - s_bar + rho sin(...)) ~ 0.4 ds)."""
    rod = rodmol.Rod(L_A, R_A, SILICONE)
    py, s_bar = 0.005, 0.2017
    ex = tendon_arc(L_A, R_A, T_A, (py, 0.0), s_bar)
    tip_exact = ex["centreline"](L_A)
    errors, ds = [], []
    for n_el in range(20, 33):
        model = rodmol.Model(rod, n_el, gravity=NO_GRAVITY,
                             cables=[rodmol.Cable((py, 0.0), s_bar, T_A, name="tendon")])
        pos, _, k = static_fields(model, rodmol.equilibrium(model))
        # Total rotation = ds * sum(k_z) = k_z * s_bar exactly.
        assert model.ds * k[:, 2].sum() == pytest.approx(ex["angle"], rel=1e-9)
        errors.append(pos[-1] - tip_exact)
        ds.append(model.ds)
    errors, ds = np.array(errors), np.array(ds)
    size = np.linalg.norm(errors, axis=1)
    assert np.all(size < 0.03 * ds), size / ds  # measured: <= 0.013 ds
    # No jumps when N changes by one: consecutive tips differ by O(ds) only.
    jumps = np.linalg.norm(np.diff(errors, axis=0), axis=1)
    assert np.all(jumps < 0.03 * ds[1:]), jumps / ds[1:]


# ---------------------------------------------------------------------------
# (b) global balance


def test_base_force_equals_cable_pull():
    """No gravity, three cables (one anchored between nodes, one at the tip):
    the body's stress at the base equals the resultant of the cable loads on
    the body, -sum T tau(0), with moment -sum p x T tau(0). With no torsion
    tau(0) = e_x, so N(0) = (-sum T, 0, 0) and M(0) = (0, -sum T p_z, sum T p_y)."""
    rod = rodmol.Rod(0.418, (0.015, 0.004), SILICONE)
    cables = [rodmol.Cable((0.006, 0.002), 0.2017, 1.5, name="a"),
              rodmol.Cable((0.0, -0.003), 0.418, 0.7, name="b"),
              rodmol.Cable((-0.008, 0.0), 0.1, 2.0, name="c")]
    model = rodmol.Model(rod, 20, gravity=NO_GRAVITY, cables=cables)
    _, q, k = static_fields(model, rodmol.equilibrium(model))

    pull, moment = np.zeros(3), np.zeros(3)
    for c in cables:
        p = np.array([0.0, *c.offset])
        path = q[0] + np.cross(k[0], p)
        tau = path / np.linalg.norm(path)
        pull += c.tension_at(0.0) * tau
        moment += np.cross(p, c.tension_at(0.0) * tau)
    kl, kth = rodmol.SemiDiscrete(model).cells[:2]  # cell 0's, where q[0] and k[0] live
    n_base = kl[0] * (q[0] - [1, 0, 0])
    m_base = kth[0] * k[0]
    np.testing.assert_allclose(n_base, -pull, atol=1e-9)
    np.testing.assert_allclose(m_base, -moment, atol=1e-11)
    np.testing.assert_allclose(n_base, [-4.2, 0, 0], atol=1e-9)
    np.testing.assert_allclose(m_base, [0, -(1.5 * 0.002 - 0.7 * 0.003), 1.5 * 0.006 - 2.0 * 0.008],
                               atol=1e-11)

    # The same through a (static) simulation's Result, base frame = global frame.
    result = rodmol.simulate(model, 0.02, output_dt=0.01)
    assert result.success
    for i in range(len(result.t)):
        np.testing.assert_allclose(result.rotations[i, 0] @ result.internal_force[i, 0],
                                   [-4.2, 0, 0], atol=1e-6)


def test_base_reaction_equals_net_weight_in_water():
    """Tapered paper rod in water, gravity, no cables: the base stress equals
    the net weight (rho - rho_w) V G, V = pi L (r0^2 + r0 r1 + r1^2)/3. The
    scheme is first order (weights at the velocity nodes, a right Riemann sum
    of A(s)): the error halves from N = 40 to 80, and the Richardson
    extrapolation 2 N_80 - N_40 matches the analytic weight to 0.5%."""
    L, r0, r1 = 0.418, 0.015, 0.004
    volume = math.pi * L * (r0**2 + r0 * r1 + r1**2) / 3
    weight = (SILICONE.rho - RHO_WATER) * volume * np.array([0.0, -9.81, 0.0])  # -0.07497 N
    rod = rodmol.Rod(L, (r0, r1), SILICONE)
    base_force, base_moment, arm = {}, {}, {}
    for n_el in (40, 80):
        model = rodmol.Model(rod, n_el, medium="water")
        pos, q, k = static_fields(model, rodmol.equilibrium(model))
        base_force[n_el] = Sampled(model).kl[0] * (q[0] - [1, 0, 0])  # base frame = global (R0 = I)
        base_moment[n_el] = Sampled(model).kth[0] * k[0]
        # Moment of the net weight about the base, trapezoid rule on the nodes.
        density = (SILICONE.rho - RHO_WATER) * math.pi * rod.radius_at(model.s_nodes) ** 2
        arm[n_el] = np.trapezoid(density[:, None] * np.cross(pos, [0.0, -9.81, 0.0]),
                                 model.s_nodes, axis=0)
    err40 = np.linalg.norm(base_force[40] - weight) / np.linalg.norm(weight)
    err80 = np.linalg.norm(base_force[80] - weight) / np.linalg.norm(weight)
    assert err40 < 0.05 and err80 < 0.025
    assert 1.6 < err40 / err80 < 2.4  # first order
    extrapolated = 2 * base_force[80] - base_force[40]
    np.testing.assert_allclose(extrapolated, weight, atol=5e-3 * np.linalg.norm(weight))
    # Base moment = moment of the weight about the base (planar: z only).
    assert np.abs(base_moment[80][:2]).max() < 1e-12
    assert base_moment[80][2] == pytest.approx(arm[80][2], rel=0.05)
    assert 2 * base_moment[80][2] - base_moment[40][2] == pytest.approx(arm[80][2], rel=0.01)


# ---------------------------------------------------------------------------
# (c) added mass and drag


L_C, R_C = 0.2, 0.01
ELASTIC = rodmol.Material(E=110e3, nu=0.5, mu=0.0, rho=1080.0)


def _bent_start(n_el, g):
    """A rest state bent by a uniform transverse load (close to the first mode)."""
    rod = rodmol.Rod(L_C, R_C, ELASTIC)
    return rod, rodmol.equilibrium(rodmol.Model(rod, n_el, gravity=(0.0, -g, 0.0)))


def _period(result):
    """First-mode period from the tip's y(t): up-crossings, refined by a sine fit."""
    from scipy.optimize import curve_fit

    t, y = result.t, result.tip[:, 1]
    yc = y - 0.5 * (y.max() + y.min())
    i = np.flatnonzero((yc[:-1] < 0) & (yc[1:] >= 0))
    crossings = t[i] - yc[i] * (t[i + 1] - t[i]) / (yc[i + 1] - yc[i])
    guess = 2 * np.pi / np.mean(np.diff(crossings))

    def wave(t, a, b, c, w):
        return a * np.cos(w * t) + b * np.sin(w * t) + c

    (_, _, _, omega), _ = curve_fit(wave, t, y, p0=[yc[0], 0.0, 0.0, guess])
    return 2 * np.pi / omega


def test_added_mass_lowers_bending_frequency():
    """Transverse added mass rho_w B_y A joins rho A; bending stiffness and
    mode shape are unchanged, so omega_water / omega_air =
    sqrt(rho / (rho + rho_w B_y)) = 0.64290. Gravity, drag and viscosity off."""
    n_el = 16
    rod, y0 = _bent_start(n_el, 0.3)
    periods = {}
    for medium, t_end in (("air", 3.0), ("water", 4.6)):
        model = rodmol.Model(rod, n_el, gravity=NO_GRAVITY, medium=medium, drag=False,
                             viscosity=False)
        result = rodmol.simulate(model, t_end, initial=y0, output_dt=0.01, rtol=1e-5)
        assert result.success
        periods[medium] = _period(result)
    expected = math.sqrt(ELASTIC.rho / (ELASTIC.rho + RHO_WATER * B_Y))
    assert periods["air"] / periods["water"] == pytest.approx(expected, rel=5e-3)  # 0.6434
    # Air: Euler-Bernoulli cantilever, omega = 1.8751^2 sqrt(E J / (rho A L^4)) -> 1.4166 s.
    A, J = math.pi * R_C**2, math.pi * R_C**4 / 4
    omega = 1.8751**2 * math.sqrt(ELASTIC.E * J / (ELASTIC.rho * A * L_C**4))
    assert periods["air"] == pytest.approx(2 * math.pi / omega, rel=0.02)  # 1.4223 s at N = 16


def _mechanical_energy(model, result):
    e = rodmol.energy(model, result)
    return e["kinetic"] + e["strain"]


def test_drag_only_removes_energy():
    """Water, drag on, mu = 0, no gravity, a large swing (tip deflection 0.16 m
    of 0.2 m): kinetic + strain energy never increases, and drag takes most of it."""
    n_el = 16
    rod, y0 = _bent_start(n_el, 6.0)
    model = rodmol.Model(rod, n_el, gravity=NO_GRAVITY, medium="water", drag=True,
                         viscosity=False)
    result = rodmol.simulate(model, 4.0, initial=y0, output_dt=0.01, rtol=1e-5)
    assert result.success
    energy = _mechanical_energy(model, result)
    assert np.all(np.diff(energy) <= 1e-9 * energy[0])
    assert energy[-1] < 0.05 * energy[0]  # measured: 0.3% left after 4 s


def test_added_mass_with_munk_moment_is_energy_neutral():
    """With the Munk moment -v x rho_w F v, the added-mass terms do no work
    (v.(w x M v) + w.(v x M v) = 0): no drag, mu = 0, energy is conserved."""
    n_el = 16
    rod, y0 = _bent_start(n_el, 6.0)
    model = rodmol.Model(rod, n_el, gravity=NO_GRAVITY, medium="water", drag=False,
                         viscosity=False, munk_moment=True)
    # BDF5 at a tight tolerance: the semi-discrete system's conservation is
    # tested here, not BDF2's numerical dissipation (the default for mu = 0).
    result = rodmol.simulate(model, 4.0, initial=y0, output_dt=0.01, rtol=1e-7, max_order=5)
    assert result.success
    energy = _mechanical_energy(model, result)
    np.testing.assert_allclose(energy, energy[0], rtol=1e-4)


# ---------------------------------------------------------------------------
# (d) the paper's three tests, coarse grid

N_D = 16


@pytest.fixture(scope="module")
def bending_run():
    """Bending test extended to 14 s (release at 4-4.5 s), and its model."""
    model = rodmol.scenarios.get("bending").model(N_D)
    return model, rodmol.simulate(model, 14.0, output_dt=0.05)


def _at(result, t):
    return int(np.argmin(np.abs(result.t - t)))


def test_bending_pull_moves_tip_toward_cable(bending_run):
    """Cable 11 sits at p_y = +3 mm: the pull bends the arm toward +y, and by
    the end of the hold (t = 4 s) the shape is close to the static equilibrium
    at 2 N."""
    model, result = bending_run
    assert result.success, result.message
    # A few times the default rtol (3e-5): measured 1.1e-4 with CVODE stopping at the
    # tension knots (0.5, 4, 4.5 s), 7e-5 without; the tips agree to 0.03 mm.
    assert result.quaternion_norm_error.max() < 3e-4
    y = result.tip[:, 1]
    assert np.all(np.diff(y[: _at(result, 2.0)]) > 0)  # rises while pulled
    assert y[_at(result, 4.0)] - y[0] > 0.25  # measured 0.30 m
    # Near-static at the end of the hold: curvatures within 3% of the static ones.
    lay = rodmol.StateLayout(N_D)
    k_static = lay.field(rodmol.equilibrium(model, 4.0), "k")
    k_run = result.curvature[_at(result, 4.0), :-1]
    assert np.abs(k_run - k_static).max() < 0.03 * np.abs(k_static).max()
    assert np.all(result.tensions[_at(result, 4.0)] == [0] * 10 + [2.0, 0])


def test_bending_returns_to_equilibrium_after_release(bending_run):
    """After the release (0 N from 4.5 s) the arm relaxes to its t = 0
    equilibrium: at 12-14 s the curvatures are within 0.15 rad/m (of up to
    1.9 rad/m) and the shape's tip within 1 cm (2.4% of L). (The lowest mode
    is lightly damped in water at small amplitude, so a few-mm swing remains.)"""
    model, result = bending_run
    late = result.t >= 12.0
    assert np.abs(result.curvature[late] - result.curvature[0]).max() < 0.15
    tip = tip_from_strains(result, model.ds)
    np.testing.assert_allclose(tip[0], result.tip[0], atol=1e-12)  # same shape at t = 0
    assert np.linalg.norm(tip[late] - tip[0], axis=1).max() < 0.01


def test_bending_integrated_tip_returns_to_equilibrium(bending_run):
    model, result = bending_run
    late = result.t >= 12.0
    assert np.linalg.norm(result.tip[late] - result.tip[0], axis=1).max() < 0.01


def test_reaching_cables_bend_proximal_segment_both_ways():
    """Cable 3 (p_y = +9 mm, L1) at 4 N bends the first segment toward +y;
    cable 1 (p_y = -9 mm, L1) at 4 N bends it toward -y (cable-only static
    curvature 4 N * 9 mm / (E J) = 8.2 rad/m at the base, 17.6 rad/m at L1)."""
    scenario = rodmol.scenarios.get("reaching")
    model = scenario.model(N_D)
    result = rodmol.simulate(model, scenario.t_end, output_dt=0.05)
    assert result.success, result.message
    # t = 0 is the gravity equilibrium: at rest, sagging (net density 58 kg/m^3).
    np.testing.assert_array_equal(result.velocity[0], 0.0)
    assert result.tip[0, 1] < -0.05 and result.tip[0, 2] == 0.0
    proximal = result.s[:-1] < 0.098
    kz = result.curvature[:, :-1][:, proximal, 2].mean(axis=1)
    assert kz[0] < 0  # gravity alone bends it downward
    assert kz[_at(result, 2.0)] > 3.0  # measured 7.4 rad/m
    assert kz[_at(result, 5.5)] < -3.0  # measured -10.6 rad/m
    assert result.tip[_at(result, 3.5), 1] - result.tip[0, 1] > 0.2  # measured 0.42 m
    assert np.allclose(result.tensions[-1], 0.0)


def test_reaching_pull_compresses_the_arm_by_tension_over_ea():
    """Held at t = 3 s of the reaching test (cable 3 at 4 N, cable 11 ramping),
    the body carries the cables' pull as axial compression: on the path of
    all pulled cables, q1 - 1 = -(sum of tensions) / (E A(s)) up to the tiny
    axial share of the net weight (about 2%)."""
    scenario = rodmol.scenarios.get("reaching")
    model = scenario.model(N_D)
    t = 3.0
    y = rodmol.equilibrium(model, t)
    q = rodmol.StateLayout(N_D).field(y, "q")
    tensions = model.tensions(t)
    assert tensions.sum() > 4.0
    pulled = Sampled(model).cable_weights[tensions > 0.0].min(axis=0) == 1.0
    s = rodmol.SCHEMES["centred"].cell_points(model.s_nodes)[pulled]  # where q lives
    ea = model.rod.material.E * model.rod.area(s)
    np.testing.assert_allclose(q[pulled, 0] - 1.0, -tensions.sum() / ea, rtol=0.03)


@pytest.mark.parametrize("scheme, order", [("upwind", 1), ("centred", 2)])
def test_position_drift_shrinks_at_the_schemes_order(scheme, order):
    """The time-integrated tip and the tip rebuilt from the strains agree at
    t = 0 and drift apart during the motion by an O(ds^p) amount: in the
    reaching test the largest gap halves (upwind) or quarters (centred) from
    N = 25 to 50 to 100."""
    scenario = rodmol.scenarios.get("reaching")
    gaps = []
    for n_el in (25, 50, 100):
        model = scenario.model(n_el)
        result = rodmol.simulate(model, scenario.t_end, output_dt=0.1, scheme=scheme)
        assert result.success, result.message
        integrated_tip = result.integrated_positions[:, -1]
        gaps.append(np.linalg.norm(integrated_tip - tip_from_strains(result, model.ds), axis=1).max())
    observed = np.log2(np.array(gaps[:-1]) / np.array(gaps[1:]))
    assert np.all((observed > order - 0.3) & (observed < order + 0.5)), (gaps, observed)
    # measured 0.038 m (upwind) and 0.36 mm (centred) at N = 100
    assert gaps[-1] < (0.1 if order == 1 else 0.002) * L_ARM


def test_fetching_is_three_dimensional_and_settles():
    """Cable 2 (p_z = -9 mm) bends toward -z, cables 5 and 11 in the x-y
    plane: the path leaves the plane of gravity. Tensions are held from 4.5 s,
    so the run (extended to 16 s) settles to the static equilibrium under
    (4, 3, 2) N."""
    scenario = rodmol.scenarios.get("fetching")
    model = scenario.model(N_D)
    result = rodmol.simulate(model, 16.0, output_dt=0.05)
    assert result.success, result.message
    assert result.tip[0, 2] == 0.0  # equilibrium under gravity is planar
    z_end = result.tip[_at(result, scenario.t_end), 2]
    assert z_end < -0.1  # measured -0.21 m (toward cable 2)
    assert np.abs(result.tip[:, 2]).max() > 0.15 * model.rod.length
    lay = rodmol.StateLayout(N_D)
    static = rodmol.equilibrium(model, 16.0)
    k_static = lay.field(static, "k")
    assert np.abs(result.curvature[-1, :-1] - k_static).max() < 0.02 * np.abs(k_static).max()
    tip = tip_from_strains(result, model.ds)
    assert np.linalg.norm(tip[-1] - lay.field(static, "u")[-1]) < 0.01  # measured 5.8 mm


# ---------------------------------------------------------------------------
# (e) bad inputs


def test_negative_constant_tension_and_knot_are_rejected():
    with pytest.raises(rodmol.ParameterError, match=r"cable 'c7' tension.*>= 0 N"):
        rodmol.Cable((0.005, 0.0), 0.2, -1.0, name="c7")
    with pytest.raises(rodmol.ParameterError, match=r"cable 'c7' tension.*knot 1"):
        rodmol.Cable((0.005, 0.0), 0.2, [(0.0, 0.0), (1.0, -2.0)], name="c7")


def test_negative_callable_tension_fails_the_run_naming_the_cable():
    rod = rodmol.Rod(0.3, 0.01, SILICONE)
    cable = rodmol.Cable((0.005, 0.0), 0.2, lambda t: 0.5 - t, name="puller")
    model = rodmol.Model(rod, 10, gravity=NO_GRAVITY, cables=[cable])
    with pytest.warns(RuntimeWarning, match="puller"):
        result = rodmol.simulate(model, 1.0)
    assert not result.success
    assert "cable 'puller'" in result.message and ">= 0 N" in result.message
    assert 0.4 <= result.t[-1] <= 0.5  # frames up to the sign change are kept


@pytest.mark.parametrize("anchor", [0.0, -0.1])
def test_anchor_must_be_positive(anchor):
    with pytest.raises(rodmol.ParameterError, match="cable 'x' anchor"):
        rodmol.Cable((0.005, 0.0), anchor, 1.0, name="x")


def test_anchor_beyond_tip_is_rejected():
    rod = rodmol.Rod(0.3, 0.01, SILICONE)
    with pytest.raises(rodmol.ParameterError, match="cable 'long'.*anchor"):
        rodmol.Model(rod, 10, cables=[rodmol.Cable((0.005, 0.0), 0.31, 1.0, name="long")])


def test_offset_outside_body_along_path_is_rejected():
    """On the paper's taper r = 15 - 11 s/L mm, a 9 mm offset leaves the body
    at s = 6 L / 11 = 0.228 m: fine to L2 = 0.203 m, an error to 0.3 m."""
    rod = rodmol.Rod(0.418, (0.015, 0.004), SILICONE)
    rodmol.Model(rod, 10, cables=[rodmol.Cable((0.0, 0.009), 0.203, 1.0, name="ok")])
    with pytest.raises(rodmol.ParameterError, match=r"cable 'far'.*outside the body at s = 0\.22"):
        rodmol.Model(rod, 10, cables=[rodmol.Cable((0.0, 0.009), 0.3, 1.0, name="far")])
    with pytest.raises(rodmol.ParameterError, match="cable 'wide'.*outside the body"):
        rodmol.Model(rod, 10, cables=[rodmol.Cable((0.012, 0.011), 0.05, 1.0, name="wide")])


def test_paper_arm_rejects_unknown_cable_numbers():
    with pytest.raises(rodmol.ParameterError, match=r"unknown cable numbers \[0, 13\]"):
        rodmol.paper_arm(10, tensions={13: 1.0, 0: 2.0, 3: 1.0})


@pytest.mark.parametrize("content, line, what", [
    ("t,T\n0,0\n,1.0\n", 3, "missing time"),
    ("t,T\n0,0\n1.0,\n", 3, "missing tension"),
    ("t,T\n0,0\n1.0,1\n0.5,2\n", 4, "does not increase"),
    ("0,0\n1,2\n1,3\n", 3, "does not increase"),
    ("t,T\n0,0\n1,-1\n", 3, "negative tension"),
], ids=["no-time", "no-tension", "backwards", "repeated", "negative"])
def test_bad_tension_csv_names_file_and_line(tmp_path, content, line, what):
    path = tmp_path / "rig.csv"
    path.write_text(content)
    for read in (rodmol.read_tension_csv, lambda p: rodmol.Cable((0.005, 0), 0.2, p)):
        with pytest.raises(rodmol.ParameterError) as err:
            read(path)
        assert f"{path}:{line}:" in str(err.value) and what in str(err.value)


def test_good_tension_csv_interpolates_linearly(tmp_path):
    path = tmp_path / "rig.csv"
    path.write_text("time [s],tension [N]\n0.0, 0.0\n# paused\n1.0, 2.0\n\n3.0, 1.0\n")
    cable = rodmol.Cable((0.005, 0.0), 0.2, path, name="logged")
    expected = {-1.0: 0.0, 0.0: 0.0, 0.25: 0.5, 1.0: 2.0, 2.0: 1.5, 2.5: 1.25, 3.0: 1.0, 9.0: 1.0}
    for t, value in expected.items():
        assert cable.tension_at(t) == pytest.approx(value, abs=1e-15)


def test_tension_csv_header_after_comment(tmp_path):
    path = tmp_path / "rig.csv"
    path.write_text("# rig log\ntime [s],tension [N]\n0.0,0.0\n1.0,2.0\n")
    assert rodmol.Cable((0.005, 0.0), 0.2, path).tension_at(0.5) == pytest.approx(1.0)


def test_tension_csv_single_cell_first_row_is_an_error(tmp_path):
    path = tmp_path / "rig.csv"
    path.write_text("0.5\n1,2\n2,3\n")
    with pytest.raises(rodmol.ParameterError, match=f"{path}:1:"):
        rodmol.read_tension_csv(path)


# ---------------------------------------------------------------------------
# (f) moving base


def test_base_at_constant_velocity_translates_rod_rigidly():
    """Base velocity (0, 0.01, 0) m/s, the rod moving with it from t = 0, no
    gravity, no fluid: every node moves by v t, strains stay at rest."""
    v = np.array([0.0, 0.01, 0.0])
    rod = rodmol.Rod(0.3, 0.01, SILICONE)
    model = rodmol.Model(rod, 12, gravity=NO_GRAVITY,
                         base=rodmol.BaseMotion(velocity=lambda t: (0.0, 0.01, 0.0)))
    y0 = rodmol.straight_state(model)
    rodmol.StateLayout(12).field(y0, "v")[:] = v
    result = rodmol.simulate(model, 2.0, initial=y0, output_dt=0.1)
    assert result.success
    straight = np.column_stack([model.s_nodes, np.zeros((13, 2))])
    expected = straight[None] + result.t[:, None, None] * v
    np.testing.assert_allclose(result.positions, expected, atol=1e-12)
    np.testing.assert_allclose(result.linear_strain, np.tile([1.0, 0, 0], (len(result.t), 13, 1)),
                               atol=1e-12)
    np.testing.assert_allclose(result.curvature, 0.0, atol=1e-12)
    np.testing.assert_allclose(result.rotations, np.broadcast_to(np.eye(3), result.rotations.shape),
                               atol=1e-12)


def test_base_velocity_is_in_the_base_frame():
    """A base turned 90 deg about z moving at (0.02, 0, 0) in its own frame goes
    along global +y, and so does the whole rod (which points along +y)."""
    turn = ((0.0, -1.0, 0.0), (1.0, 0.0, 0.0), (0.0, 0.0, 1.0))
    rod = rodmol.Rod(0.3, 0.01, SILICONE)
    model = rodmol.Model(rod, 8, gravity=NO_GRAVITY, base=rodmol.BaseMotion(
        velocity=lambda t: (0.02, 0.0, 0.0), position=(0.1, 0.0, 0.0), rotation=turn))
    y0 = rodmol.straight_state(model)
    rodmol.StateLayout(8).field(y0, "v")[:] = (0.02, 0.0, 0.0)
    result = rodmol.simulate(model, 1.0, initial=y0, output_dt=0.5)
    assert result.success
    expected = np.column_stack([np.full(9, 0.1), model.s_nodes + 0.02 * 1.0, np.zeros(9)])
    np.testing.assert_allclose(result.positions[-1], expected, atol=1e-12)
