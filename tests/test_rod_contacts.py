"""Contact between rods (rodmol.RodContact) against independent references:
a rod resting across another carries the share of its weight that beam
theory gives a propped cantilever, at a gap of the two radii within the
law's stated penetration (statics and a dynamic settle); two parallel rods
pressed together by a distributed load feel it as their contact line force;
a declared contact that never touches leaves a run as it was; bad input is
refused naming the parameter."""

import numpy as np
import pytest

import rodmol
from rodmol.discretise.assembly import Assembly
from rodmol.discretise.external import penalty
from rodmol.discretise.rod_contact import SAMPLE_SPACING
from rodmol.errors import ParameterError

G, L, R, N = 9.81, 0.3, 0.01, 12
SOFT = rodmol.Material(E=1e7, nu=0.5, mu=2e4, rho=1000.0)
STIFF = rodmol.Material(E=1e9, nu=0.5, mu=2e6, rho=1000.0)  # a support that hardly bends
ALONG_Z = np.array([[0.0, 0.0, -1.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]])  # the rod's x axis along global z
# Where the upper rod crosses the lower one: on a sample of each rod, off their nodes (a crossing
# at a node is a kink of the nodes' shares, where Newton's iterations stall).
CROSS, OFFSET = 0.2025, 0.0075


def _rod(material, **base):
    return rodmol.Model(rodmol.Rod(L, radius=R, material=material), N, base=rodmol.BaseMotion(**base))


def _crossing(height=2 * R, **law):
    """The upper rod, clamped at its base, lies across the lower one, clamped at both ends, at x = CROSS."""
    lower = _rod(STIFF, position=(CROSS, 0.0, -L / 2 - OFFSET), rotation=ALONG_Z)
    upper = _rod(SOFT, position=(0.0, height, 0.0))
    return rodmol.System({"lower": lower, "upper": upper}, joints=[rodmol.Joint(("lower", "tip"), "world")],
                         contacts=[rodmol.RodContact("upper", "lower", **law)], gravity=(0.0, -G, 0.0))


def _propped_reaction(w, length, a):
    """The support's reaction [N] under a uniform load ``w`` [N/m] of a cantilever of ``length``
    [m] propped at ``a`` [m] from its clamp (Euler-Bernoulli, rigid prop)."""
    return w * (6 * length**2 - 4 * length * a + a**2) / (8 * a)


def _depth(force, stiffness, length, h):
    """The depth at which the law's penalty k length P(d) carries ``force`` [N] (P of external.penalty)."""
    p = force / (stiffness * length)
    return np.sqrt(2 * h * p) if p < h / 2 else p + h / 2


def _check_resting(assembly, y):
    pairs = assembly.rod_pairs
    pairs.evaluate(y)
    on_upper, on_lower = pairs.node_forces("upper"), pairs.node_forces("lower")
    np.testing.assert_allclose(on_upper.sum(axis=0), -on_lower.sum(axis=0), rtol=0, atol=1e-12)  # equal, opposite
    carried = on_upper.sum(axis=0)[1]
    expected = _propped_reaction(SOFT.rho * np.pi * R**2 * G, L, CROSS)
    assert carried == pytest.approx(expected, rel=5e-3)
    # The stated penetration: a crossing on a sample of each rod, each side half the stiffness over
    # a sample's length (the total on both), deeper by at most spacing^2 / (8 (r_a + r_b)) off them.
    k, _, _, _, h = assembly.system.rod_pairs[0][1].law(assembly.rods["upper"].model, assembly.rods["lower"].model)
    spacing = L / N / pairs.pairs[0]["samples"][0]
    assert spacing <= SAMPLE_SPACING * 2 * R
    stated = _depth(carried, k, spacing, h) + spacing**2 / (8 * 2 * R)
    assert 0.0 < -pairs.least_gap <= stated
    return carried


