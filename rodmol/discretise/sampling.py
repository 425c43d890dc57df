"""The model's sectional quantities sampled on its grid (done once, by the
system: :attr:`rodmol.discretise.system.SemiDiscrete.sampled`).

Grid (section IV-C of the paper): N elements, ds = L/N, nodes s_i = i ds.
Strains q, k and the stresses live on the *strain nodes* i = 0..N-1; pose u, R
and velocities v, w on the *velocity nodes* i = 1..N. The base (node 0) has
prescribed velocities, the tip (node N) a vanishing total stress.
"""

import numpy as np

#: The sampled arrays (read-only once built).
SAMPLED = ("kl", "kth", "vl", "vth", "added", "mass", "inertia", "net_mass", "drag_coefficient",
           "cable_weights")


def cell_properties(model, s):
    """Sectional stiffness and viscosity diagonals at arc lengths ``s`` [m]:
    (Kl, Kth, Vl, Vth), each (len(s), 3) [N, N m^2, N s, N m^2 s], with the
    model's ``viscosity=False`` honoured. A scheme samples them at its cells."""
    s = np.asarray(s, dtype=float)
    kl, kth = model.rod.stiffness(s)
    vl, vth = model.rod.viscosity(s)
    if not model.viscosity:
        vl, vth = np.zeros_like(vl), np.zeros_like(vth)
    return kl, kth, vl, vth


def rest_strains(model, s):
    """The rod's rest strains (q*, k*) at arc lengths ``s`` [m], each (len(s), 3),
    local frame [-, 1/m]: a scheme samples them at its cells, with the stiffness."""
    return model.rod.rest_strains_at(np.asarray(s, dtype=float))


def section_masses(model, s):
    """The sections' masses at arc lengths ``s`` [m], local frame: ``mass``
    (len(s), 3) [kg/m] (with the added mass), ``added`` (len(s), 3) [kg/m],
    rotational ``inertia`` (len(s), 3) [kg m] and ``net_mass`` (len(s),)
    [kg/m] (minus the displaced fluid). The velocity nodes sample them
    (:class:`Sampled`), and so does a body carrying a rod's base
    (:mod:`rodmol.discretise.assembly`)."""
    s = np.asarray(s, dtype=float)
    rod, med = model.rod, model.medium
    rho, a = rod.material.rho, rod.area(s)
    coeff = np.array([0.0, med.By, med.Bz]) if model.added_mass else np.zeros(3)
    added = med.rho * a[:, None] * coeff
    return rho * a[:, None] + added, added, rho * rod.second_moments(s), (rho - med.rho) * a


def cable_weights(model):
    """(n_cables, N) fraction of each strain node's cell on the cable's path:
    moving the anchor inside a cell shifts its concentrated load smoothly
    between the neighbouring nodes."""
    anchors = np.array([c.anchor for c in model.cables]).reshape(-1, 1)
    return np.clip((anchors - model.s_nodes[None, :-1]) / model.ds, 0.0, 1.0)


class Sampled:
    """The model's sectional quantities on its grid, local frame.

    ``kl``, ``kth``, ``vl``, ``vth`` (N, 3) at the strain nodes s_0..s_N-1
    (the paper's upwind reading; a scheme samples its cells with
    :func:`cell_properties`); at the velocity nodes s_1..s_N: ``mass`` (N, 3)
    [kg/m] (with the added mass ``added``), ``inertia`` (N, 3) [kg m],
    ``net_mass`` (N,) [kg/m] (minus the displaced fluid) and
    ``drag_coefficient`` (N, 3) [kg/m^2]; ``cable_weights`` (n_cables, N).
    """

    def __init__(self, model):
        n, rod, med = model.n_elements, model.rod, model.medium
        s_vel = model.s_nodes[1:]
        self.kl, self.kth, self.vl, self.vth = cell_properties(model, model.s_nodes[:-1])
        r = rod.radius_at(s_vel)
        self.mass, self.added, self.inertia, self.net_mass = section_masses(model, s_vel)
        if not model.drag:
            self.drag_coefficient = np.zeros((n, 3))
        elif model.drag_law == "componentwise":
            self.drag_coefficient = np.tile(model.drag_coefficients, (n, 1))
        else:
            self.drag_coefficient = med.rho * r[:, None] * np.array([0.5 * np.pi * med.Cx, med.Cy, med.Cz])
        self.cable_weights = cable_weights(model)
        for name in SAMPLED:
            getattr(self, name).flags.writeable = False
