"""Numba's disk cache of the kernels follows every source a kernel can read."""

import shutil

from numba.core import caching

from rodmol.discretise import external, kernel_cache


def test_rodmol_kernels_are_stamped_with_the_digest_of_every_kernel_source():
    assert caching.CacheImpl._locator_classes[:2] == [kernel_cache.InTreeLocator, kernel_cache.UserWideLocator]
    locator = kernel_cache.InTreeLocator.from_function(external.load.py_func, external.__file__)
    own, digest = locator.get_source_stamp()
    assert digest == kernel_cache.DIGEST == kernel_cache.sources_digest()
    # The stamp numba would use alone: the kernel's own file, blind to load_kinds.py's codes.
    assert own == caching.InTreeCacheLocator.from_function(external.load.py_func, external.__file__).get_source_stamp()
    names = {path.name for path in kernel_cache.SOURCES}
    assert {"load_kinds.py", "loads.py", "holds.py", "layout.py", "stencil.py", "physics.py", "newton_matrix.py"} <= names


def test_a_function_outside_the_package_keeps_numbas_own_locator(tmp_path):
    script = tmp_path / "user.py"
    script.write_text("def f():\n    return 1\n")
    namespace = {}
    exec(compile(script.read_text(), str(script), "exec"), namespace)
    assert kernel_cache.InTreeLocator.from_function(namespace["f"], str(script)) is None
    assert kernel_cache.UserWideLocator.from_function(namespace["f"], str(script)) is None


def test_changing_any_kernel_source_changes_the_digest(tmp_path):
    copies = []
    for path in kernel_cache.SOURCES:
        copy = tmp_path / path.parent.name / path.name
        copy.parent.mkdir(exist_ok=True)
        shutil.copy(path, copy)
        copies.append(copy)
    assert kernel_cache.sources_digest(copies) == kernel_cache.DIGEST
    kinds = next(c for c in copies if c.name == "load_kinds.py")
    kinds.write_text(kinds.read_text().replace("Kernel(4,", "Kernel(5,", 1))  # e.g. a load kind's code edited
    assert kernel_cache.sources_digest(copies) != kernel_cache.DIGEST


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
