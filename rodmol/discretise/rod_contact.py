"""Contact between rods of a system (:class:`rodmol.RodContact`), as the
assembly evaluates it (:mod:`rodmol.discretise.rod_contact_law` holds the
compiled law and broad phase).

Every rod of a rod contact carries one load, a force density at each of
its velocity nodes (``rodmol.rod_contacts.LOAD_NAME``, added by the System;
a follower load, written in each node's section frame: the kernel's
cheapest kind). Before each right-hand side :meth:`RodPairs.apply` gathers
the rods' centrelines and velocities and, in one compiled call
(:func:`contact_pass`), finds the candidate segment pairs of every contact
(a sort and sweep of the segments' boxes) when a node has moved half a
skin since they were last found (a Verlet list: the boxes grown by the
skin, so that no pair that touches now was out of reach then), adds the
candidates' forces and writes each node's force over its node length into
that load. A share on a rod's base node goes into the base's support, as a
point load's does. The rod's Result then records the contact forces as
part of its external force.
"""

import numpy as np

from ..rod_contacts import LOAD_NAME
from .layout import QUAT, U, V
from .load_entries import count
from .physics import jit, rotation, to_global, to_local
from .rod_contact_law import ACTIVE, ENERGY, LEAST_GAP, boxes, candidate_forces, sweep
from .rotations import matrices

#: Sample spacing along a segment, as a fraction of the two rods' summed radii: a
#: crossing between samples sinks at most spacing^2 / (8 (r_a + r_b)) deeper, 1/128 of r_a + r_b.
SAMPLE_SPACING = 0.25
#: The skin of the kept candidates, as a fraction of the smallest rod radius: the sweep runs again
#: when a node has moved half of it (38 times in the 405 calls of the octopus's 1 s, each arm touching its neighbours).
SKIN = 0.5


@jit
def gather(y, start, header, block, n_blocks, base_velocity, pos, vel, first):
    """Write the centreline nodes 0..n_blocks of the rod whose state starts at
    ``y[start]`` into ``pos``, their velocities (global) into ``vel``, from row
    ``first`` on; node 0 is the base, moving with ``base_velocity`` (its local frame)."""
    r = rotation((y[start + 3], y[start + 4], y[start + 5], y[start + 6]))
    v = to_global(r, (base_velocity[0], base_velocity[1], base_velocity[2]))
    for x in range(3):
        pos[first, x], vel[first, x] = y[start + x], v[x]
    for i in range(n_blocks):
        b = start + header + block * i
        r = rotation((y[b + QUAT], y[b + QUAT + 1], y[b + QUAT + 2], y[b + QUAT + 3]))
        v = to_global(r, (y[b + V], y[b + V + 1], y[b + V + 2]))
        for x in range(3):
            pos[first + 1 + i, x], vel[first + 1 + i, x] = y[b + U + x], v[x]


#: The columns of :func:`contact_pass`'s rod table: where its state starts, its segments,
#: its first node row, its state's header and block sizes, its first contact entry, its first box row.
START, SEGMENTS, FIRST, HEADER, BLOCK, ENTRY, BOX = range(7)


@jit
def moved(pos, ref, limit):
    """True if a node of ``pos`` is ``limit`` [m] or more from where ``ref`` has it."""
    limit2 = limit * limit
    for i in range(pos.shape[0]):
        dx, dy, dz = pos[i, 0] - ref[i, 0], pos[i, 1] - ref[i, 1], pos[i, 2] - ref[i, 2]
        if dx * dx + dy * dy + dz * dz >= limit2:
            return True
    return False