def test_a_rod_resting_across_another_carries_the_propped_cantilevers_share_at_rest():
    assembly = Assembly(_crossing())
    y = rodmol.equilibrium(assembly)
    _check_resting(assembly, y)


def test_a_rod_released_across_another_settles_where_the_statics_put_it():
    run = rodmol.simulate(_crossing(), 2.0, output_dt=0.5)  # released straight: it sags onto the support
    assert run.success
    assert run.stats["rod_contact_pairs"] >= 1 and run.stats["rod_contact_least_gap"] < 0.0
    carried = _check_resting(run.assembly, run.states[-1])
    # The recorded external force of each rod holds the contact forces (the lower rod's, off its tip hold).
    lower = run["lower"]
    recorded = np.einsum("ni,n->i", lower.external_force[-1, :-1], lower.node_length[:-1])
    assert recorded[1] == pytest.approx(-carried, rel=1e-6)


def test_parallel_rods_pressed_together_feel_the_load_as_their_contact_line_force():
    load = 20.0  # [N/m], pressing the rods together along their whole length
    k, _, _, _, h = rodmol.RodContact("lower", "upper").law(_rod(SOFT), _rod(SOFT))
    # Each rod's ends held where the law's depth under the load puts them: then nothing bends
    # the rods, and their every node must feel the load as contact (a clamp at zero depth would
    # carry a share of it by bending, over a boundary layer of an element here).
    depth = _depth(load, k, 1.0, h)
    lower = _rod(SOFT).replace(loads=[rodmol.DistributedForce((0.0, load, 0.0))])
    upper = _rod(SOFT, position=(0.0, 2 * R - depth, 0.0)).replace(
        loads=[rodmol.DistributedForce((0.0, -load, 0.0))])
    system = rodmol.System({"lower": lower, "upper": upper},
                           joints=[rodmol.Joint(("lower", "tip"), "world"), rodmol.Joint(("upper", "tip"), "world")],
                           contacts=[rodmol.RodContact("lower", "upper")], gravity=(0.0, 0.0, 0.0))
    assembly = Assembly(system)
    y = rodmol.equilibrium(assembly)
    pairs = assembly.rod_pairs
    pairs.evaluate(y)
    line = pairs.node_forces("upper")[1:, 1] / assembly.rods["upper"].node_lengths
    np.testing.assert_allclose(line, load, rtol=1e-3)
    np.testing.assert_allclose(pairs.node_forces("upper").sum(axis=0), -pairs.node_forces("lower").sum(axis=0),
                               rtol=0, atol=1e-12 * load)
    assert -pairs.least_gap == pytest.approx(depth, rel=1e-2)


def test_a_declared_contact_that_never_touches_leaves_the_run_unchanged():
    far = _crossing(height=0.1)
    alone = far.replace(contacts=[])
    runs = [rodmol.simulate(s, 0.05, output_dt=0.025) for s in (far, alone)]
    assert all(run.success for run in runs)
    np.testing.assert_array_equal(runs[0].states, runs[1].states)
    assert runs[0].stats["steps"] == runs[1].stats["steps"]
    assert runs[0].stats["rod_contact_pairs"] == 0 and runs[0].stats["rod_contact_least_gap"] == np.inf


def _hairpin(s, bend, leg):
    """Centreline points at arc lengths ``s``: a leg of length ``leg`` along x, a half turn of
    radius ``bend`` and a leg back, 2 ``bend`` above the first."""
    turn = np.clip((s - leg) / bend, 0.0, np.pi)
    back = np.maximum(s - leg - np.pi * bend, 0.0)
    x = np.minimum(s, leg) + bend * np.sin(turn) - back
    y = bend * (1.0 - np.cos(turn))
    return np.stack([x, y, 0.0 * s], axis=1)


