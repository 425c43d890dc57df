"""Closing the loop: the questions a controller asks of the model.

The top floor with analysis and calibration: a model stepped by a controller
(:class:`Simulator`, which drives :mod:`rodmol.solve`, builds Results and
streams into :mod:`rodmol.output`) and inverse statics (:func:`inverse_statics`:
the tensions whose equilibrium puts the tip on a target). The learning
environments (``rodmol.control.envs``, needs ``gymnasium``) are registered
with gymnasium here when it is installed (:mod:`.registration`) and imported
by ``gymnasium.make``.
"""

from .inverse_statics import StaticFit, inverse_statics, inverse_statics_path
from .optimal_tensions import TensionPlan, optimal_tensions
from .registration import register_environments
from .simulator import Simulator, Snapshot
from .system_fit import SystemFit

register_environments()

__all__ = ["Simulator", "Snapshot", "StaticFit", "SystemFit", "TensionPlan", "inverse_statics", "inverse_statics_path",
           "optimal_tensions"]
