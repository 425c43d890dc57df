"""Dynamics of the semi-discrete rod: vibration frequency and damping against an
independent beam calculation, energy conservation and dissipation, agreement
of the two time integrators, and bounded quaternion drift.
"""

import numpy as np
import pytest
from scipy.integrate import cumulative_trapezoid, solve_bvp
from vibration import measure_free_vibration

import rodmol
from rodmol.discretise.schemes import DEFAULT_SCHEME, get_scheme
from rodmol.output.stream import RunWriter

# Table I, restated so that the reference calculations do not read rodmol.
L = 0.418  # m
R_BASE, R_TIP = 0.015, 0.004  # m
E, NU, MU, RHO = 110e3, 0.5, 300.0, 1080.0  # Pa, -, Pa s, kg/m^3
G_SHEAR = E / (2.0 * (1.0 + NU))
# For nu = 0.5 the Kelvin-Voigt law of MODEL.md is stiffness-proportional:
# Vl = tau Kl and Vth = tau Kth with tau = 3 mu / E, so every linear mode
# has the damping ratio zeta = omega tau / 2.
TAU = 3.0 * MU / E


def tapered(s):
    return R_BASE + (R_TIP - R_BASE) * s / L


# --------------------------------------------------------------------------
# (a) first bending mode of the tapered cantilever in air, about the straight state
# --------------------------------------------------------------------------

def beam_first_mode(radius, length=L, rotary=True, shear=True):
    """First bending mode of a clamped-free beam by ``solve_bvp`` (omega^2 is a parameter).

    Timoshenko beam with shear factor 1 and rotary inertia rho J, which is what
    the linearised Cosserat rod with Kl = (EA, GA, GA), Kth = (.., EJ, EJ) is;
    with ``rotary=shear=False`` it is the Euler-Bernoulli beam. Unknowns:
    deflection W, section rotation P, moment M, shear force V:

        W' = P + V / (G A),  P' = M / (E J),
        M' = -V - omega^2 rho J P,  V' = -omega^2 rho A W,

    W(0) = P(0) = 0, M(L) = V(L) = 0, normalised by W(L) = 1. The guess is the
    static deflection of a uniformly loaded cantilever, which leads to the
    first mode. Returns (omega [rad/s], solution).
    """
    def rhs(s, z, p):
        w, rot, m, v = z
        r = radius(s)
        area, inertia = np.pi * r**2, np.pi * r**4 / 4.0
        return np.vstack([rot + (v / (G_SHEAR * area) if shear else 0.0),
                          m / (E * inertia),
                          -v - (p[0] * RHO * inertia * rot if rotary else 0.0),
                          -p[0] * RHO * area * w])

    def bc(a, b, p):
        return np.array([a[0], a[1], b[2], b[3], b[0] - 1.0])

    s = np.linspace(0.0, length, 101)
    x = s / length
    w = x**2 * (6.0 - 4.0 * x + x**2) / 3.0
    guess = np.vstack([w, np.gradient(w, s), np.zeros_like(s), np.zeros_like(s)])
    sol = solve_bvp(rhs, bc, s, guess, p=[4.0], tol=1e-8, max_nodes=100_000)
    assert sol.success, sol.message
    # A first mode has no node between the clamp and the tip.
    assert np.all(sol.sol(s[1:])[0] > 0.0)
    return float(np.sqrt(sol.p[0])), sol


def test_reference_eigensolver_uniform_cantilever():
    """Check the reference: uniform Euler-Bernoulli cantilever,
    omega_1 = 1.8751041^2 sqrt(E J / (rho A L^4))."""
    r = 0.01
    omega, _ = beam_first_mode(lambda s: np.full_like(s, r), rotary=False, shear=False)
    exact = 1.87510407**2 * np.sqrt(E * np.pi * r**4 / 4.0 / (RHO * np.pi * r**2 * L**4))
    assert omega == pytest.approx(exact, rel=1e-6)


@pytest.fixture(scope="module")
def first_mode():
    omega, sol = beam_first_mode(tapered)
    omega_eb, _ = beam_first_mode(tapered, rotary=False, shear=False)
    return omega, omega_eb, sol