def test_a_rods_self_contact_touches_only_parts_apart_along_it():
    """A hairpin bent as tightly as a tube of radius r can be (bend radius 1.05 r): its parts
    within pi r along it are within 2 r of each other, yet nothing touches; bent tighter
    (0.95 r) its legs overlap and push each other apart, equal and opposite."""
    model = rodmol.Model(rodmol.Rod(0.2, radius=R, material=SOFT), 40)
    assembly = Assembly(rodmol.System({"rod": model}, contacts=[rodmol.RodContact("rod", "rod")]))
    pairs, lay = assembly.rod_pairs, assembly.rods["rod"].layout
    y = assembly.undeformed_state()
    for bend, touching in ((1.05 * R, False), (0.95 * R, True)):
        lay.blocks(y)[:, lay.slices()["u"]] = _hairpin(model.s_nodes, bend, 0.08)[1:]
        pairs.evaluate(y)
        assert (pairs.active > 0) == touching
        forces = pairs.node_forces("rod")
        np.testing.assert_allclose(forces.sum(axis=0), 0.0, atol=1e-12 * max(1.0, np.abs(forces).max()))
        if touching:  # the legs pushed apart
            assert forces[1:12, 1].sum() < 0.0 < forces[-12:, 1].sum()


@pytest.mark.parametrize("bad, key", [
    (dict(b="missing"), "missing"),
    (dict(stiffness=-1.0), "stiffness"),
    (dict(damping=-1.0), "damping"),
    (dict(friction=-0.1), "friction"),
    (dict(slip_speed=0.0), "slip_speed"),
    (dict(smoothing_depth=0.0), "smoothing_depth"),
])
def test_bad_rod_contacts_are_refused_naming_the_parameter(bad, key):
    with pytest.raises(ParameterError, match=key):
        _crossing(**{k: v for k, v in bad.items() if k != "b"}) if "b" not in bad else rodmol.System(
            {"upper": _rod(SOFT)}, contacts=[rodmol.RodContact("upper", bad["b"])])


def test_a_pair_declared_twice_and_the_solvers_on_the_pattern_are_refused():
    twice = [rodmol.RodContact("upper", "lower"), rodmol.RodContact("lower", "upper")]
    with pytest.raises(ParameterError, match=r"contacts\[1\]"):
        _crossing().replace(contacts=twice)
    with pytest.raises(ParameterError, match="sparse.*RodContact"):
        rodmol.simulate(_crossing(), 0.01, linsolver="sparse")
    with pytest.raises(ParameterError, match="galpha.*RodContact"):  # its Newton matrix: a sparse LU on the pattern
        rodmol.simulate(_crossing(), 0.01, backend="galpha")


def test_the_penalty_is_the_obstacles_law():
    # The law shares the obstacles' smoothed penalty (C1 at first touch).
    h = 1e-4
    assert penalty(0.5 * h, h)[0] == pytest.approx(0.125 * h)
    assert penalty(2 * h, h)[0] == pytest.approx(1.5 * h)


def test_a_streamed_run_records_the_rod_contacts_and_reads_them_back(tmp_path):
    system = _crossing()
    run = rodmol.simulate(system, 0.2, output_dt=0.1, out=tmp_path / "run")
    back = rodmol.load_result(tmp_path / "run")
    for key in ("rod_contact_least_gap", "rod_contact_pairs"):
        assert back.stats[key] == run.stats[key]
    assert run.stats["rod_contact_pairs"] >= 1
    forces, _, _ = run.rod_contacts()
    recorded = np.einsum("tni,n->ti", back["upper"].external_force, back["upper"].node_length)
    np.testing.assert_allclose(recorded, forces["upper"][:, 1:].sum(axis=1), rtol=0, atol=1e-6)


def _drop(**law):
    """The crossing without material damping, the upper rod released 2 mm above the lower one."""
    elastic, stiff = (rodmol.Material(E=m.E, nu=0.5, mu=0.0, rho=m.rho) for m in (SOFT, STIFF))
    lower = _rod(stiff, position=(CROSS, 0.0, -L / 2 - OFFSET), rotation=ALONG_Z)
    upper = _rod(elastic, position=(0.0, 2 * R + 2e-3, 0.0))
    return rodmol.System({"lower": lower, "upper": upper}, joints=[rodmol.Joint(("lower", "tip"), "world")],
                         contacts=[rodmol.RodContact("upper", "lower", **law)], gravity=(0.0, -G, 0.0))


