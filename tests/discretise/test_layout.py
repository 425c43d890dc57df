"""The Jacobian band of the right-hand side follows from the state layout.

CVODE's banded solver is given ``SemiDiscrete(model).bandwidths()``, derived
by the layout from the scheme's and the loads' declared dependencies; if they
under-estimated the coupling, the Newton matrix would silently miss entries.
Here the pattern is found numerically (``sksundae.jacband.j_pattern`` perturbs
one state variable at a time) at a random, generic state where no coupling
vanishes by accident, and compared with the layout's structural pattern.
"""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from sksundae.jacband import bandwidth, j_pattern

import rodmol


def generic_state(model, rng):
    """Random strains, velocities and orientations (no symmetry, nothing zero)."""
    n = model.n_elements
    lay = rodmol.StateLayout(n)
    quat = rng.normal(size=(n, 4))
    quat /= np.linalg.norm(quat, axis=1, keepdims=True)
    quat0 = rng.normal(size=4)
    quat0 /= np.linalg.norm(quat0)
    return lay.pack(
        u0=rng.normal(scale=0.01, size=3), quat0=quat0,
        u=rng.normal(scale=0.1, size=(n, 3)), quat=quat,
        q=np.array([1.0, 0.0, 0.0]) + rng.normal(scale=0.05, size=(n, 3)),
        k=rng.normal(scale=3.0, size=(n, 3)),
        v=rng.normal(scale=0.1, size=(n, 3)),
        w=rng.normal(scale=1.0, size=(n, 3)),
    )


def models(n):
    """Every load that couples state variables: water (drag, added mass,
    buoyancy), gravity, tensioned cables (anchors on and between nodes, one at
    the tip), a moving base, and the optional Munk moment."""
    rod = rodmol.arm.paper_rod()
    L = rod.length
    cables = [
        rodmol.Cable((0.003, 0.0), 0.37 * L, 1.5, name="between nodes"),
        rodmol.Cable((0.0, -0.002), 0.5 * L, 0.7, name="on a node"),
        rodmol.Cable((-0.001, 0.0015), L, 0.4, name="to the tip"),
    ]
    base = rodmol.BaseMotion(velocity=lambda t: np.array([0.01, 0.02, -0.01]),
                       angular_velocity=lambda t: np.array([0.1, -0.2, 0.3]))
    loads = [rodmol.PointForce(0.6 * L, (0.1, -0.2, 0.05)),
             rodmol.PointMoment(L, (0.0, 0.01, 0.02), frame="local"),
             rodmol.DistributedForce(lambda s, t: np.outer(s, [0.0, 1.0, 0.5]), frame="local"),
             rodmol.PlaneContact((0.0, 0.0, 0.0), (0.0, 1.0, 0.2), stiffness=1e3, damping=1.0,
                                 friction=0.4, smoothing_depth=1.0),
             rodmol.SphereContact((0.0, 0.0, 0.1), 0.2, stiffness=1e3, damping=1.0, friction=0.4,
                                  smoothing_depth=1.0)]
    return {
        "paper loads": rodmol.Model(rod, n, medium="water", cables=cables),
        "external loads, contact": rodmol.Model(rod, n, medium="water", cables=cables, loads=loads),
        "moving base, Munk": rodmol.Model(rod, n, medium="water", cables=cables, base=base,
                                          munk_moment=True),
    }


def numerical_pattern(n, case):
    """(numerical pattern, the system) of one case at a generic state (the
    contact smoothing depth of 1 m keeps every node in smooth contact)."""
    model = models(n)[case]
    rhs = rodmol.SemiDiscrete(model)
    y = generic_state(model, np.random.default_rng(1234 + n))
    return j_pattern(lambda t, y, yp: rhs(t, y, yp), 0.3, y).astype(bool), rhs


CASES = ["paper loads", "moving base, Munk", "external loads, contact"]


@pytest.mark.parametrize("n", [2, 3, 7])
@pytest.mark.parametrize("case", CASES)
def test_numerical_pattern_within_layout_pattern(n, case):
    """Every coupling the right-hand side really has is in the structural
    pattern, hence inside the band CVODE is told about."""
    numeric, system = numerical_pattern(n, case)
    structural = system.pattern()
    assert numeric.shape == structural.shape == (system.size, system.size)
    missing = np.argwhere(numeric & ~structural)
    assert missing.size == 0, f"couplings outside the declared pattern (row, col): {missing[:10]}"
    lo, up = bandwidth(numeric)
    assert lo <= system.bandwidths()[0] and up <= system.bandwidths()[1]
    # The sampling point is generic enough to show the neighbour couplings of
    # the upwind scheme: velocities see the next block's strains (stress
    # differences) and strains the previous block's velocities (velocity
    # differences), so both half-bandwidths reach at least one block.
    assert lo >= 19 and up >= 19


@pytest.mark.parametrize("n", [2, 7])
@pytest.mark.parametrize("case", CASES)
def test_numerical_band_equals_layout_band(n, case):
    """The layout's bandwidths are exactly those of the real Jacobian (neither
    too narrow, which would be wrong, nor wider than needed, which costs
    Jacobian evaluations and band-LU work)."""
    numeric, system = numerical_pattern(n, case)
    print(f"\nN={n} {case}: numerical bandwidths {bandwidth(numeric)}, declared {system.bandwidths()}")
    assert tuple(int(b) for b in bandwidth(numeric)) == system.bandwidths()


