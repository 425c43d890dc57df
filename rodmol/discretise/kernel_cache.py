"""Numba's disk cache of rodmol's kernels, invalidated by any kernel source.

Numba keys a cached function on its own file's time stamp only, but rodmol's
kernels inline functions and freeze constants from other modules (the load
kinds' codes of :mod:`rodmol.load_kinds`, the parameter columns of :mod:`rodmol.loads`, the layout's
offsets, the compiled physics): after an edit or an upgrade that changed
only those, the old machine code was loaded and ran silently wrong physics.
Here every rodmol kernel's stamp also carries one digest of all the sources
its code can read, so any change to them recompiles every kernel once.
"""

import hashlib
import pickle
from pathlib import Path

from numba.core import caching

PACKAGE = Path(__file__).resolve().parents[1]
#: The sources whose code or constants a compiled kernel can read.
SOURCES = (*sorted((PACKAGE / "discretise").glob("*.py")), *sorted((PACKAGE / "solve").glob("*.py")),
           PACKAGE / "load_kinds.py", PACKAGE / "loads.py", PACKAGE / "holds.py")


def sources_digest(paths=SOURCES):
    """SHA-1 of the contents of ``paths``, in order."""
    digest = hashlib.sha1()
    for path in paths:
        digest.update(path.name.encode())
        digest.update(path.read_bytes())
    return digest.hexdigest()


DIGEST = sources_digest()


class _KernelSources:
    """A locator mixin: rodmol's own files only, stamped with :data:`DIGEST` too."""

    def get_source_stamp(self):
        return super().get_source_stamp(), DIGEST

    @classmethod
    def from_function(cls, py_func, py_file):
        if not Path(py_file).resolve().is_relative_to(PACKAGE):
            return None
        return super().from_function(py_func, py_file)


class InTreeLocator(_KernelSources, caching.InTreeCacheLocator):
    """Next to the package (``__pycache__``), where it is writable."""


class UserWideLocator(_KernelSources, caching.UserWideCacheLocator):
    """In numba's user-wide cache directory, for a read-only installation."""


def install():
    """Put the locators first in numba's list, once (a numba without that list
    keeps its own stamps: then delete ``__pycache__/*.nbi`` after an edit)."""
    locators = getattr(getattr(caching, "CacheImpl", None), "_locator_classes", None)
    if isinstance(locators, list) and InTreeLocator not in locators:
        locators[:0] = [InTreeLocator, UserWideLocator]


def cached(dispatcher):
    """True if numba's disk cache holds machine code of ``dispatcher`` stamped for today's
    sources (a run will load it), False if not (a run will compile it), None if this numba
    does not say (its cache's internals differ)."""
    try:
        return bool(dispatcher._cache._cache_file._load_index())
    except (AttributeError, OSError, EOFError, ValueError, pickle.UnpicklingError):
        return None
