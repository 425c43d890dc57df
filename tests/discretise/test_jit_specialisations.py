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


def _compilations(run):
    """The (function name, argument types) numba compiles while ``run()`` runs."""
    from numba.core import event

    seen = []

    class Recorder(event.Listener):
        def on_start(self, ev):
            seen.append((ev.data["dispatcher"].py_func.__name__, str(ev.data["args"])))

        def on_end(self, ev):
            pass

    recorder = Recorder()
    event.register("numba:compile", recorder)
    try:
        run()
    finally:
        event.unregister("numba:compile", recorder)
    return seen


def test_a_helper_called_with_two_constants_is_compiled_once(tmp_path):
    module = _kernel_module(tmp_path)
    result = []
    compiled = _compilations(lambda: result.append(module.caller(np.arange(6.0))))
    assert result == [5.0]
    # numba alone types 0 and 3 as literals and compiles the helper twice (a fresh
    # cache compiled the stencil's helpers sixteen times more than needed).
    helper = [args for name, args in compiled if name == "triple"]
    assert len(helper) == 1 and "Literal" not in helper[0]
    assert module.triple(np.arange(6.0), 2) == (2.0, 3.0, 4.0)  # and it is callable from Python


def test_kernels_of_strided_views_are_compiled_once_for_any_layout():
    """Post-processing reads strided views of the states and contiguous arrays: one
    compilation serves both (numba alone compiled each of these kernels twice)."""
    from rodmol.discretise import centreline, rotations

    rng = np.random.default_rng(0)
    quat = rng.normal(size=(3, 5, 4))
    states = rng.normal(size=(3, 5, 11))  # strain fields are strided views of states
    q, k = states[..., 4:7], states[..., 7:10]
    for quat_in in (quat, quat[:, :, :]):  # contiguous, then a strided view with the others
        chords = centreline.chords(quat_in, q, k, 0.01)
    strided = np.concatenate([quat, quat], axis=-1)[..., :4]
    assert np.allclose(centreline.chords(strided, q, k, 0.01), chords)
    matrices = rotations.matrices(quat)
    vectors = rng.normal(size=(3, 5, 3))
    turned = rotations.rotate(matrices, vectors)
    assert np.allclose(rotations.rotate(matrices, states[..., :3].copy()), np.einsum("fnij,fnj->fni", matrices, states[..., :3]))
    assert np.allclose(turned, np.einsum("fnij,fnj->fni", matrices, vectors))
    unit = quat.copy()
    rotations.normalise(unit)
    view = states[..., :4]
    rotations.normalise(view)
    assert np.allclose(np.linalg.norm(unit, axis=-1), 1.0) and np.allclose(np.linalg.norm(view, axis=-1), 1.0)
    for kernel in (centreline._chords, rotations._rotate, rotations._normalise):
        assert len(kernel.signatures) == 1, kernel
