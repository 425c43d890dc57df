"""Held points (rodmol.Hold): a rod held at both ends against independent
references. A propped cantilever (clamped base, pinned tip) under its
weight against the beam formulas, statically and settled by CVODE; a slack
rod hanging from a pin against ``solve_bvp`` of the same Cosserat rod
(observed order of the centred scheme) and the analytical extensible
catenary; a clamped tip's orientation under a tip moment; bad holds.

The references come from tests/rod_bvp.py through conftest.py's fixtures.
"""

import numpy as np
import pytest

import rodmol
from rodmol import loads as loads_module
from rodmol.discretise import external, load_entries
from rodmol.holds import HOLD_STIFFNESS_FACTOR, default_stiffness

G_ACC = 9.81
# A short stiff rod: small deflections, so the beam formulas hold.
BEAM = dict(length=0.5, radius=0.01, E=1e9, rho=1000.0)
# A long soft rod hanging slack from a pin at 0.8 L: a catenary with a bending boundary layer.
SLACK = dict(length=1.0, radius=0.005, E=1e6, rho=1000.0)
SPAN = 0.8


def _rod(length, radius, E, rho, mu=0.0):
    return rodmol.Rod(length, radius, rodmol.Material(E=E, nu=0.5, mu=mu, rho=rho))


def _section(length, radius, E, rho):
    """(w [N/m], EA [N], GA [N], EI [N m^2]) of the rod (nu = 0.5: G = E / 3)."""
    area = np.pi * radius**2
    return rho * area * G_ACC, E * area, E / 3.0 * area, E * np.pi * radius**4 / 4.0


def _model(rod, n, loads, **kwargs):
    return rodmol.Model(rod, n, gravity=(0.0, 0.0, -G_ACC), medium=rodmol.MEDIA["air"], loads=loads,
                        **kwargs)


def _positions(model, y):
    """Positions (N, 3) [m] of the velocity nodes 1..N in the state y (those the hold reads)."""
    return rodmol.StateLayout(model.n_elements).field(y, "u")


def _hold_wrench(model, y):
    """(force [N], moment [N m]) the holds exert on the rod at rest in the
    state y, global, summed over the holds (their compiled law)."""
    grid = load_entries.of_model(model)
    layout = rodmol.StateLayout(model.n_elements)
    u, quat = layout.field(y, "u"), layout.field(y, "Q")
    out = np.zeros(6)
    for e in np.flatnonzero(np.isin(grid.kind, (external.PIN, external.CLAMP))):
        node = grid.node[e] - 1
        f, m = external.load(grid.kind[e], grid.params[e], tuple(grid.initial[e]), tuple(u[node]),
                             tuple(quat[node]), (0.0, 0.0, 0.0), (0.0, 0.0, 0.0))
        r = _rotation(quat[node])
        out += np.concatenate([r @ f, r @ m])
    return out[:3], out[3:]


def _rotation(quat):
    a, b, c, d = quat / np.linalg.norm(quat)
    return np.array([[a * a + b * b - c * c - d * d, 2 * (b * c - a * d), 2 * (b * d + a * c)],
                     [2 * (b * c + a * d), a * a - b * b + c * c - d * d, 2 * (c * d - a * b)],
                     [2 * (b * d - a * c), 2 * (c * d + a * b), a * a - b * b - c * c + d * d]])


def propped_cantilever(x, length, w, ei, ga):
    """Tip reaction R [N] and deflection [m] (downward positive) at x of a beam
    clamped at 0 and simply supported at ``length`` under a uniform load w
    [N/m], with the shear compliance 1 / GA (Timoshenko; GA = inf is
    Euler-Bernoulli: R = 3 w L / 8)."""
    c = 1.0 / ga
    reaction = w * length * (length**2 / (8 * ei) + c / 2) / (length**2 / (3 * ei) + c)
    bending = (w * x**2 * (6 * length**2 - 4 * length * x + x**2) / (24 * ei)
               - reaction * x**2 * (3 * length - x) / (6 * ei))
    return reaction, bending + c * (w * (length * x - x**2 / 2) - reaction * x)


# --------------------------------------------------------------------------- propped cantilever

