"""Contact between rods of a system (:class:`rodmol.RodContact`), as the
assembly evaluates it (:mod:`rodmol.discretise.rod_contact_law` holds the
compiled law).

Every rod of a rod contact carries one load, a global force density at
each of its velocity nodes (``rodmol.rod_contacts.LOAD_NAME``, added by the
System): before each right-hand side :meth:`RodPairs.apply` gathers the
rods' centrelines and velocities, finds the candidate segment pairs of each
contact (sort and sweep of their boxes, at every call: the pairs come and
go without a step missing one) and writes each node's contact force over
its node length into that load's value. A share on a rod's base node goes
into the base's support, as a point load's does. The rod's Result then
records the contact forces as part of its external force.
"""

import numpy as np

from ..rod_contacts import LOAD_NAME
from .layout import QUAT, U, V
from .load_entries import count
from .physics import jit, rotation, to_global
from .rod_contact_law import ACTIVE, ENERGY, LEAST_GAP, boxes, pair_forces, sweep

#: Sample spacing along a segment, as a fraction of the two rods' summed radii: a
#: crossing between samples sinks at most spacing^2 / (8 (r_a + r_b)) deeper, 1/128 of r_a + r_b.
SAMPLE_SPACING = 0.25


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
def contact_pass(y, rods, reach, bases, pos, vel, radius, arc, rest, force, pairs, laws, box, candidates, margin,
                 stats, values, lengths, write):
    """One evaluation of every rod contact at the state ``y``, compiled in one call:
    gather the rods (table ``rods``, the base velocities ``bases``, each rod's), sweep each pair of
    ``pairs`` (rod a, rod b, samples of a, of b, self) for candidates within ``reach`` (rods,)
    plus half ``margin`` [m] of each rod, add their forces (law rows ``laws``: k, c, mu, v_s,
    h, cut-off) into ``force`` and ``stats``; if ``write``, each rod's nodes' forces over their
    ``lengths`` into its load values ``values`` (from its first contact entry). Returns 0, or
    minus the candidates a pair needs if ``candidates`` is too small (nothing written)."""
    for r in range(rods.shape[0]):
        gather(y, rods[r, START], rods[r, HEADER], rods[r, BLOCK], rods[r, SEGMENTS], bases[r], pos, vel,
               rods[r, FIRST])
    force[:] = 0.0
    stats[ENERGY], stats[LEAST_GAP], stats[ACTIVE] = 0.0, np.inf, 0.0
    for k in range(pairs.shape[0]):
        a, b, same = pairs[k, 0], pairs[k, 1], pairs[k, 4] == 1
        na, nb, ba, bb = rods[a, SEGMENTS], rods[b, SEGMENTS], rods[a, BOX], rods[b, BOX]
        boxes(pos, rods[a, FIRST], na, reach[a] + 0.5 * margin, box[ba:ba + na])
        if not same:
            boxes(pos, rods[b, FIRST], nb, reach[b] + 0.5 * margin, box[bb:bb + nb])
        found = sweep(box[ba:ba + na], box[bb:bb + nb], same, candidates)
        if found < 0:
            return found
        pair_forces(pos, vel, radius, arc, rest, force, candidates, found, rods[a, FIRST], na, rods[b, FIRST], nb,
                    pairs[k, 2], pairs[k, 3], same, laws[k], laws[k, 5], stats)
    if write:
        for r in range(rods.shape[0]):
            into, length, entry, first = values[r], lengths[r], rods[r, ENTRY], rods[r, FIRST]
            for i in range(rods[r, SEGMENTS]):
                for x in range(3):
                    into[entry + i, x] = force[first + 1 + i, x] / length[i]
    return 0


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
        self.pairs, pairs, laws = [], [], []
        index = {name: k for k, name in enumerate(self.rods)}
        for _, contact in system.rod_pairs:
            a, b = self.rods[contact.a], self.rods[contact.b]
            spacing = SAMPLE_SPACING * (a.rmax + b.rmax)
            samples = [max(1, int(np.ceil(float(np.max(r.sd.model.ds)) / spacing))) for r in (a, b)]
            law = (*contact.law(a.sd.model, b.sd.model), np.pi * max(a.rmax, b.rmax))
            pairs.append((index[contact.a], index[contact.b], *samples, int(a is b)))
            laws.append(law)
            self.pairs.append(dict(a=a, b=b, samples=samples, law=np.array(law[:5]), cutoff=law[5]))
        self._pairs, self._laws = np.array(pairs, dtype=np.int64), np.array(laws)
        rods = list(self.rods.values())
        boxes_first = np.cumsum([0] + [rod.n for rod in rods])
        self._table = np.array([(rod.start, rod.n, rod.first, rod.sd.layout.header, rod.sd.layout.block,
                                 rod.entries.start, boxes_first[k]) for k, rod in enumerate(rods)], dtype=np.int64)
        self._reach = np.array([rod.rmax for rod in rods])
        # Tuples of the rods' own arrays: the pass reads their base velocities as the last
        # call set them and writes their load values in place.
        self._bases = tuple(rod.sd.base_velocities for rod in rods)
        self._box = np.zeros((boxes_first[-1], 6))
        self._candidates = np.zeros((4 * int(boxes_first[-1]), 2), dtype=np.int64)
        self._values = tuple(rod.sd.entry_values for rod in rods)
        self._lengths = tuple(np.ascontiguousarray(rod.sd.node_lengths, dtype=float) for rod in rods)
        self.stats = np.array([0.0, np.inf, 0.0])

    def _pass(self, y, margin, write):
        while True:
            found = contact_pass(y, self._table, self._reach, self._bases, self.pos, self.vel, self.radius, self.arc,
                                 self.rest, self.force, self._pairs, self._laws, self._box, self._candidates,
                                 float(margin), self.stats, self._values, self._lengths, write)
            if found == 0:
                return
            self._candidates = np.zeros((2 * -found, 2), dtype=np.int64)  # grown, and the pass again

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
        forces = self.history(states)[0][name][:, 1:] / rod.sd.node_lengths[None, :, None]
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