@pytest.fixture(scope="module", params=["upwind", "centred"])
def vibration_runs(first_mode, request):
    """Free vibration of the tapered arm in air, gravity off, for several N.

    The arm starts straight with the velocity field of the continuum first
    mode (v_y = a omega W(s), w_z = a omega P(s), tip amplitude a = 1 % of L, so
    the motion is linear), which excites the discrete first mode almost alone.
    """
    omega, _, sol = first_mode
    period = 2.0 * np.pi / omega
    amplitude = 0.01 * L
    out = {}
    for n in (25, 50, 100):
        model = rodmol.Model(rodmol.arm.paper_rod(), n, medium="air", gravity=(0.0, 0.0, 0.0))
        lay = rodmol.StateLayout(n)
        y0 = rodmol.straight_state(model)
        w, rot = sol.sol(model.s_nodes[1:])[:2]  # velocity nodes 1..N
        lay.field(y0, "v")[:, 1] = amplitude * omega * w
        lay.field(y0, "w")[:, 2] = amplitude * omega * rot
        res = rodmol.simulate(model, 4.0 * period, initial=y0, rtol=1e-7,
                              output_dt=period / 200.0, scheme=request.param)
        assert res.success, res.message
        keep = res.t > 0.5 * period  # let the small higher-mode content decay
        tip_y = res.tip[keep, 1]
        assert np.max(np.abs(tip_y)) < 1.1 * amplitude  # small, linear motion
        assert np.max(np.abs(res.tip[:, 2])) < 1e-12  # stays in its plane
        out[n] = measure_free_vibration(res.t[keep], tip_y)
    return request.param, out


def test_first_bending_frequency(first_mode, vibration_runs):
    omega_ref, omega_eb, _ = first_mode
    scheme, runs = vibration_runs
    ns = np.array(sorted(runs), dtype=int)
    omegas = np.array([runs[n][0] for n in ns])
    rel = omegas / omega_ref - 1.0
    order = np.polyfit(np.log(L / ns), np.log(np.abs(rel)), 1)[0]
    richardson = 2.0 * omegas[-1] - omegas[-2]
    print(f"\n{scheme}: reference omega_1 = {omega_ref:.6f} rad/s (Euler-Bernoulli {omega_eb:.6f}); "
          f"rodmol N={ns.tolist()}: {omegas}, relative errors {rel}, order {order:.3f}, "
          f"Richardson {richardson:.6f} ({richardson / omega_ref - 1:+.2e})")

    if scheme == "upwind":
        # The O(ds) scheme: a few percent at N = 50, halving with ds.
        assert abs(rel[ns == 50][0]) < 0.05
        assert abs(rel[ns == 100][0]) < 0.025
        assert 0.8 <= order <= 1.3
        # With the leading C ds term removed the continuum value is recovered.
        assert richardson == pytest.approx(omega_ref, rel=5e-3)
    else:
        # The O(ds^2) scheme is at the period estimate's own floor (~1e-5)
        # already at N = 25, where the upwind scheme is 10% off.
        assert np.all(np.abs(rel) < 5e-5)


def test_damping_ratio_matches_kelvin_voigt(first_mode, vibration_runs):
    omega_ref = first_mode[0]
    for n, (omega, zeta) in sorted(vibration_runs[1].items()):
        print(f"\nN={n}: zeta = {zeta:.6f}, omega tau / 2 = {omega * TAU / 2:.6f} "
              f"(continuum {omega_ref * TAU / 2:.6f})")
        # The discrete system is exactly stiffness-proportional too, so its mode
        # has zeta = omega_discrete tau / 2; only the measurement errs here.
        assert zeta == pytest.approx(omega * TAU / 2.0, rel=0.01)
        # Against the continuum: off by the frequency's discretisation error.
        allowed = abs(omega / omega_ref - 1.0) + 0.01
        assert zeta == pytest.approx(omega_ref * TAU / 2.0, rel=allowed)


# --------------------------------------------------------------------------
# (b) energy: conserved with mu = 0, dissipated at the Kelvin-Voigt rate with mu > 0
# --------------------------------------------------------------------------

def deformed_moving_state(n):
    """A deformed, non-equilibrium start: the static droop under a skew load in
    air (bending about y and z), plus a twisting and swinging velocity field."""
    model = rodmol.Model(rodmol.arm.paper_rod(), n, medium="air", gravity=(0.0, -4.0, 3.0))
    y0 = rodmol.equilibrium(model)
    lay = rodmol.StateLayout(n)
    s = model.s_nodes[1:]
    lay.field(y0, "v")[:] = np.c_[0.0 * s, 0.2 * s, -0.1 * s]  # m/s
    lay.field(y0, "w")[:] = np.c_[3.0 * s / L, 0.0 * s, 0.0 * s]  # rad/s, torsion
    return y0