def test_propped_cantilever_reaction_and_deflection_match_the_beam_formulas():
    """Base clamped, tip pinned where it is at rest: the tip reaction is
    3 w L / 8 and the midspan deflection Euler-Bernoulli's w L^4 / 192 EI
    (within 1%; a free tip sags 2.4 times more), and both agree with the
    formula that adds the shear compliance (as the Cosserat rod has it)
    to the grid's second-order error."""
    length = BEAM["length"]
    w, _, ga, ei = _section(**BEAM)
    model = _model(_rod(**BEAM), 40, [rodmol.Hold(length)])
    y = rodmol.equilibrium(model)
    force, moment = _hold_wrench(model, y)
    sag = -_positions(model, y)[19, 2]  # node 20 of 40: s = L / 2

    np.testing.assert_allclose(force[2], 3 * w * length / 8, rtol=1e-3)
    np.testing.assert_allclose(moment, 0.0, atol=1e-12)  # a pin holds no moment
    free = w * (length / 2) ** 2 * (6 * length**2 - 2 * length**2 + length**2 / 4) / (24 * ei)
    beam = propped_cantilever(length / 2, length, w, ei, np.inf)[1]
    np.testing.assert_allclose(beam, w * length**4 / (192 * ei), rtol=1e-12)
    assert free > 2.4 * beam
    np.testing.assert_allclose(sag, beam, rtol=1e-2)
    reaction, deflection = propped_cantilever(length / 2, length, w, ei, ga)
    np.testing.assert_allclose(force[2], reaction, rtol=1e-3)
    np.testing.assert_allclose(sag, deflection, rtol=3e-3)


def test_propped_cantilever_settles_with_cvode_onto_the_equilibrium():
    """Released straight, the damped rod settles (CVODE) onto the rest
    state the equilibrium finds, with the tip held within the pin's drift."""
    length = BEAM["length"]
    model = _model(_rod(**BEAM, mu=1e6), 10, [rodmol.Hold(length)])
    rest = _positions(model, rodmol.equilibrium(model))
    result = rodmol.simulate(model, 0.1, initial="straight", output_dt=0.05)
    assert result.success
    settled = result.integrated_positions[-1, 1:]
    np.testing.assert_allclose(settled, rest, atol=1e-3 * np.max(np.abs(rest[:, 2])))
    w, ea, _, _ = _section(**BEAM)
    drift = np.linalg.norm(settled[-1] - (length, 0.0, 0.0))
    assert drift < 3 * w * length / 8 / default_stiffness(ea / model.ds, model.ds, length) * 1.01


# --------------------------------------------------------------------------- slack rod, catenary

def _slack_model(n):
    return _model(_rod(**SLACK), n, [rodmol.Hold(SLACK["length"], position=(SPAN, 0.0, 0.0))])


@pytest.fixture(scope="module")
def slack_states():
    return {n: rodmol.equilibrium(_slack_model(n)) for n in (10, 20, 40)}


def test_slack_rod_matches_solve_bvp_at_second_order(slack_states, clamped_pinned_rod, observed_orders):
    """The rod clamped at the origin and pinned at (0.8 L, 0, 0) hangs as the
    boundary-value problem of the same Cosserat rod says: the node errors
    (max over the nodes) fall at the centred scheme's second order."""
    length = SLACK["length"]
    w, ea, ga, ei = _section(**SLACK)
    shape, _ = clamped_pinned_rod(length, w, ea, ga, ei, (SPAN, 0.0))
    errors = []
    for n, y in slack_states.items():
        model = _slack_model(n)
        u = _positions(model, y)
        x, z = shape(model.s_nodes[1:])[:2]
        np.testing.assert_allclose(u[:, 1], 0.0, atol=1e-12)
        errors.append(np.max(np.hypot(u[:, 0] - x, u[:, 2] - z)))
    assert errors[-1] < 1e-3 * length
    # the pin's force on the rod is the boundary-value problem's internal force at the tip
    model = _slack_model(40)
    force, _ = _hold_wrench(model, slack_states[40])
    n_tip = shape(length)[3:5]
    np.testing.assert_allclose(force[[0, 2]], n_tip, rtol=1e-2)
    assert np.all(observed_orders(errors) > 1.7), errors
    slope = -np.polyfit(np.log([10, 20, 40]), np.log(errors), 1)[0]
    assert slope >= 1.8, errors


