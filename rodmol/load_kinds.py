"""The kinds of external load, one record each: the branches of the compiled
load kernel (:func:`rodmol.discretise.external.load`).

Every fact about a kind that the Python side needs is a field of its
record, and every list of kinds is derived from the records: the hold kinds
of :class:`rodmol.Hold` and the joint kinds of :class:`rodmol.Joint`
(:data:`HOLD_KINDS`), the codes the rest equations, the energies and the
assembly treat as holds or contacts (:func:`codes`), the Jacobian's
dependency table, the joints' turning law, how a body moves a contact
shape. The compiled kernels read the codes as module constants derived here
(numba freezes them at compile time); adding a kind is its record here and
its branch in the kernel (docs/systems.md, "Adding a joint kind or a
contact shape"; docs/model.md, "Adding a load kind").
"""

from dataclasses import dataclass

#: What a kind adds up as: a force or a moment (the load scale adds them
#: up), a contact (a penalty against an obstacle's surface) or a hold (a
#: penalty joint of a node to a held point: rodmol.Hold, a system's joints).
QUANTITIES = ("force", "moment", "contact", "hold")
#: How a body moves each 3-vector of a contact shape's geometry: a point
#: (moved and turned with the body) or a direction (turned only).
ROLES = ("point", "direction")


@dataclass(frozen=True)
class Kernel:
    """One branch of the compiled load kernel.

    Parameters
    ----------
    code : int
        Its number in the kernel (the records' codes are 0, 1, 2, ...).
    depends : tuple of str
        The state fields of its own element block it reads (the Jacobian's
        pattern, colouring and preconditioner are derived from them).
    quantity : str
        One of :data:`QUANTITIES`.
    holds_turning : bool
        A hold: it also holds the section's orientation (the clamp's
        moment), so all six relative motions are held. A rod's base joined
        so is eliminated (a tree joint); a base held otherwise becomes a base
        body held by a body joint, and the joints' default law has a
        turning stiffness only where this is True.
    geometry : tuple of str
        A contact shape: the roles (:data:`ROLES`) of the 3-vectors that
        open its parameter row, in order (the first a point: the obstacle's
        material point whose motion the row carries).
    """

    code: int
    depends: tuple
    quantity: str
    holds_turning: bool = False
    geometry: tuple = ()


#: The kernel's branches, by name; a load names its branch in ``kernel``.
KERNELS = {
    "follower_force": Kernel(0, (), "force"),
    "dead_force": Kernel(1, ("Q",), "force"),
    "follower_moment": Kernel(2, (), "moment"),
    "dead_moment": Kernel(3, ("Q",), "moment"),
    "plane": Kernel(4, ("u", "Q", "v", "w"), "contact", geometry=("point", "direction")),
    "capsule": Kernel(5, ("u", "Q", "v", "w"), "contact", geometry=("point", "point")),
    "pin": Kernel(6, ("u", "Q", "v"), "hold"),
    "clamp": Kernel(7, ("u", "Q", "v", "w"), "hold", holds_turning=True),
}


def names(quantity):
    """The names of the kinds of ``quantity``, in the records' order."""
    return tuple(name for name, kind in KERNELS.items() if kind.quantity == quantity)


def codes(quantity, **fields):
    """The codes of the kinds of ``quantity`` (a tuple of ints: the compiled
    kernels read it as a constant) whose records also have the given
    ``fields`` values (e.g. ``holds_turning=True``)."""
    return tuple(kind.code for kind in KERNELS.values() if kind.quantity == quantity
                 and all(getattr(kind, f) == value for f, value in fields.items()))


#: The hold kinds (rodmol.Hold's ``kind``, a system Joint's ``kind``).
HOLD_KINDS = names("hold")