GRAVITY_CASES = {"no gravity": (0.0, 0.0, 0.0), "gravity": (0.0, -9.81, 0.0)}


@pytest.mark.parametrize("gravity", GRAVITY_CASES.values(), ids=GRAVITY_CASES.keys())
def test_energy_conserved_without_viscosity(gravity):
    """mu = 0, no fluid: kinetic + strain (+ gravity potential) is a first
    integral of the semi-discrete system, so it drifts only by integration
    error, which shrinks with the tolerance."""
    n = 20
    y0 = deformed_moving_state(n)
    model = rodmol.Model(rodmol.arm.paper_rod(), n, medium=None, gravity=gravity,
                         viscosity=False)
    drift = {}
    for rtol in (1e-7, 1e-9):
        res = rodmol.simulate(model, 0.5, initial=y0, rtol=rtol, output_dt=0.005)
        assert res.success, res.message
        e = rodmol.energy(model, res)
        scale = e["kinetic"][0] + e["strain"][0]  # energy in motion and deformation
        drift[rtol] = float(np.max(np.abs(e["total"] - e["total"][0])) / scale)
        # Energy does move between kinetic, strain (and potential) forms.
        assert np.ptp(e["kinetic"]) > 0.1 * scale
    print(f"\nrelative energy drift: {drift}")
    assert drift[1e-7] < 1e-6
    assert drift[1e-9] < 0.1 * drift[1e-7]


@pytest.mark.parametrize("gravity", GRAVITY_CASES.values(), ids=GRAVITY_CASES.keys())
def test_energy_dissipated_by_viscosity(gravity):
    """mu > 0: the energy never increases, and it decreases exactly by the
    Kelvin-Voigt dissipation  D = ds sum(q_t . Vl q_t + k_t . Vth k_t),
    with the strain rates recovered from the output stresses."""
    n = 20
    y0 = deformed_moving_state(n)
    model = rodmol.Model(rodmol.arm.paper_rod(), n, medium=None, gravity=gravity)
    res = rodmol.simulate(model, 0.5, initial=y0, rtol=1e-8, output_dt=0.001)
    assert res.success, res.message
    e = rodmol.energy(model, res)
    total = e["total"]
    scale = e["kinetic"][0] + e["strain"][0]

    increase = np.max(np.diff(total)) / scale
    assert increase < 1e-9  # never increases (beyond round-off and tolerance)
    dissipated = total[0] - total[-1]
    assert dissipated > 0.03 * scale

    # Energy balance E(t) + W(t) = const, W = integral of D. The strain rates
    # jump in a short viscous layer at t = 0 that the output frames do not
    # resolve, so the balance is checked from t = 0.05 s on (trapezoid rule,
    # O(dt^2)).
    dq = res.linear_strain[:, :-1] - np.array([1.0, 0.0, 0.0])
    k = res.curvature[:, :-1]
    kl, kth, vl, vth = rodmol.SemiDiscrete(model, res.meta["scheme"]).cells
    q_t = (res.internal_force[:, :-1] - kl * dq) / vl
    k_t = (res.internal_moment[:, :-1] - kth * k) / vth
    rate = model.ds * (np.einsum("tni,ni,tni->t", q_t, vl, q_t)
                       + np.einsum("tni,ni,tni->t", k_t, vth, k_t))
    work = cumulative_trapezoid(rate, res.t, initial=0.0)
    i = np.searchsorted(res.t, 0.05)
    balance = (total[i:] - total[i]) + (work[i:] - work[i])
    error = np.max(np.abs(balance)) / (total[i] - total[-1])
    print(f"\ndissipated {dissipated / scale:.4f} of the energy; max increase {increase:.2e}; "
          f"balance error {error:.2e} of the energy dissipated after 0.05 s")
    assert error < 1e-4


# --------------------------------------------------------------------------
# (c) the two backends agree
# --------------------------------------------------------------------------

