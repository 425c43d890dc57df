"""The compiled law of contact between rods (rodmol.discretise.rod_contact_law):
its elastic forces are minus the gradient of its energy (no energy created
by the penalty), its damping and friction only remove energy, every force
is equal and opposite, and the broad phase finds every pair the brute force
finds."""

import numpy as np
import pytest

from rodmol.discretise.rod_contact_law import ACTIVE, ENERGY, boxes, pair_forces, sweep

R_A, R_B, N = 0.01, 0.012, 10
SAMPLES = 4


def _rods(seed):
    """Two wavy rods of N segments crossing each other, overlapping by a few mm (nodes
    (2 (N + 1), 3) [m]: rod a's then rod b's), their radii, arc lengths and rest lengths."""
    rng = np.random.default_rng(seed)
    s = np.linspace(0.0, 0.2, N + 1)
    a = np.stack([s - 0.1, 0.003 * np.sin(20 * s + rng.uniform(0, 6)), 0.002 * np.cos(15 * s)], axis=1)
    b = np.stack([0.004 * np.sin(25 * s), 0.2 * rng.uniform(0.05, 0.1) + 0.003 * np.cos(18 * s), s - 0.1], axis=1)
    b[:, 1] = R_A + R_B - 0.004 + 0.002 * np.sin(30 * s)  # through rod a: several samples inside
    turn = rng.normal(size=(3, 3))
    q, _ = np.linalg.qr(turn)
    pos = np.concatenate([a, b]) @ q.T
    radius = np.concatenate([np.full(N + 1, R_A), np.full(N + 1, R_B)])
    arc = np.concatenate([s, s])
    rest = np.concatenate([np.diff(s), [0.0], np.diff(s), [0.0]])
    return pos, radius, arc, rest


def _evaluate(pos, vel, radius, arc, rest, law, same=False):
    """(forces (nodes, 3), stats) of rods a (nodes 0..N) and b (N+1..2N+1), or of rod a with itself."""
    nb = N if not same else N
    box_a, box_b = np.zeros((N, 6)), np.zeros((nb, 6))
    boxes(pos, 0, N, R_A, box_a)
    boxes(pos, 0 if same else N + 1, nb, R_B if not same else R_A, box_b)
    pairs = np.zeros((4 * N * N, 2), dtype=np.int64)
    found = sweep(box_a, box_b, same, pairs)
    force, stats = np.zeros_like(pos), np.array([0.0, np.inf, 0.0])
    pair_forces(pos, vel, radius, arc, rest, force, pairs, found, 0, N, 0 if same else N + 1, nb, SAMPLES, SAMPLES,
                same, np.asarray(law, dtype=float), np.pi * R_A, stats)
    return force, stats


@pytest.mark.parametrize("seed", range(4))
def test_the_elastic_forces_are_minus_the_gradient_of_the_energy(seed):
    pos, radius, arc, rest = _rods(seed)
    law = (1e6, 0.0, 0.0, 1e-4, 1e-4)
    still = np.zeros_like(pos)
    force, stats = _evaluate(pos, still, radius, arc, rest, law)
    assert stats[ACTIVE] > 0 and stats[ENERGY] > 0.0
    gradient = np.zeros_like(pos)
    step = 1e-8
    for i in range(len(pos)):
        for x in range(3):
            up, down = pos.copy(), pos.copy()
            up[i, x] += step
            down[i, x] -= step
            gradient[i, x] = (_evaluate(up, still, radius, arc, rest, law)[1][ENERGY]
                              - _evaluate(down, still, radius, arc, rest, law)[1][ENERGY]) / (2 * step)
    np.testing.assert_allclose(force, -gradient, rtol=0, atol=1e-5 * np.abs(force).max())


@pytest.mark.parametrize("seed", range(4))
def test_damping_and_friction_only_remove_energy_and_every_force_is_equal_and_opposite(seed):
    pos, radius, arc, rest = _rods(seed)
    vel = np.random.default_rng(seed + 10).normal(scale=0.05, size=pos.shape)
    elastic, _ = _evaluate(pos, np.zeros_like(pos), radius, arc, rest, (1e6, 0.0, 0.0, 1e-4, 1e-4))
    for law in ((1e6, 300.0, 0.0, 1e-4, 1e-4), (1e6, 0.0, 0.6, 1e-4, 1e-4), (1e6, 300.0, 0.6, 1e-3, 1e-4)):
        force, _ = _evaluate(pos, vel, radius, arc, rest, law)
        power = float(np.sum((force - elastic) * vel))
        assert power < 0.0
        np.testing.assert_allclose(force.sum(axis=0), 0.0, atol=1e-12 * np.abs(force).max())


def test_the_broad_phase_finds_every_pair_within_reach():
    rng = np.random.default_rng(3)
    pos = np.cumsum(rng.normal(scale=0.01, size=(2 * (N + 1), 3)), axis=0)
    box_a, box_b = np.zeros((N, 6)), np.zeros((N, 6))
    boxes(pos, 0, N, R_A, box_a)
    boxes(pos, N + 1, N, R_B, box_b)
    pairs = np.zeros((2, 2), dtype=np.int64)
    found = sweep(box_a, box_b, False, pairs)
    if found < 0:  # too small a buffer: it says how many it needs
        pairs = np.zeros((-found, 2), dtype=np.int64)
        found = sweep(box_a, box_b, False, pairs)
    brute = {(i, j) for i in range(N) for j in range(N)
             if np.all(box_a[i, :3] <= box_b[j, 3:]) and np.all(box_b[j, :3] <= box_a[i, 3:])}
    assert {tuple(p) for p in pairs[:found]} == brute and found == len(brute) > 0
    same = np.zeros((N * N, 2), dtype=np.int64)
    found = sweep(box_a, box_a, True, same)
    mine = {tuple(p) for p in same[:found]}
    assert mine == {(i, j) for i in range(N) for j in range(i + 2, N)
                    if np.all(box_a[i, :3] <= box_a[j, 3:]) and np.all(box_a[j, :3] <= box_a[i, 3:])}
