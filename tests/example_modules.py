"""Example scripts loaded as modules without putting examples/ on ``sys.path``: solvers/ holds
scripts of the same names (octopus.py), which the solver scripts import as their siblings."""

import importlib.util
from pathlib import Path

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def load_example(script):
    """examples/``script`` (a file name or path) as a module named ``<stem>_example``; its
    ``__main__`` part is not run."""
    path = EXAMPLES / Path(script).name
    spec = importlib.util.spec_from_file_location(path.stem + "_example", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module