def test_bandwidths_do_not_grow_with_n():
    """The half-bandwidths are a property of the blocking, not of N: a banded
    solve stays O(N)."""
    depends = rodmol.SemiDiscrete(models(3)["paper loads"]).depends
    bands = {n: rodmol.StateLayout(n).bandwidths(depends) for n in (3, 10, 100)}
    assert len(set(bands.values())) == 1
    lo, up = bands[3]
    assert lo < 2 * 19 and up < 2 * 19  # couples only neighbouring element blocks
    # The structural pattern of a long rod is block-periodic: its bandwidths,
    # computed directly, agree with the three-block shortcut.
    rows, cols = np.nonzero(rodmol.StateLayout(10).pattern(depends))
    assert (int(np.max(rows - cols)), int(np.max(cols - rows))) == (lo, up)


@pytest.mark.parametrize("case", CASES)
def test_colouring_groups_touch_disjoint_rows(case):
    """Columns perturbed together by the compiled Jacobian never share a row
    of the pattern, and every column any row depends on is in one group."""
    n = 7
    system = rodmol.SemiDiscrete(models(n)[case])
    lay, pat = system.layout, system.pattern()
    groups = lay.colouring(system.depends)
    covered = set()
    for j, r, period, _ in groups:
        cols = [lay.header + lay.block * b + j for b in range(r, n, period)]
        covered.update(cols)
        hits = pat[:, cols].sum(axis=1)
        assert hits.max() <= 1, f"group (entry {j}, residue {r}) shares a row"
    needed = set(np.flatnonzero(pat[:, lay.header:].any(axis=0)) + lay.header)
    assert needed <= covered


def test_state_accessors_and_straight_state():
    """Offsets come from the layout: accessors read what pack wrote."""
    lay = rodmol.StateLayout(4)
    rng = np.random.default_rng(3)
    parts = dict(u0=rng.normal(size=3), quat0=rng.normal(size=4), u=rng.normal(size=(4, 3)),
                 quat=rng.normal(size=(4, 4)), q=rng.normal(size=(4, 3)), k=rng.normal(size=(4, 3)),
                 v=rng.normal(size=(4, 3)), w=rng.normal(size=(4, 3)))
    y = lay.pack(**parts)
    np.testing.assert_array_equal(lay.base_position(y), parts["u0"])
    np.testing.assert_array_equal(lay.quaternions(y)[0], parts["quat0"])
    np.testing.assert_array_equal(lay.quaternions(y)[1:], parts["quat"])
    np.testing.assert_array_equal(y[lay.tip_slice("v")], parts["v"][-1])
    np.testing.assert_array_equal(lay.integrated_positions(y)[-1], parts["u"][-1])
    assert lay.entry_name(lay.tip_slice("k").start + 2) == "k[2] of element 3"
    model = rodmol.Model(rodmol.Rod(2.0, 0.1, rodmol.Material(E=1e6, nu=0.3, rho=1e3)), 4)
    straight = rodmol.straight_state(model)
    np.testing.assert_allclose(lay.integrated_positions(straight)[:, 0], model.s_nodes)
    # Without gravity the straight rod is at rest: every rate vanishes.
    weightless = rodmol.Model(model.rod, 4, gravity=(0.0, 0.0, 0.0))
    assert np.all(rodmol.SemiDiscrete(weightless)(0.0, straight) == 0.0)


@settings(max_examples=15, deadline=None)
@given(scale=st.floats(0.5, 2.0), seed=st.integers(0, 2**16), case=st.sampled_from(CASES))
def test_rates_do_not_see_the_quaternion_norm(scale, seed, case):
    """What makes the projection of the stored states harmless: with every
    quaternion scaled by c, the rates of the positions, strains and velocities
    are unchanged (rotations divide by |Q|^2) and the quaternions' own rates
    are c times the kinematics Q (x) (0, w) / 2 plus the norm's restoring term."""
    model = models(4)[case]
    system = rodmol.SemiDiscrete(model)
    lay = system.layout
    y = generic_state(model, np.random.default_rng(seed))
    scaled = y.copy()
    lay.field(scaled, "Q")[:] *= scale
    scaled[3:lay.header] *= scale
    f, f_scaled = system(0.3, y), system(0.3, scaled)
    rate = rodmol.discretise.system.QUATERNION_RESTORING_RATE
    for name in ("u", "q", "k", "v", "w"):
        np.testing.assert_allclose(lay.field(f_scaled, name), lay.field(f, name), rtol=1e-9, atol=1e-9)
    np.testing.assert_allclose(lay.field(f_scaled, "Q"), scale * lay.field(f, "Q")
                               + rate * (1.0 - scale**2) * lay.field(scaled, "Q"), rtol=1e-9, atol=1e-9)
    # The projection puts the norm back and touches nothing else.
    lay.project_quaternions(scaled)
    np.testing.assert_allclose(scaled, y, rtol=1e-14, atol=1e-15)
    np.testing.assert_allclose(np.linalg.norm(lay.quaternions(scaled), axis=-1), 1.0, rtol=1e-15)
