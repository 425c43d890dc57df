"""The compiled law of contact between rods (rodmol.discretise.rod_contact_law):
its elastic forces are minus the gradient of its energy (no energy created
by the penalty), its damping and friction only remove energy, every force
is equal and opposite, and the broad phase finds every pair the brute force
finds."""

import numpy as np
import pytest

from rodmol.discretise.rod_contact_law import ACTIVE, ENERGY, boxes, candidate_forces, sweep

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


def _swept(pos, same):
    """(candidates, count, first, segments, contact_rods) of rods a (nodes 0..N) and b (N+1..2N+1)
    in contact, or of rod a with itself."""
    first, segments = np.array([0, N + 1]), np.array([N, N])
    box = np.zeros((2 * N, 6))
    boxes(pos, 0, N, R_A, box[:N])
    boxes(pos, N + 1, N, R_B, box[N:])
    owner, index = np.repeat([0, 1], N), np.tile(np.arange(N), 2)
    contact_of = np.full((2, 2), -1)
    contact_rods = np.array([[0, 0]]) if same else np.array([[0, 1]])
    contact_of[tuple(contact_rods[0])] = contact_of[tuple(contact_rods[0][::-1])] = 0
    candidates = np.zeros((4 * N * N, 3), dtype=np.int64)
    count = sweep(box, owner, index, contact_of, contact_rods, candidates)
    return candidates, count, first, segments, contact_rods


def _evaluate(pos, vel, radius, arc, rest, law, same=False):
    """(forces (nodes, 3), stats) of rods a (nodes 0..N) and b (N+1..2N+1), or of rod a with itself."""
    candidates, count, first, segments, contact_rods = _swept(pos, same)
    force, stats = np.zeros_like(pos), np.array([0.0, np.inf, 0.0])
    laws = np.array([[*law, np.pi * R_A]], dtype=float)
    candidate_forces(pos, vel, radius, arc, rest, force, candidates, count, first, segments, contact_rods,
                     np.array([[SAMPLES, SAMPLES]]), laws, stats)
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

    def overlap(p, q):
        return np.all(p[:3] <= q[3:]) and np.all(q[:3] <= p[3:])

    candidates, count, *_ = _swept(pos, False)
    brute = {(0, i, j) for i in range(N) for j in range(N) if overlap(box_a[i], box_b[j])}
    assert {tuple(c) for c in candidates[:count]} == brute and count == len(brute) > 0
    candidates, count, *_ = _swept(pos, True)
    assert {tuple(c) for c in candidates[:count]} == {(0, i, j) for i in range(N) for j in range(i + 2, N)
                                                      if overlap(box_a[i], box_a[j])}
    box = np.concatenate([box_a, box_b])
    short = np.zeros((1, 3), dtype=np.int64)  # too small a buffer: it says how many it needs
    contact_of = np.array([[-1, 0], [0, -1]])
    assert sweep(box, np.repeat([0, 1], N), np.tile(np.arange(N), 2), contact_of, np.array([[0, 1]]), short) \
        == -len(brute)