def test_slack_rod_hangs_as_the_extensible_catenary_outside_the_bending_layer(
        slack_states, extensible_catenary):
    """A cable has no bending stiffness; the rod's clamp turns it horizontal
    within a boundary layer of length sqrt(EI / H) (H the horizontal
    tension, about 0.26 N here: 4 cm) where the catenary leaves the base at
    55 degrees, so the shapes differ by about that length times the angle;
    the midspan sag, far from the clamp, agrees within 0.5%."""
    length = SLACK["length"]
    w, ea, _, ei = _section(**SLACK)
    x_of, z_of, tension = extensible_catenary(length, w, ea, SPAN)
    layer = np.sqrt(ei / tension)
    model = _slack_model(40)
    u = _positions(model, slack_states[40])
    s = model.s_nodes[1:]
    gap = np.hypot(u[:, 0] - x_of(s), u[:, 2] - z_of(s))
    assert np.max(gap) < layer
    np.testing.assert_allclose(u[19, 2], z_of(0.5 * length), rtol=5e-3)
    # the catenary's supports share the weight; the clamp's moment takes a little off the pin
    force, _ = _hold_wrench(model, slack_states[40])
    assert 0.45 * w * length < force[2] < 0.5 * w * length


# --------------------------------------------------------------------------- clamp

def test_a_clamped_tip_keeps_its_orientation_under_a_tip_moment():
    """A tip moment M about z on a rod clamped at both ends: the tip turns by
    M / (k_r + 4 EI / L), k_r = k r^2 / 4 the clamp's turning stiffness
    (the rod's own 4 EI / L in parallel), i.e. less than M / k_r, and its
    position stays held."""
    length = BEAM["length"]
    moment = 2.0
    _, ea, _, ei = _section(**BEAM)
    model = rodmol.Model(_rod(**BEAM), 20, gravity=(0.0, 0.0, 0.0), medium=rodmol.MEDIA["air"],
                         loads=[rodmol.Hold(length, kind="clamp"),
                                rodmol.PointMoment(length, (0.0, 0.0, moment))])
    y = rodmol.equilibrium(model)
    tip = _rotation(rodmol.StateLayout(20).field(y, "Q")[-1])
    angle = np.arctan2(tip[1, 0], tip[0, 0])
    k_turn = default_stiffness(ea / model.ds, model.ds, length) * BEAM["radius"] ** 2 / 4
    np.testing.assert_allclose(angle, moment / (k_turn + 4 * ei / length), rtol=2e-2)
    assert 0.0 < angle < moment / k_turn
    np.testing.assert_allclose(_positions(model, y)[-1], (length, 0.0, 0.0), atol=1e-9)
    _, held = _hold_wrench(model, y)
    np.testing.assert_allclose(held[2], -moment * k_turn / (k_turn + 4 * ei / length), rtol=2e-2)


def test_a_clamp_turns_the_tip_to_its_held_rotation():
    """A clamp at a rotation other than the rest one (1 degree about z) bends
    the rod: the tip section ends off the held rotation by the clamp's drift,
    the rod's end moment 4 EI theta / L over the turning stiffness."""
    length = BEAM["length"]
    angle = np.radians(1.0)
    c, s = np.cos(angle), np.sin(angle)
    held = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    model = rodmol.Model(_rod(**BEAM), 20, gravity=(0.0, 0.0, 0.0), medium=rodmol.MEDIA["air"],
                         loads=[rodmol.Hold(length, kind="clamp", rotation=held)])
    y = rodmol.equilibrium(model)
    tip = _rotation(rodmol.StateLayout(20).field(y, "Q")[-1])
    mismatch = np.arccos(np.clip((np.trace(held.T @ tip) - 1) / 2, -1.0, 1.0))
    _, ea, _, ei = _section(**BEAM)
    k_turn = default_stiffness(ea / model.ds, model.ds, length) * BEAM["radius"] ** 2 / 4
    np.testing.assert_allclose(mismatch, 4 * ei / length * angle / k_turn, rtol=5e-2)


