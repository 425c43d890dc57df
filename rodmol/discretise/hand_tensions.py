"""A model whose cable tensions are given by hand: the inputs linearisation and inverse
statics differentiate by (:func:`tensions_by_hand`)."""

from dataclasses import replace


def tensions_by_hand(model):
    """The same model with every cable in the kernel and its tension given by
    hand (``tensions=`` to :meth:`SemiDiscrete.rest_rates`): a constant
    nonzero tension keeps each cable in the kernel, and displacement control
    and feedback laws are dropped. The routing and friction of each cable
    stay as they are. The linearisation and the inverse statics differentiate
    with respect to the tensions of this model."""
    return model.replace(cables=[replace(c, tension=1.0, displacement=None, compliance=None,
                                         base_to_actuator=0.0, rest_length=None) for c in model.cables])
