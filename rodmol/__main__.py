"""``python -m rodmol`` runs the command line (see :mod:`rodmol.cli`)."""

import sys

from .cli import main

sys.exit(main())