def _total_energy(run):
    """Kinetic, strain, gravity and holds' energy of both rods and the contact's elastic energy [J], per frame."""
    total = sum(rodmol.energy(run.assembly.rods[name].model, run[name])["total"] for name in ("upper", "lower"))
    pairs = run.assembly.rod_pairs
    return total + np.array([(pairs.evaluate(np.ascontiguousarray(y)), pairs.energy)[1] for y in run.states])


def test_a_frictionless_elastic_drop_creates_no_energy_and_the_contacts_damping_removes_some():
    """Dropped onto the lower rod, the upper one bounces: with no damping anywhere the total
    energy (the contact's penalty included) never exceeds the start's and loses only the
    integrator's share; the law's default damping removes over 100 times more."""
    losses = []
    for law in (dict(damping=0.0), dict()):
        run = rodmol.simulate(_drop(**law), 0.08, output_dt=0.002, rtol=1e-6)
        assert run.success and run.stats["rod_contact_least_gap"] < 0.0  # it hit
        energy = _total_energy(run)
        assert np.max(energy - energy[0]) <= 1e-9 * energy[0]
        losses.append(energy[0] - energy[-1])
    assert 0.0 <= losses[0] < 1e-2 * losses[1]  # measured 1.8e-6 J against 2.4e-4 J


def test_a_rod_rolled_up_by_a_tip_moment_past_a_full_turn_does_not_pass_through_itself():
    """The issue's case: a follower tip moment of 1.3 full turns' (2 pi EI / L) rolls a cantilever
    up; without self-contact its tip passes through its base's part by most of a diameter, with it
    the coil lies on itself (its samples within 5% of the radius, its nodes, between them, 10%)."""
    material = rodmol.Material(E=1e6, nu=0.5, mu=1e4, rho=1000.0)
    n = 30
    turns = 1.3 * 2 * np.pi * material.E * np.pi * R**4 / 4 / L
    rod = rodmol.Model(rodmol.Rod(L, radius=R, material=material), n,
                       loads=[rodmol.PointMoment(L, [(0.0, 0.0, 0.0, 0.0), (1.0, 0.0, 0.0, turns)], frame="local")])
    gaps = []
    for contacts in ([rodmol.RodContact("rod", "rod")], []):
        system = rodmol.System({"rod": rod}, contacts=contacts, gravity=(0.0, 0.0, 0.0))
        run = rodmol.simulate(system, 1.5, output_dt=0.05)
        assert run.success
        u = run.assembly.rods["rod"].layout.integrated_positions(run.states[-1])  # what the law sees
        apart = np.abs(np.subtract.outer(np.arange(n + 1), np.arange(n + 1))) * L / n > np.pi * R
        gaps.append(np.linalg.norm(u[:, None] - u[None], axis=-1)[apart].min() - 2 * R)  # between nodes
        if contacts:
            assert run.stats["rod_contact_least_gap"] > -0.05 * R  # between the samples (measured -0.035 R)
    assert gaps[0] > -0.1 * R and gaps[1] < -R  # measured -0.068 R and -1.96 R


def test_the_dense_solver_differences_the_contact_and_agrees_with_gmres():
    runs = [rodmol.simulate(_crossing(), 0.3, output_times=[0.0, 0.3], rtol=1e-7, linsolver=solver)
            for solver in ("gmres", "dense")]
    assert all(run.success for run in runs)
    carried = [run.rod_contacts()[0]["upper"][-1].sum(axis=0)[1] for run in runs]
    assert carried[1] == pytest.approx(carried[0], rel=1e-3)  # measured 4e-5
