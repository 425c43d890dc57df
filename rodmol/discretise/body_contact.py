"""Contact of a free rigid body with fixed obstacles, through the rods' contact law.

A body's contacts (:class:`rodmol.RigidBody` ``contacts``) pair every
obstacle with every contact point: a sphere of radius r around a point c of
the body frame. Each pair is one call of the rods' compiled law
(:func:`rodmol.discretise.external.contact`) with the sphere standing in for
a tube section: centre u = x + R c (global), the body's rotation R, the
point's velocity v + w x c and the body's angular velocity w (body frame),
the section radius r. The law returns a density for a rod; a body's row
holds the stiffness per point [N/m] and damping [N s/m], so it returns a
force [N], acting at the surface point, and its moment about c.
"""

import numpy as np

from ..loads import KERNELS, N_PARAMS, P_SMOOTHING
from .external import contact, contact_energy
from .physics import add, cross, jit, rotation, to_global
from .rigid import BQ, BV, BW, BX, _row3
from .rotations import matrices


@jit
def contact_wrench(kinds, rows, points, body, out):
    """Force and moment [N, N m] about the body origin, body frame, of the
    contact pairs (``kinds`` codes, ``rows`` (n, N_PARAMS) the law's
    parameters with the sphere's radius, ``points`` (n, 3) [m] the spheres'
    centres, body frame) on a body in the state ``body`` (x, Q, v, w: origin
    [m], quaternion, global; velocities [m/s, rad/s], body frame). Each
    pair's force and moment go into ``out`` (n, 6)."""
    x_b = _row3(body, BX)
    quat = (body[BQ], body[BQ + 1], body[BQ + 2], body[BQ + 3])
    v_b, w_b = _row3(body, BV), _row3(body, BW)
    r_b = rotation(quat)
    force, torque = (0.0, 0.0, 0.0), (0.0, 0.0, 0.0)
    for i in range(kinds.shape[0]):
        c = _row3(points[i], 0)
        u = add(x_b, to_global(r_b, c))
        f, m = contact(kinds[i], rows[i], u, r_b, add(v_b, cross(w_b, c)), w_b)
        m = add(m, cross(c, f))
        for j in range(3):
            out[i, j] = f[j]
            out[i, 3 + j] = m[j]
        force, torque = add(force, f), add(torque, m)
    return force, torque


class BodyContacts:
    """The contact pairs of a :class:`rodmol.RigidBody` (every obstacle with
    every contact point) as the compiled law's arrays: ``kinds`` (n,),
    ``rows`` (n, N_PARAMS), ``points`` (n, 3) [m], body frame."""

    def __init__(self, body):
        n = len(body.contact_points)
        kinds, rows = [], []
        for obstacle in body.contacts:
            kinds += [KERNELS[obstacle.kernel].code] * n
            law = obstacle.params(body.contact_radius)
            if obstacle.smoothing_depth is None:  # a body's default: of its size (rodmol.RigidBody)
                law[:, P_SMOOTHING] = body.contact_smoothing
            rows.append(law)
        self.kinds = np.array(kinds, dtype=np.int64)
        self.rows = np.ascontiguousarray(np.concatenate(rows) if rows else np.zeros((0, N_PARAMS)))
        self.points = np.ascontiguousarray(np.tile(body.contact_points, (len(body.contacts), 1)))
        self.pairs = np.zeros((len(self.kinds), 6))

    def wrench(self, body):
        """(6,) force and moment [N, N m] about the origin, body frame, on a
        body in the state ``body`` (x, Q, v, w); each pair's in ``pairs``."""
        force, torque = contact_wrench(self.kinds, self.rows, self.points, np.ascontiguousarray(body), self.pairs)
        return np.array([*force, *torque])

    def forces(self, body):
        """(n, 3) each pair's force [N], global, on a body in the state ``body``."""
        self.wrench(body)
        return self.pairs[:, :3] @ matrices(body[BQ:BQ + 4]).T

    def energy(self, body):
        """Elastic energy [J] of the penalties at the pose in ``body`` (the law's energy density per point)."""
        centres = body[BX:BX + 3] + self.points @ matrices(body[BQ:BQ + 4]).T
        return sum(contact_energy(k, row, tuple(u)) for k, row, u in zip(self.kinds, self.rows, centres))
