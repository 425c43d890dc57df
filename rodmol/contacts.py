"""Rods touching rigid bodies: :class:`Contact`, a body's shape that chosen
rods of a :class:`rodmol.System` touch (an arm grasping a payload).

The shape is a contact load of the rods (one of
:data:`rodmol.loads.CONTACT_SHAPES`: :class:`rodmol.PlaneContact`,
:class:`rodmol.CapsuleContact`, :func:`rodmol.SphereContact`, the same
penalty law with friction) given in the body's frame: the body carries it
(the shape's ``placed``) and feels the rods' contact forces with the opposite sign
(:mod:`rodmol.discretise.contact_parts`).
"""

from dataclasses import dataclass

from . import _checks
from .errors import ParameterError
from .loads import CONTACT_NAMES, CONTACT_SHAPES


@dataclass(frozen=True)
class Contact:
    """Rods touching a rigid body's shape.

    Parameters
    ----------
    body : str
        The body's name in the System's ``bodies`` (free, driven or fixed).
    rods : str or sequence of str
        The rods that touch it (every velocity node of each, as a contact
        load acts on a rod).
    shape : PlaneContact or CapsuleContact (SphereContact)
        The shape and its law: its points (``point``, ``start``, ``end``
        [m]) and ``normal`` in the body frame; ``stiffness`` and
        ``damping`` per unit length of rod [N/m^2, N s/m^2], ``friction``,
        ``slip_speed``, ``smoothing_depth`` as for a fixed obstacle. The
        damping and friction act on the sliding relative to the body.
    """

    body: str
    rods: tuple
    shape: object

    def __post_init__(self):
        if not isinstance(self.body, str) or not self.body:
            raise ParameterError(f"Contact `body` must be a body's name, got {_checks.short(self.body)}")
        rods = (self.rods,) if isinstance(self.rods, str) else self.rods
        rods = _checks.items("Contact rods", rods, str, "a rod's name")
        if not rods:
            raise ParameterError("Contact `rods` must name at least one rod")
        object.__setattr__(self, "rods", rods)
        if not isinstance(self.shape, CONTACT_SHAPES):
            raise ParameterError(f"Contact `shape` must be a {CONTACT_NAMES} (in the body frame), got "
                                 f"{_checks.short(self.shape)}")


@dataclass(frozen=True)
class RodContact:
    """One rod's side of ``contacts[index]``: its Model's load ``loads[load]``
    (the shape placed at the body's initial pose, global), moved by body
    ``body``; ``shape`` is the shape in the body frame."""

    index: int
    rod: str
    load: int
    body: str
    shape: object


def attach(contacts, rods, bodies):
    """The rods (a dict of name to Model) with each contact's shape added to
    its rods' loads, placed at the body's pose (``bodies``: name to
    RigidBody), and the :class:`RodContact` of each (contact, rod)."""
    added, records = {name: [] for name in rods}, []
    for i, contact in enumerate(contacts):
        if not isinstance(contact, Contact):  # a rodmol.RodContact: between rods (rodmol.rod_contacts)
            continue
        if contact.body not in bodies:
            raise ParameterError(f"`contacts[{i}]` names the body {contact.body!r}, which is not in `bodies`"
                                 f"{_checks.did_you_mean(contact.body, bodies)}")
        body, shape = bodies[contact.body], contact.shape
        placed = shape.placed(body.position, body.rotation, f"contacts[{i}]")
        for rod in contact.rods:
            if rod not in rods:
                raise ParameterError(f"`contacts[{i}]` names the rod {rod!r}, which is not in `rods`"
                                     f"{_checks.did_you_mean(rod, rods)}")
            if any(r.rod == rod and r.index == i for r in records):
                raise ParameterError(f"`contacts[{i}]` names the rod {rod!r} twice")
            records.append(RodContact(i, rod, len(rods[rod].loads) + len(added[rod]), contact.body, shape))
            added[rod].append(placed)
    rods = {name: m.replace(loads=tuple(m.loads) + tuple(added[name])) if added[name] else m
            for name, m in rods.items()}
    return rods, records