@jit
def contact_pass(y, rods, reach, bases, pos, vel, radius, arc, rest, force, box, owner, index, contact_of,
                 contact_rods, samples, laws, candidates, kept, ref, skin, margin, stats, values, lengths, write):
    """One evaluation of every rod contact at the state ``y``, compiled in one call:
    gather the rods (table ``rods``, the base velocities ``bases``, each rod's); if a
    node has moved half the ``skin`` [m] since the candidates were found (``ref``,
    their positions then), or none are kept (``kept[0]`` < 0), or ``margin`` > 0,
    box the segments (grown by ``reach`` (rods,) and half the skin and margin) and
    sweep them for every contact's candidates (:func:`sweep`): a pair in contact now
    was within reach then; add the candidates' forces into ``force`` and ``stats``
    (:func:`candidate_forces`); if ``write``, each rod's nodes' forces over their
    ``lengths`` into its load values ``values`` (from its first contact entry).
    Returns 1 if it swept, else 0; or minus the candidates needed if ``candidates`` is too small."""
    for r in range(rods.shape[0]):
        gather(y, rods[r, START], rods[r, HEADER], rods[r, BLOCK], rods[r, SEGMENTS], bases[r], pos, vel,
               rods[r, FIRST])
    if margin > 0.0 or kept[0] < 0 or moved(pos, ref, 0.5 * skin):
        for r in range(rods.shape[0]):
            row = rods[r, BOX]
            boxes(pos, rods[r, FIRST], rods[r, SEGMENTS], reach[r] + 0.5 * (skin + margin),
                  box[row:row + rods[r, SEGMENTS]])
        found = sweep(box, owner, index, contact_of, contact_rods, candidates)
        if found < 0:
            kept[0] = -1
            return found
        ref[:] = pos
        kept[0] = found if margin == 0.0 else -1  # a margin's candidates serve that call only
        count, swept = found, 1
    else:
        count, swept = kept[0], 0
    force[:] = 0.0
    stats[ENERGY], stats[LEAST_GAP], stats[ACTIVE] = 0.0, np.inf, 0.0
    candidate_forces(pos, vel, radius, arc, rest, force, candidates, count, rods[:, FIRST], rods[:, SEGMENTS],
                     contact_rods, samples, laws, stats)
    if write:  # as follower densities: the kernel's cheapest kind (no turning of its own)
        for r in range(rods.shape[0]):
            into, length, entry, first = values[r], lengths[r], rods[r, ENTRY], rods[r, FIRST]
            for i in range(rods[r, SEGMENTS]):
                f = (force[first + 1 + i, 0], force[first + 1 + i, 1], force[first + 1 + i, 2])
                if f[0] == 0.0 and f[1] == 0.0 and f[2] == 0.0:
                    into[entry + i, 0] = into[entry + i, 1] = into[entry + i, 2] = 0.0
                    continue
                b = rods[r, START] + rods[r, HEADER] + rods[r, BLOCK] * i + QUAT
                local = to_local(rotation((y[b], y[b + 1], y[b + 2], y[b + 3])), f)
                for x in range(3):
                    into[entry + i, x] = local[x] / length[i]
    return swept


class _Rod:
    """A rod of the rod contacts: its system ``sd``, where its state starts,
    its first row in the node arrays and the entries of its contact load."""

    def __init__(self, name, sd, start, first):
        model = sd.model
        load = next(k for k, item in enumerate(model.loads) if getattr(item, "name", None) == LOAD_NAME)
        entry = sum(count(item, model.s_nodes) for item in model.loads[:load])
        self.name, self.sd, self.start, self.first = name, sd, start, first
        self.n = sd.layout.n_blocks
        self.entries = slice(entry, entry + self.n)
        self.rmax = float(np.max(model.rod.radius_at(model.s_nodes)))


