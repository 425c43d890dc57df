"""External loads on the grid: each load of a model (:mod:`rodmol.loads`)
becomes *entries* at the velocity nodes 1..N, the rows the compiled kernel
(:func:`rodmol.discretise.external.load`) reads.

A point load at arc length s is shared between the two nodes around s,
linearly (a share that falls on the clamped base goes into the clamp);
distributed and contact loads act at every node but the base.
"""

from dataclasses import dataclass

import numpy as np

from ..holds import default_stiffness
from ..loads import (
    KERNELS,
    N_PARAMS,
    P_DAMPING,
    P_STIFFNESS,
    P_TURN_DAMPING,
    P_TURN_STIFFNESS,
)
from ..rod_contacts import LOAD_NAME as REACTION_LOAD
from . import external
from .layout import StateLayout
from .rotations import from_matrix
from .undeformed import undeformed_state


@dataclass(frozen=True)
class GridLoad:
    """Loads mapped onto the velocity nodes 1..N of a grid.

    ``weight`` is the entry's share of the node's load density [1/m for a
    point load, 1 for densities], taking every node as standing for a length
    ds; ``concentrated`` marks point loads, whose density a scheme scales to
    its own node lengths. ``initial`` (n_entries, 3) are the values at t = 0;
    ``values`` lists (entry slice, values(t)) for the time-dependent loads.
    """

    kind: np.ndarray
    node: np.ndarray
    weight: np.ndarray
    params: np.ndarray
    initial: np.ndarray
    concentrated: np.ndarray
    values: list

    def fill(self, t, out):
        """Write the entries' values at time t into ``out`` (n_entries, 3)."""
        for rows, at in self.values:
            out[rows] = at(t)
        return out


def node_shares(s, s_nodes):
    """Velocity nodes (1..N) and weights [1/m] sharing a point load at s [m]."""
    n = len(s_nodes) - 1
    ds = s_nodes[1] - s_nodes[0]
    x = min(s / ds, float(n))
    j = min(int(np.floor(x)), n - 1)
    f = x - j
    nodes, weights = [], []
    for node, share in ((j, 1.0 - f), (j + 1, f)):
        if node >= 1 and share > 0.0:  # node 0 is the clamped base
            nodes.append(node)
            weights.append(share / ds)
    return np.array(nodes, dtype=int), np.array(weights)


def hold_law(hold, axial_stiffness, mass, radius, ds, length):
    """(stiffness [N/m], damping [N s/m], turning stiffness [N m], turning
    damping [N m s]) of ``hold`` (a :class:`rodmol.Hold`) at a node whose
    element has the axial stiffness E A / ds ``axial_stiffness`` [N/m], of
    ``mass`` [kg] and section ``radius`` [m], on a rod of ``length`` [m]
    and elements ``ds`` [m]: the defaults where the hold gives none
    (:func:`rodmol.holds.default_stiffness`, critical damping), and the
    turning law the section's I / A = r^2 / 4 times it."""
    k = default_stiffness(axial_stiffness, ds, length) if hold.stiffness is None else hold.stiffness
    c = 2.0 * np.sqrt(k * mass) if hold.damping is None else hold.damping
    arm2 = 0.25 * radius * radius
    return k, c, k * arm2, c * arm2


def _held_entries(load, s_nodes, rest):
    """The one entry of a hold (a :class:`rodmol.Hold`): its node, weight
    (the whole force at the node), parameter row and values (the held
    displacement from the rest position, global: the equilibrium's
    continuation ramps it as a load of its own); ``rest`` as from :func:`rest_nodes`."""
    ds = s_nodes[1] - s_nodes[0]
    node = int(round(load.s / ds))
    row = np.zeros((1, N_PARAMS))
    position, quat = rest["u"][node], rest["Q"][node]
    if load.rotation is not None:
        quat = from_matrix(load.rotation)
    row[0, :3], row[0, 3:7] = position, quat
    law = hold_law(load, rest["axial_stiffness"][node], rest["mass"][node], rest["radius"][node], ds,
                   s_nodes[-1] - s_nodes[0])
    row[0, [P_STIFFNESS, P_DAMPING, P_TURN_STIFFNESS, P_TURN_DAMPING]] = law
    shift = np.zeros((1, 3)) if load.position is None else (load.position - position)[None, :]
    return np.array([node]), np.array([1.0 / ds]), row, lambda t: shift


def rest_nodes(model, undeformed=None):
    """What holds read at the nodes 0..N of ``model`` at rest in its rest shape
    (``undeformed``, its undeformed state; by default on the centred scheme's
    cells): the pose (``u`` [m], ``Q``, global), E A / ds [N/m]
    (``axial_stiffness``), the node's mass rho A ds [kg] and the section
    ``radius`` [m]."""
    s, layout = model.s_nodes, StateLayout(model.n_elements)
    y = undeformed_state(model) if undeformed is None else undeformed
    u = layout.integrated_positions(y)
    quat = layout.quaternions(y)
    area = model.rod.area(s)
    return {"u": u, "Q": quat, "axial_stiffness": model.rod.stiffness(s)[0][:, 0] / model.ds,
            "mass": model.rod.material.rho * area * model.ds, "radius": model.rod.radius_at(s)}


