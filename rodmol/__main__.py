"""``python -m rodmol`` runs the command line (see :mod:`rodmol.cli`)."""

import sys

from .io.cli import main

sys.exit(main())
