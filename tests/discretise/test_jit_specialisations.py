"""rodmol's kernels are compiled once per argument type, not once per constant."""

import importlib.util

import numpy as np


def _kernel_module(tmp_path):
    # A module outside the package: its cache stays in tmp_path, the test compiles afresh.
    script = tmp_path / "constants_module.py"
    script.write_text(
        "from rodmol.discretise.physics import jit\n\n"
        "@jit\ndef triple(a, i):\n    return (a[i], a[i + 1], a[i + 2])\n\n"
        "@jit\ndef caller(a):\n    x = triple(a, 0)\n    y = triple(a, 3)\n    return x[0] + y[2]\n")
    spec = importlib.util.spec_from_file_location("constants_module", script)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_a_helper_called_with_two_constants_is_compiled_once(tmp_path):
    module = _kernel_module(tmp_path)
    assert module.caller(np.arange(6.0)) == 5.0
    # numba alone types 0 and 3 as literals and compiles the helper twice (a fresh
    # cache compiled the stencil's helpers sixteen times more than needed).
    assert len(module.triple.signatures) == 1
    assert "Literal" not in str(module.triple.signatures)