def test_cvode_and_rk23_agree():
    """Implicit BDF (CVODE) and explicit RK23 integrate the same right-hand
    side: released from straight in water under gravity while cable 11 is
    ramped to 1 N, their centrelines agree to far below the motion."""
    model = rodmol.paper_arm(20, tensions={11: [(0.0, 0.0), (0.1, 1.0)]})
    runs = {b: rodmol.simulate(model, 0.2, initial="straight", backend=b, rtol=1e-7,
                               output_dt=0.01) for b in ("cvode", "rk23")}
    for r in runs.values():
        assert r.success, r.message
    a, b = runs["cvode"], runs["rk23"]
    assert np.array_equal(a.t, b.t)
    motion = np.max(np.linalg.norm(a.tip - a.tip[0], axis=1))
    diff = np.max(np.linalg.norm(a.positions - b.positions, axis=-1))
    dv = np.max(np.abs(a.velocity - b.velocity))
    print(f"\ntip motion {motion / L:.3e} L; max centreline difference {diff / L:.2e} L; "
          f"max velocity difference {dv:.2e} m/s")
    assert motion > 0.01 * L
    assert diff < 1e-6 * L
    assert dv < 2e-5 * motion / 0.2  # velocities agree too, relative to a mean speed (measured 1.1e-5)


# --------------------------------------------------------------------------
# (d) quaternion drift over a long run, and periodicity under periodic input
# --------------------------------------------------------------------------

PERIOD = 3.0  # s, period of the tension input below


def oscillating_tension(t):
    return 1.0 + 0.5 * np.sin(2.0 * np.pi * t / PERIOD)


@pytest.fixture(scope="module")
def long_runs():
    """60 s of the paper's arm (N = 10, water, gravity) with cable 11 pulled
    1 +- 0.5 N at a 3 s period, so it keeps moving the whole time."""
    out = {}
    for rtol in (1e-6, 1e-7):
        model = rodmol.paper_arm(10, tensions={11: oscillating_tension})
        res = rodmol.simulate(model, 60.0, initial="straight", rtol=rtol, output_dt=0.05)
        assert res.success, res.message
        out[rtol] = res
    return out


def test_stored_quaternions_have_unit_norm(long_runs):
    # The integrator lets |Q| stray by up to its tolerance (2.8e-6 at rtol 1e-6
    # before the projection); the states handed back are on the unit sphere.
    for res in long_runs.values():
        assert res.quaternion_norm_error.max() < 1e-12


def test_projection_keeps_the_norm_and_does_not_move_the_tip(tmp_path, monkeypatch):
    """Fetching test, N = 10, 3 s at default tolerances, streamed in chunks of 25
    frames (each chunk restarts the solver from the projected state): the
    frames' |Q| stay within 1e-6 of 1, where without the projection they
    stray by 7.8e-5, and the tip is where it is without the projection."""
    model = rodmol.scenarios.get("fetching").model(10)

    def run(name):
        res = rodmol.simulate(model, 3.0, out=RunWriter(tmp_path / name, chunk_frames=25, views=False))
        assert res.success, res.message
        return res.positions[:, -1], res.quaternion_norm_error.max()

    tip, drift = run("projected")
    monkeypatch.setattr(rodmol.StateLayout, "project_quaternions", lambda self, y: None)
    tip_before, drift_before = run("as before")
    assert drift < 1e-6 < drift_before
    rtol, length = get_scheme(DEFAULT_SCHEME).default_rtol, model.rod.length
    # measured 4.6e-9 m, against the integrator's rtol L = 1.3e-5 m
    assert np.max(np.linalg.norm(tip - tip_before, axis=-1)) < 0.01 * rtol * length


def _one_period_later(res, t0):
    i = np.searchsorted(res.t, t0 - 1e-9)
    j = np.searchsorted(res.t, t0 + PERIOD - 1e-9)
    assert res.t[i] == pytest.approx(t0) and res.t[j] == pytest.approx(t0 + PERIOD)
    return i, j


def test_periodic_input_gives_periodic_shape(long_runs):
    """A clamped damped arm under a periodic input settles to a periodic motion:
    after 30 s, strains and orientations repeat from one period to the next."""
    res = long_runs[1e-7]
    for t0 in (30.0, 50.0):
        i, j = _one_period_later(res, t0)
        assert np.max(np.abs(res.curvature[j] - res.curvature[i])) < 1e-3 / L
        assert np.max(np.abs(res.linear_strain[j] - res.linear_strain[i])) < 1e-5
        assert np.max(np.abs(res.rotations[j] - res.rotations[i])) < 1e-4