class RodPairs:
    """The rod contacts of ``assembly``'s system (``System.rod_pairs``).

    Attributes
    ----------
    force : (nodes, 3)
        The last call's contact force [N] on each node, global (the rods' nodes 0..N in turn).
    stats : (3,)
        The last call's elastic energy [J], least surface gap [m] (inf if no
        pair was within reach) and number of touching segment pairs.
    """

    def __init__(self, assembly):
        system = assembly.system
        names = list(dict.fromkeys(name for _, c in system.rod_pairs for name in c.rods))
        self.rods, first = {}, 0
        for name in names:
            self.rods[name] = _Rod(name, assembly.rods[name], assembly.parts[name].start, first)
            first += self.rods[name].n + 1
        self.pos, self.vel, self.force = np.zeros((first, 3)), np.zeros((first, 3)), np.zeros((first, 3))
        self.radius, self.arc, self.rest = np.zeros(first), np.zeros(first), np.zeros(first)
        for rod in self.rods.values():
            model, nodes = rod.sd.model, slice(rod.first, rod.first + rod.n + 1)
            self.radius[nodes] = model.rod.radius_at(model.s_nodes)
            self.arc[nodes] = model.s_nodes
            self.rest[rod.first:rod.first + rod.n] = np.diff(model.s_nodes)
        self.pairs, contact_rods, samples, laws = [], [], [], []
        index = {name: k for k, name in enumerate(self.rods)}
        self._contact_of = np.full((len(index), len(index)), -1, dtype=np.int64)
        for c, (_, contact) in enumerate(system.rod_pairs):
            a, b = self.rods[contact.a], self.rods[contact.b]
            spacing = SAMPLE_SPACING * (a.rmax + b.rmax)
            counts = [max(1, int(np.ceil(float(np.max(r.sd.model.ds)) / spacing))) for r in (a, b)]
            law = (*contact.law(a.sd.model, b.sd.model), np.pi * max(a.rmax, b.rmax))
            contact_rods.append((index[contact.a], index[contact.b]))
            self._contact_of[index[contact.a], index[contact.b]] = self._contact_of[index[contact.b],
                                                                                    index[contact.a]] = c
            samples.append(counts)
            laws.append(law)
            self.pairs.append(dict(a=a, b=b, samples=counts, law=np.array(law[:5]), cutoff=law[5]))
        self._contact_rods, self._samples = np.array(contact_rods, dtype=np.int64), np.array(samples, dtype=np.int64)
        self._laws = np.array(laws)
        rods = list(self.rods.values())
        boxes_first = np.cumsum([0] + [rod.n for rod in rods])
        self._table = np.array([(rod.start, rod.n, rod.first, rod.sd.layout.header, rod.sd.layout.block,
                                 rod.entries.start, boxes_first[k]) for k, rod in enumerate(rods)], dtype=np.int64)
        self._reach = np.array([rod.rmax for rod in rods])
        self._box = np.zeros((boxes_first[-1], 6))
        self._owner = np.repeat(np.arange(len(rods)), [rod.n for rod in rods]).astype(np.int64)
        self._index = np.concatenate([np.arange(rod.n) for rod in rods]).astype(np.int64)
        self._candidates = np.zeros((4 * int(boxes_first[-1]), 3), dtype=np.int64)
        # The candidates are kept until a node moves half the skin (a Verlet list): half the smallest radius.
        self._kept, self._ref = np.array([-1], dtype=np.int64), np.zeros_like(self.pos)
        self.skin = SKIN * float(np.min(self._reach))
        self.calls = self.sweeps = 0  # evaluations, and those that swept
        # Tuples of the rods' own arrays: the pass reads their base velocities as the last
        # call set them and writes their load values in place.
        self._bases = tuple(rod.sd.base_velocities for rod in rods)
        self._values = tuple(rod.sd.entry_values for rod in rods)
        self._lengths = tuple(np.ascontiguousarray(rod.sd.node_lengths, dtype=float) for rod in rods)
        self.stats = np.array([0.0, np.inf, 0.0])

    def _pass(self, y, margin, write):
        while True:
            found = contact_pass(y, self._table, self._reach, self._bases, self.pos, self.vel, self.radius, self.arc,
                                 self.rest, self.force, self._box, self._owner, self._index, self._contact_of,
                                 self._contact_rods, self._samples, self._laws, self._candidates, self._kept,
                                 self._ref, self.skin, float(margin), self.stats, self._values, self._lengths, write)
            if found >= 0:
                self.calls, self.sweeps = self.calls + 1, self.sweeps + found
                return
            self._candidates = np.zeros((2 * -found, 3), dtype=np.int64)  # grown, and the pass again

    def evaluate(self, y, margin=0.0):
        """The contact forces (:attr:`force`) and :attr:`stats` at the state ``y``;
        pairs within ``margin`` [m] of touching count toward the least gap."""
        self._pass(y, margin, False)
        return self.force

    def apply(self, y):
        """Write every rod's contact force densities at the state ``y`` into its contact load's values."""
        self._pass(y, 0.0, True)

    def node_forces(self, name):
        """Rod ``name``'s nodes' contact forces [N], global, (N + 1, 3), of the last evaluation (zeros if
        the rod is in no rod contact)."""
        rod = self.rods.get(name)
        if rod is None:
            return None
        return self.force[rod.first:rod.first + rod.n + 1].copy()

    def history(self, states):
        """At the frames ``states`` (n_t, size): each rod's nodes' contact forces
        {name: (n_t, N + 1, 3)} [N], global, the least surface gap (n_t,) [m]
        (inf with no pair within the two rods' radii) and the touching segment pairs (n_t,)."""
        forces = {name: np.zeros((len(states), rod.n + 1, 3)) for name, rod in self.rods.items()}
        gaps, active = np.full(len(states), np.inf), np.zeros(len(states), dtype=int)
        reach = max(rod.rmax for rod in self.rods.values())
        for k, y in enumerate(states):
            self.evaluate(np.ascontiguousarray(y), margin=2.0 * reach)
            for name, rod in self.rods.items():
                forces[name][k] = self.force[rod.first:rod.first + rod.n + 1]
            gaps[k], active[k] = self.least_gap, self.active
        return forces, gaps, active

    def replay(self, name, t, states):
        """Rod ``name``'s contact load entries at the frames ``states`` (n_t, size) at ``t``:
        (entry, rows (n_t, N_PARAMS), values (n_t, 3)) each, as :class:`RecordedJoints` takes them."""
        rod = self.rods[name]
        global_forces = self.history(states)[0][name][:, 1:] / rod.sd.node_lengths[None, :, None]
        turns = matrices(rod.sd.layout.field(np.asarray(states)[:, rod.start:rod.start + rod.sd.size], "Q"))
        forces = np.einsum("tnji,tnj->tni", turns, global_forces)  # local: the load is a follower
        rows = rod.sd.entry_params[rod.entries]
        return [(rod.entries.start + i, np.tile(rows[i], (len(t), 1)), forces[:, i]) for i in range(rod.n)]

    @property
    def energy(self):
        return float(self.stats[ENERGY])

    @property
    def least_gap(self):
        return float(self.stats[LEAST_GAP])

    @property
    def active(self):
        return int(self.stats[ACTIVE])