# --------------------------------------------------------------------------- input checks

@pytest.mark.parametrize("kwargs, fragment", [
    (dict(s=0.0), "`hold `s`` must be > 0"),
    (dict(s=0.3, kind="ball"), "unknown `hold kind` 'ball'"),
    (dict(s=0.3, rotation=np.eye(3)), "kind='clamp' only"),
    (dict(s=0.3, kind="clamp", rotation=2 * np.eye(3)), "must be a rotation matrix"),
    (dict(s=0.3, stiffness=-1.0), "`hold stiffness` must be > 0 N/m"),
    (dict(s=0.3, position=(0.0, 1.0)), "`hold position` must have three components"),
])
def test_bad_holds_are_refused_by_name(kwargs, fragment):
    with pytest.raises(rodmol.ParameterError, match=None) as info:
        rodmol.Hold(**kwargs)
    assert fragment in str(info.value)


def test_a_hold_between_nodes_or_beyond_the_tip_is_refused_before_any_work():
    rod = _rod(**BEAM)
    with pytest.raises(rodmol.ParameterError, match=r"velocity node .* got 0\.26 m"):
        _model(rod, 10, [rodmol.Hold(0.26)])
    with pytest.raises(rodmol.ParameterError, match=r"`s` must lie in \(0, L"):
        _model(rod, 10, [rodmol.Hold(0.6)])


def test_default_law_is_the_documented_multiple_of_the_element_and_critical():
    """k = HOLD_STIFFNESS_FACTOR E A / ds L / ds (a compliance O(ds^2) against the rod's);
    c = 2 sqrt(k m), m = rho A ds."""
    model = _model(_rod(**BEAM), 10, [rodmol.Hold(0.25, kind="clamp")])
    grid = load_entries.of_model(model)
    _, ea, _, _ = _section(**BEAM)
    k = HOLD_STIFFNESS_FACTOR * ea / model.ds * BEAM["length"] / model.ds
    mass = BEAM["rho"] * np.pi * BEAM["radius"] ** 2 * model.ds
    law = load_entries.hold_law(model.loads[0], ea / model.ds, mass, BEAM["radius"], model.ds, BEAM["length"])
    columns = [loads_module.P_STIFFNESS, loads_module.P_DAMPING, loads_module.P_TURN_STIFFNESS,
               loads_module.P_TURN_DAMPING]
    np.testing.assert_allclose(grid.params[0, columns], law, rtol=1e-12)
    np.testing.assert_allclose(law, (k, 2 * np.sqrt(k * mass), k * BEAM["radius"] ** 2 / 4,
                                     2 * np.sqrt(k * mass) * BEAM["radius"] ** 2 / 4), rtol=1e-12)
    assert list(grid.node) == [5]


def test_a_very_stiff_pin_still_gives_the_propped_cantilever():
    """1000 times the default stiffness: the equilibrium's residual floor is
    raised for the pinned node's force rows only, so the rest state (its
    positions rebuilt from the strains) still carries the beam's reaction."""
    length = BEAM["length"]
    w, ea, ga, ei = _section(**BEAM)
    model = _model(_rod(**BEAM), 20, [])
    k = 1e3 * HOLD_STIFFNESS_FACTOR * ea / model.ds
    model = model.replace(loads=[rodmol.Hold(length, stiffness=k)])
    force, _ = _hold_wrench(model, rodmol.equilibrium(model))
    np.testing.assert_allclose(force[2], propped_cantilever(length, length, w, ei, ga)[0], rtol=2e-3)


def test_a_stiffer_slack_rod_sags_instead_of_staying_compressed(clamped_pinned_rod):
    """Ten times stiffer (E = 10 MPa): ramped together with the weight, the
    pulled-in pin kept the rod on the straight, compressed branch (strain
    -0.2, a rest state the dynamics would leave at once); the equilibrium
    lets the rod sag first and then moves the pin in steps, so it hangs as
    ``solve_bvp`` says."""
    stiff = dict(SLACK, E=1e7)
    length = stiff["length"]
    w, ea, ga, ei = _section(**stiff)
    shape, _ = clamped_pinned_rod(length, w, ea, ga, ei, (SPAN, 0.0))
    model = _model(_rod(**stiff), 20, [rodmol.Hold(length, position=(SPAN, 0.0, 0.0))])
    u = _positions(model, rodmol.equilibrium(model))
    x, z = shape(model.s_nodes[1:])[:2]
    assert np.max(np.hypot(u[:, 0] - x, u[:, 2] - z)) < 5e-3 * length


