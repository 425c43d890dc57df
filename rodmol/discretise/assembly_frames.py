"""What a System's recorded frames give beyond the rates: each rod's system as at the
frames (:func:`recorded_rod`, its penalty joints and rod contacts replayed) and the
momenta (:func:`momentum`), read by :class:`rodmol.SystemResult`."""

import numpy as np

from .joints import RecordedJoints, RodJointPart
from .rotations import matrices


def recorded_rod(assembly, name, t, states, sd=None):
    """Rod ``name``'s system of the :class:`Assembly` ``assembly`` (or ``sd``, a copy of it) for rebuilding its
    Result from the frames ``states`` (n_t, size) at ``t``: if penalty
    joints hold it to bodies or it touches rods (:class:`rodmol.RodContact`),
    a :class:`RecordedJoints` replaying their held points and contact forces
    at the frames, else ``sd`` itassembly."""
    sd = assembly.rods[name] if sd is None else sd
    joints = [joint for joint in assembly.joints + assembly.rod_joints if joint.joint.rod == name]
    touching = assembly.rod_pairs is not None and name in assembly.rod_pairs.rods
    if not joints and not touching:
        return sd
    replay = assembly.rod_pairs.replay(name, t, states) if touching else []
    for joint in joints:
        rows, values = np.tile(joint.row, (len(t), 1)), np.zeros((len(t), 3))
        for i, (ti, yi) in enumerate(zip(t, states)):
            yi = np.ascontiguousarray(yi)
            if isinstance(joint, RodJointPart):
                joint.wrench(yi, rows[i], values[i])
            else:
                joint.wrench(yi, assembly.body_state(joint.part, ti, yi), rows[i], values[i])
        replay.append((joint.entry, rows, values))
    return RecordedJoints(sd.model, sd.scheme, t, replay)


def momentum(assembly, y):
    """Total linear momentum [kg m/s] and angular momentum about the
    global origin [kg m^2/s] of the bodies and rods, global, at the state
    ``y``: the nodes' as their mass per length times the length each
    stands for, at their integrated positions; a free body's with the
    rods' base segments it carries (:meth:`rodmol.discretise.body_part.BodyPart.carry`)."""
    linear, angular = np.zeros(3), np.zeros(3)
    for name, sd in assembly.rods.items():
        y_rod, lay = y[assembly.parts[name]], sd.layout
        rot = matrices(lay.field(y_rod, "Q"))
        lengths = sd.node_lengths[:, None]
        p = np.einsum("nij,nj->ni", rot, sd.sampled.mass * lay.field(y_rod, "v") * lengths)
        h = np.einsum("nij,nj->ni", rot, sd.sampled.inertia * lay.field(y_rod, "w") * lengths)
        linear += p.sum(axis=0)
        angular += (np.cross(lay.field(y_rod, "u"), p) + h).sum(axis=0)
    for part in assembly.free:
        r = matrices(y[part.fields["Q"]])
        v, w = y[part.fields["v"]], y[part.fields["w"]]
        momentum = part.rigid_mass @ np.concatenate([v, w])
        linear += r @ momentum[:3]
        angular += np.cross(y[part.fields["x"]], r @ momentum[:3]) + r @ momentum[3:]
    return linear, angular
