"""Closing the loop: a model stepped by a controller (:class:`Simulator`).

The top floor with analysis and calibration: it drives :mod:`rodmol.solve`,
builds Results and streams into :mod:`rodmol.io`. The learning environment
(``rodmol.control.envs``, needs ``gymnasium``) is imported on demand.
"""

from .simulator import Simulator, Snapshot

__all__ = ["Simulator", "Snapshot"]