def test_the_compiled_hold_law_against_scipy_rotations():
    """Pin: F = R^T (-k (u - p)) - c v, local. Clamp: M = k_r sin(theta) n - c_r w,
    theta n the rotation vector (local) from the section to the held orientation
    (scipy's Rotation, scalar-last), whatever the quaternions' signs and norms."""
    from scipy.spatial.transform import Rotation

    rng = np.random.default_rng(7)
    section, held = Rotation.random(2, random_state=rng)
    quat = 1.3 * np.roll(section.as_quat(), 1)  # rodmol's quaternions: scalar first, any norm
    held_quat = -0.8 * np.roll(held.as_quat(), 1)
    u, p, shift = rng.normal(size=3), rng.normal(size=3), rng.normal(size=3)
    v, w = rng.normal(size=3), rng.normal(size=3)
    row = np.zeros(loads_module.N_PARAMS)
    row[:3], row[3:7] = p, held_quat
    k, c, k_r, c_r = 3.0, 0.5, 0.2, 0.05
    row[[loads_module.P_STIFFNESS, loads_module.P_DAMPING, loads_module.P_TURN_STIFFNESS,
         loads_module.P_TURN_DAMPING]] = k, c, k_r, c_r
    r = section.as_matrix()
    theta = (section.inv() * held).as_rotvec()  # local: held = section * exp(theta)
    angle = np.linalg.norm(theta)
    for kind, moment in ((external.PIN, np.zeros(3)),
                         (external.CLAMP, k_r * np.sin(angle) * theta / angle - c_r * w)):
        f, m = external.load(kind, row, tuple(shift), tuple(u), tuple(quat), tuple(v), tuple(w))
        np.testing.assert_allclose(f, r.T @ (-k * (u - p - shift)) - c * v, rtol=1e-12, atol=1e-14)
        np.testing.assert_allclose(m, moment, rtol=1e-12, atol=1e-14)


@pytest.mark.parametrize("kind", ["pin", "clamp"])
def test_an_undamped_hold_conserves_the_energy_with_its_penalty(kind):
    """mu = 0, no gravity, no fluid, hold damping 0: the hold is a spring, so
    kinetic + strain + its penalty energy (``energy()["hold"]``, which starts
    with all of it: the rod is released straight, 1 mm from the held point
    and, for a clamp, 3 degrees off the held rotation) stays constant."""
    length = BEAM["length"]
    rod = rodmol.Rod(length, 0.01, rodmol.Material(E=1e6, nu=0.5, mu=0.0, rho=1000.0))
    angle = np.radians(3.0)
    turned = np.array([[np.cos(angle), 0.0, np.sin(angle)], [0.0, 1.0, 0.0],
                       [-np.sin(angle), 0.0, np.cos(angle)]])
    hold = rodmol.Hold(length, kind=kind, position=(length, 1e-3, 0.0), stiffness=50.0, damping=0.0,
                       rotation=turned if kind == "clamp" else None)
    model = rodmol.Model(rod, 10, gravity=(0.0, 0.0, 0.0), medium=rodmol.MEDIA["air"], loads=[hold])
    result = rodmol.simulate(model, 0.2, initial="straight", output_dt=0.01, rtol=1e-8)
    assert result.success
    e = rodmol.energy(model, result)
    start = e["hold"][0]
    np.testing.assert_allclose(start, 0.5 * 50.0 * 1e-6 + (kind == "clamp") * 50.0 * 0.01**2 / 4
                               * (1 - np.cos(angle)), rtol=1e-9)
    assert np.min(e["hold"]) < 0.7 * start  # the spring gives its energy to the rod and back
    np.testing.assert_allclose(e["kinetic"] + e["strain"] + e["hold"], start, rtol=1e-4)