def _entries(load, s_nodes, radius, rest):
    """(nodes, weights, params, values(t) at those nodes, time-dependent) of one load."""
    if load.spread == "node":
        return _held_entries(load, s_nodes, rest)
    if load.spread == "point":
        nodes, weights = node_shares(load.s, s_nodes)
    else:
        nodes = np.arange(1, len(s_nodes))
        weights = np.ones(len(nodes))
    s = s_nodes[nodes]
    params = np.zeros((len(nodes), N_PARAMS))
    row = load.params(radius[nodes])
    params[:, :row.shape[1]] = row

    def at(t):
        return load.values(s, t)

    return nodes, weights, params, at


def count(load, s_nodes):
    """How many entries ``load`` has on the grid of nodes ``s_nodes`` [m]."""
    if load.spread == "node":
        return 1
    return len(node_shares(load.s, s_nodes)[0]) if load.spread == "point" else len(s_nodes) - 1


def on_grid(loads, s_nodes, radius, rest=None):
    """All ``loads`` as one :class:`GridLoad`; ``radius`` [m] at ``s_nodes``;
    ``rest`` (:func:`rest_nodes`) is needed by holds only."""
    kind, node, weight, params, initial, concentrated, timed = [], [], [], [], [], [], []
    start = 0
    for load in loads:
        nodes, weights, rows, at = _entries(load, s_nodes, radius, rest)
        n = len(nodes)
        kind.append(np.full(n, KERNELS[load.kernel].code))
        node.append(nodes)
        weight.append(weights)
        params.append(rows)
        initial.append(np.asarray(at(0.0), dtype=float).reshape(n, 3))
        concentrated.append(np.full(n, load.spread != "nodes"))
        if not load.constant:
            timed.append((slice(start, start + n), at))
        start += n

    def cat(arrays, shape):
        return np.concatenate(arrays) if arrays else np.zeros(shape)

    return GridLoad(cat(kind, 0).astype(np.int64), cat(node, 0).astype(np.int64), cat(weight, 0),
                    cat(params, (0, N_PARAMS)), cat(initial, (0, 3)), cat(concentrated, 0).astype(bool),
                    timed)


def of_model(model, undeformed=None):
    """The model's loads on its grid (holds read its rest shape from ``undeformed``,
    the model's undeformed state; by default on the centred scheme's cells)."""
    held = any(load.spread == "node" for load in model.loads)
    rest = rest_nodes(model, undeformed) if held else None
    return on_grid(model.loads, model.s_nodes, model.rod.radius_at(model.s_nodes), rest)


def load_scale(model, t=0.0, tensions=None, grid=None):
    """A force scale [N] of the applied loads at time t: net weight, cable
    tensions (``tensions`` [N] if given, else the inputs at t), external
    forces and external moments divided by L, as the grid sees them
    (``grid``: the model's :class:`GridLoad`, built here if None)."""
    net_density = abs(model.rod.material.rho - model.medium.rho)
    scale = net_density * np.linalg.norm(model.gravity) * model.rod.volume()
    if model.cables:
        scale += float(np.sum(model.tensions(t) if tensions is None else tensions))
    g = of_model(model) if grid is None else grid
    size = np.linalg.norm(g.fill(t, g.initial.copy()), axis=1) * g.weight * model.ds
    by_code = {k.code: k.quantity for k in KERNELS.values()}
    quantity = np.array([by_code[int(k)] for k in g.kind], dtype=object)
    return scale + float(np.sum(size[quantity == "force"]) + np.sum(size[quantity == "moment"])
                         / model.rod.length)


def kernel_rows(entries, model, node_lengths):
    """The compiled right-hand side's arrays of the load ``entries`` of ``model``
    (:func:`of_model`) on velocity nodes standing for ``node_lengths`` [m]: kinds, element
    blocks, weights (a point load's share spread over its node's own length), parameter
    rows (E, ``external.N_PARAMS``), values (E, 3), which are holds (rodmol.Hold), and
    which are the reactions a system's rod contacts write (rodmol.RodContact: not a load
    the continuation ramps)."""
    kinds = np.ascontiguousarray(entries.kind, dtype=np.int64)
    nodes = np.ascontiguousarray(entries.node - 1, dtype=np.int64)
    stretch = np.where(entries.concentrated, model.ds / node_lengths[nodes], 1.0)
    weights = np.ascontiguousarray(entries.weight * stretch, dtype=float)
    params = np.ascontiguousarray(entries.params, dtype=float).reshape(-1, external.N_PARAMS)
    values = np.ascontiguousarray(entries.initial, dtype=float).reshape(-1, 3)
    reactions = np.zeros(len(kinds), dtype=bool)
    ends = np.cumsum([count(item, model.s_nodes) for item in model.loads])[:-1]
    for load, rows in zip(model.loads, np.split(np.arange(len(kinds)), ends)):
        reactions[rows] = getattr(load, "name", None) == REACTION_LOAD
    return kinds, nodes, weights, params, values, np.isin(kinds, external.HOLDS), reactions
