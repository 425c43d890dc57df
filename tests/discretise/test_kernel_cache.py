"""Numba's disk cache of each kernel follows every source that kernel can read."""

import shutil

from numba.core import caching

from rodmol.discretise import external, kernel_cache, stencil
from rodmol.solve import newton_matrix


def test_rodmol_kernels_are_stamped_with_the_digest_of_the_sources_they_read():
    assert caching.CacheImpl._locator_classes[:2] == [kernel_cache.InTreeLocator, kernel_cache.UserWideLocator]
    locator = kernel_cache.InTreeLocator.from_function(external.load.py_func, external.__file__)
    own, digest = locator.get_source_stamp()
    assert digest == kernel_cache.kernel_digest(external.__file__)
    # The stamp numba would use alone: the kernel's own file, blind to load_kinds.py's codes.
    assert own == caching.InTreeCacheLocator.from_function(external.load.py_func, external.__file__).get_source_stamp()
    read = {path.relative_to(kernel_cache.PACKAGE).as_posix() for path in kernel_cache.reads(stencil.__file__)}
    assert {"load_kinds.py", "loads.py", "holds.py", "discretise/layout.py", "discretise/stencil.py",
            "discretise/physics.py", "discretise/external.py"} <= read
    assert "solve/stepping.py" not in read and "simulate.py" not in read
    newton = {path.name for path in kernel_cache.reads(newton_matrix.__file__)}
    assert {"newton_matrix.py", "stencil.py", "preconditioner.py", "load_kinds.py"} <= newton


def _package_copy(tmp_path):
    copy = tmp_path / "rodmol"
    shutil.copytree(kernel_cache.PACKAGE, copy, ignore=shutil.ignore_patterns("__pycache__"))
    return copy


def _forget():
    for memo in (kernel_cache.reads, kernel_cache.kernel_digest, kernel_cache._imported, kernel_cache._file_digest):
        memo.cache_clear()


def _digests(package, modules):
    return {m: kernel_cache.kernel_digest(package / m, package) for m in modules}


def test_an_edit_recompiles_the_kernels_that_read_the_edited_source_and_no_other(tmp_path):
    package = _package_copy(tmp_path)
    modules = ("discretise/stencil.py", "discretise/external.py", "discretise/rotations.py",
               "discretise/preconditioner.py", "solve/newton_matrix.py")
    before = _digests(package, modules)
    assert before == _digests(kernel_cache.PACKAGE, modules)  # the same sources, the same stamps

    kinds = package / "load_kinds.py"
    kinds.write_text(kinds.read_text().replace("Kernel(4,", "Kernel(5,", 1))  # e.g. a load kind's code edited
    _forget()
    kinds_edited = _digests(package, modules)
    assert {m for m in modules if kinds_edited[m] != before[m]} == set(modules) - {"discretise/rotations.py"}

    stepping = package / "solve" / "stepping.py"
    stepping.write_text(stepping.read_text() + "\n# an edit of the solver's Python\n")
    _forget()
    assert _digests(package, modules) == kinds_edited  # no kernel reads stepping.py


def test_a_function_outside_the_package_keeps_numbas_own_locator(tmp_path):
    script = tmp_path / "user.py"
    script.write_text("def f():\n    return 1\n")
    namespace = {}
    exec(compile(script.read_text(), str(script), "exec"), namespace)
    assert kernel_cache.InTreeLocator.from_function(namespace["f"], str(script)) is None
    assert kernel_cache.UserWideLocator.from_function(namespace["f"], str(script)) is None


def test_cached_tells_whether_a_run_compiles_or_loads(tmp_path, monkeypatch):
    """kernel_cache.cached reads numba's index: False before a kernel's first compilation,
    True once its machine code is on disk; the progress line says which."""
    import importlib.util

    from rodmol.solve import kernels

    script = tmp_path / "kernel_module.py"
    script.write_text("import numba\n\n@numba.njit(cache=True)\ndef twice(x):\n    return 2.0 * x\n")
    spec = importlib.util.spec_from_file_location("kernel_module", script)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    assert kernel_cache.cached(module.twice) is False
    assert module.twice(1.5) == 3.0
    assert kernel_cache.cached(module.twice) is True
    assert kernel_cache.cached(lambda: None) is None  # not a numba kernel: no answer

    monkeypatch.setattr(kernels, "cached", lambda dispatcher: False)
    assert kernels.stage_text().startswith("compiling the kernels") and "once" in kernels.stage_text()
    monkeypatch.setattr(kernels, "cached", lambda dispatcher: True)
    assert kernels.stage_text() == "preparing the compiled kernels"
