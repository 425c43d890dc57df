"""Numba's disk cache of rodmol's kernels, invalidated by every source a kernel reads.

Numba keys a cached function on its own file's time stamp only, but rodmol's
kernels inline functions and freeze constants from other modules (the load
kinds' codes of :mod:`rodmol.load_kinds`, the parameter columns of :mod:`rodmol.loads`, the layout's
offsets, the compiled physics): after an edit or an upgrade that changed
only those, the old machine code was loaded and ran silently wrong physics.
Here every rodmol kernel's stamp also carries a digest of the sources its code can
read: its own module and every rodmol module that one imports, transitively
(:func:`reads`). An edit recompiles the kernels whose modules reach the edited file
and no other (an edit of ``solve/stepping.py`` leaves the stencil's machine code be).
"""

import functools
import hashlib
import pickle
import re
from pathlib import Path

from numba.core import caching

PACKAGE = Path(__file__).resolve().parents[1]
#: The sources whose code or constants a compiled kernel can read (all kernels together).
SOURCES = (*sorted((PACKAGE / "discretise").glob("*.py")), *sorted((PACKAGE / "solve").glob("*.py")),
           PACKAGE / "load_kinds.py", PACKAGE / "loads.py", PACKAGE / "holds.py")


def sources_digest(paths=SOURCES):
    """SHA-1 of the names and contents of ``paths``, in order."""
    digest = hashlib.sha1()
    for path in paths:
        digest.update(path.name.encode())
        digest.update(path.read_bytes())
    return digest.hexdigest()


def _module_file(stem, package):
    """The source of module or package ``stem`` (a path without suffix) inside ``package``, or None."""
    for candidate in (stem.with_suffix(".py"), stem / "__init__.py"):
        if candidate.is_file() and candidate.resolve().is_relative_to(package):
            return candidate.resolve()
    return None


#: A top-level import statement (at the start of a line): ``from .x import a, b`` (names
#: possibly in parentheses over several lines) or ``import rodmol.x``.
_IMPORT = re.compile(r"^(?:from[ \t]+(\.*)([\w.]*)[ \t]+import[ \t]+(\([^)]*\)|[^\n]*)|import[ \t]+([\w., \t]+))",
                     re.MULTILINE)


@functools.cache
def _imported(path, package):
    """The rodmol modules that the module at ``path`` imports at its top level (not
    transitively; imports inside functions run after compilation, kernels cannot read them).
    Read with a pattern, not parsed: a run's start stamps every kernel with these."""
    found = set()
    for level, module, names, plain in _IMPORT.findall(path.read_text()):
        if plain:
            found.update(_module_file(package.parent.joinpath(*name.split()[0].split(".")), package)
                         for name in plain.split(",") if name.split() and name.split()[0].split(".")[0] == package.name)
            continue
        if level:
            base = path.parent.parents[len(level) - 2] if len(level) > 1 else path.parent
        elif module.split(".")[0] == package.name:
            base = package.parent
        else:
            continue
        stem = base.joinpath(*module.split(".")) if module else base
        listed = [n.split()[0] for n in re.sub(r"#[^\n]*", "", names).strip("()").split(",") if n.split()]
        # A submodule imported by name, or else a name from the module (or package) itself.
        submodules = [_module_file(stem / name, package) for name in listed]
        found.update(submodules)
        if not all(submodules):
            found.add(_module_file(stem, package))
    found.discard(None)
    return frozenset(found)


@functools.cache
def reads(path, package=PACKAGE):
    """The sources a kernel defined in the module at ``path`` can read: that module and the
    modules of ``package`` (rodmol) it imports at their top level, transitively, sorted."""
    seen, todo = set(), [Path(path).resolve()]
    while todo:
        current = todo.pop()
        if current not in seen:
            seen.add(current)
            todo += _imported(current, package) - seen
    return tuple(sorted(seen))


@functools.cache
def kernel_digest(path, package=PACKAGE):
    """The digest of :func:`reads` of ``path``: a kernel's cache stamp carries it."""
    digest = hashlib.sha1()
    for source in reads(path, package):
        digest.update(source.relative_to(package).as_posix().encode())
        digest.update(_file_digest(source))
    return digest.hexdigest()


@functools.cache
def _file_digest(path):
    return hashlib.sha1(path.read_bytes()).digest()


class _KernelSources:
    """A locator mixin: rodmol's own files only, stamped with :func:`kernel_digest` too."""

    def get_source_stamp(self):
        return super().get_source_stamp(), kernel_digest(self._py_file)

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
