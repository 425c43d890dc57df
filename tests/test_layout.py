"""The Jacobian band of the right-hand side follows from the state layout.

CVODE's banded solver is given ``StateLayout(N).bandwidths()``; if the layout
under-estimated the coupling, the Newton matrix would silently miss entries.
Here the pattern is found numerically (``sksundae.jacband.j_pattern`` perturbs
one state variable at a time) at a random, generic state where no coupling
vanishes by accident, and compared with the layout's structural pattern.
"""

import numpy as np
import pytest
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
    return {
        "paper loads": rodmol.Model(rod, n, medium="water", cables=cables),
        "moving base, Munk": rodmol.Model(rod, n, medium="water", cables=cables, base=base,
                                          munk_moment=True),
    }


def numerical_pattern(n, case):
    model = models(n)[case]
    rhs = rodmol.SemiDiscrete(model)
    y = generic_state(model, np.random.default_rng(1234 + n))
    return j_pattern(lambda t, y, yp: rhs(t, y, yp), 0.3, y).astype(bool)


CASES = ["paper loads", "moving base, Munk"]


@pytest.mark.parametrize("n", [2, 3, 7])
@pytest.mark.parametrize("case", CASES)
def test_numerical_pattern_within_layout_pattern(n, case):
    """Every coupling the right-hand side really has is in the structural
    pattern, hence inside the band CVODE is told about."""
    lay = rodmol.StateLayout(n)
    numeric = numerical_pattern(n, case)
    structural = lay.pattern()
    assert numeric.shape == structural.shape == (lay.size, lay.size)
    missing = np.argwhere(numeric & ~structural)
    assert missing.size == 0, f"couplings outside the layout's pattern (row, col): {missing[:10]}"
    lo, up = bandwidth(numeric)
    assert lo <= lay.bandwidths()[0] and up <= lay.bandwidths()[1]
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
    lay = rodmol.StateLayout(n)
    numeric = numerical_pattern(n, case)
    print(f"\nN={n} {case}: numerical bandwidths {bandwidth(numeric)}, layout {lay.bandwidths()}")
    assert tuple(int(b) for b in bandwidth(numeric)) == lay.bandwidths()


def test_bandwidths_do_not_grow_with_n():
    """The half-bandwidths are a property of the blocking, not of N: a banded
    solve stays O(N)."""
    bands = {n: rodmol.StateLayout(n).bandwidths() for n in (3, 10, 100)}
    assert len(set(bands.values())) == 1
    lo, up = bands[3]
    assert lo < 2 * 19 and up < 2 * 19  # couples only neighbouring element blocks
    # The structural pattern of a long rod is block-periodic: its bandwidths,
    # computed directly, agree with the three-block shortcut.
    rows, cols = np.nonzero(rodmol.StateLayout(10).pattern())
    assert (int(np.max(rows - cols)), int(np.max(cols - rows))) == (lo, up)