def test_periodic_input_gives_periodic_positions(long_runs):
    """Same settled periodic motion: the centreline must repeat too (to 0.1 % L)."""
    res = long_runs[1e-7]
    for t0 in (30.0, 50.0):
        i, j = _one_period_later(res, t0)
        drift = np.max(np.linalg.norm(res.positions[j] - res.positions[i], axis=-1))
        print(f"\ncentreline change over one period from t = {t0} s: {drift / L:.2e} L")
        assert drift < 1e-3 * L


# --------------------------------------------------------------------------
# (e) observed order in space of the tip trajectory, both schemes
# --------------------------------------------------------------------------

@pytest.mark.parametrize("scheme, order", [("upwind", 1), ("centred", 2)])
def test_tip_trajectory_converges_at_the_schemes_order(scheme, order):
    """The bending test's first second (cable 11 ramped to 2 N, the arm
    swings up), at a tolerance far below the space error: the largest tip
    difference between N and 2N halves (upwind) or quarters (centred) as N
    doubles. The full study to N = 800 is solvers/convergence.py."""
    scenario = rodmol.scenarios.get("bending")
    tips = []
    for n in (12, 24, 48):
        res = rodmol.simulate(scenario.model(n), 1.0, scheme=scheme, rtol=1e-8, output_dt=0.01)
        assert res.success, res.message
        tips.append(res.tip)
    d = [np.max(np.linalg.norm(b - a, axis=1)) for a, b in zip(tips, tips[1:])]
    observed = np.log2(d[0] / d[1])
    print(f"\n{scheme}: differences {d} m, observed order {observed:.3f}")
    assert order - 0.3 < observed < order + 0.5


# --------------------------------------------------------------------------
# (f) continuation from a Result, explicit t0, output at given times
# --------------------------------------------------------------------------

def test_continued_run_matches_an_uninterrupted_one():
    """0-1 s, then 1-2 s from the first Result, ends where one 0-2 s run ends
    (the pull ramps through t = 1 s: the inputs are read at absolute time)."""
    model = rodmol.scenarios.get("bending").model(12)
    whole = rodmol.simulate(model, 2.0, rtol=1e-9, output_dt=0.1)
    first = rodmol.simulate(model, 1.0, rtol=1e-9, output_dt=0.1)
    second = rodmol.simulate(model, 2.0, initial=first, rtol=1e-9, output_dt=0.1)
    assert second.t[0] == 1.0 and second.t[-1] == 2.0
    np.testing.assert_array_equal(second.states[0], first.states[-1])
    np.testing.assert_allclose(second.tensions[-1], whole.tensions[-1])
    gap = np.max(np.abs(second.positions[-1] - whole.positions[-1]))
    motion = np.max(np.abs(whole.positions[-1] - whole.positions[0]))
    print(f"\ncontinued vs whole: {gap:.2e} m of {motion:.2e} m of motion")
    assert motion > 0.05 and gap < 1e-6 * motion


def test_output_at_given_times_and_from_t0():
    model = rodmol.scenarios.get("bending").model(10)
    times = [0.13, 0.5, 0.777]
    res = rodmol.simulate(model, 1.0, output_times=times)
    np.testing.assert_array_equal(res.t, [0.0, *times, 1.0])
    late = rodmol.simulate(model, 1.0, t0=0.5, output_dt=0.25)
    np.testing.assert_allclose(late.t, [0.5, 0.75, 1.0])
    # started at the equilibrium under the tension at t0 = 0.5 s, not at 0
    np.testing.assert_allclose(late.tensions[0], model.tensions(0.5))
    np.testing.assert_allclose(late.states[0], rodmol.equilibrium(model, 0.5), atol=1e-12)
    assert np.max(np.abs(late.states[0] - rodmol.equilibrium(model, 0.0))) > 1e-3
    for bad, says in (({"output_times": [0.5, 0.2]}, "increasing"), ({"output_times": [2.0]}, "lie in"),
                      ({"t0": 1.5}, "after the start")):
        with pytest.raises(rodmol.ParameterError, match=says):
            rodmol.simulate(model, 1.0, **bad)
