"""Closing the loop: the questions a controller asks of the model.

The top floor with analysis and calibration: a model stepped by a controller
(:class:`Simulator`, which drives :mod:`rodmol.solve`, builds Results and
streams into :mod:`rodmol.output`) and inverse statics (:func:`inverse_statics`:
the tensions whose equilibrium puts the tip on a target). The learning
environment (``rodmol.control.envs``, needs ``gymnasium``) is imported on demand.
"""

from .inverse_statics import StaticFit, inverse_statics, inverse_statics_path
from .simulator import Simulator, Snapshot
from .system_statics import SystemFit

__all__ = ["Simulator", "Snapshot", "StaticFit", "SystemFit", "inverse_statics", "inverse_statics_path"]
