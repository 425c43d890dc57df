"""The ``rodmol`` command line (``rodmol = "rodmol.cli:main"``, ``python -m rodmol``):
:mod:`~rodmol.cli.commands` (run, render, plot), :mod:`~rodmol.cli.options`
(the run options) and :mod:`~rodmol.cli.calibrate` (study, identify, sweep)."""

from .commands import main

__all__ = ["main"]
