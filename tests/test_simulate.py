"""simulate builds one system and takes its sizes and default tolerances from it."""

import subprocess
import sys

import numpy as np
import pytest

import rodmol
from rodmol.discretise.layout import BLOCK, FIELDS, HEADER
from rodmol.discretise.system import SemiDiscrete


def test_equilibrium_of_a_built_system_is_the_models():
    model = rodmol.scenarios.get("fetching").model(8)
    for scheme in rodmol.SCHEMES:
        system = SemiDiscrete(model, scheme)
        np.testing.assert_array_equal(rodmol.equilibrium(system, 0.1),
                                      rodmol.equilibrium(model, 0.1, scheme=scheme))


def test_default_atol_is_the_systems_scale_times_rtol_and_simulates_as_the_default():
    model = rodmol.scenarios.get("bending").model(6)
    system = SemiDiscrete(model)
    np.testing.assert_array_equal(rodmol.default_atol(model, 1e-5), 1e-5 * system.atol_scale())
    by_default = rodmol.simulate(model, 0.02, rtol=1e-5)
    given = rodmol.simulate(model, 0.02, rtol=1e-5, atol=rodmol.default_atol(model, 1e-5))
    np.testing.assert_array_equal(by_default.states, given.states)
    assert by_default.stats["steps"] == given.stats["steps"]


def test_simulate_builds_one_system_and_hands_it_on(monkeypatch):
    model = rodmol.scenarios.get("bending").model(6)
    rodmol.simulate(model, 0.01)  # the kernels made ready: the run below builds only its own
    built, seen = [], []
    module = sys.modules["rodmol.run_arguments"]  # where a run's initial state is solved
    init, solve = SemiDiscrete.__init__, module.equilibrium

    def counting(self, *args, **kwargs):
        built.append(self)
        init(self, *args, **kwargs)

    def spying(system, t):
        seen.append(system)
        return solve(system, t)

    monkeypatch.setattr(SemiDiscrete, "__init__", counting)
    monkeypatch.setattr(module, "equilibrium", spying)
    result = rodmol.simulate(model, 0.02)
    assert result.success and len(built) == 1 and seen == built


def test_a_state_sized_argument_is_sized_by_the_systems_layout():
    model = rodmol.scenarios.get("bending").model(6)
    size = SemiDiscrete(model).size
    with pytest.raises(rodmol.ParameterError, match=rf"`atol` must have length {size} \(the state size\)"):
        rodmol.simulate(model, 0.01, atol=np.ones(size + 1))
    bad = np.ones(size)
    index = HEADER + BLOCK * 2 + FIELDS["q"].start
    bad[index] = -1.0
    with pytest.raises(rodmol.ParameterError, match=rf"-1.0 at entry {index} \(q\[0\] of element 2\)"):
        rodmol.simulate(model, 0.01, atol=bad)


@pytest.mark.subprocess
def test_a_state_sized_argument_is_refused_before_compiling_and_a_system_compiles_when_first_evaluated():
    """Building the system compiles nothing, so simulate checks ``atol`` against it before
    any work; its first evaluation waits for the compiler (a fresh process sees both)."""
    code = ("import rodmol\n"
            "from rodmol.discretise import compiling\n"
            "model = rodmol.scenarios.get('bending').model(6)\n"
            "try:\n"
            "    rodmol.simulate(model, 1.0, atol=[1.0, 2.0])\n"
            "except rodmol.ParameterError as error:\n"
            "    print('refused' if 'atol' in str(error) else error)\n"
            "print(len(compiling._UNCOMPILED))\n"
            "system = rodmol.SemiDiscrete(model)\n"
            "print(len(compiling._UNCOMPILED))\n"
            "system(0.0, rodmol.straight_state(model))\n"
            "print(len(compiling._UNCOMPILED))\n")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300, check=False)
    assert out.returncode == 0, out.stderr
    refused, before, built, evaluated = out.stdout.split()
    # Evaluated: the right-hand side is compiled (the helper's kernels at their first call).
    assert refused == "refused" and int(before) == int(built) > int(evaluated)


def _arm(n):
    return rodmol.paper_arm(n, markers=())


def test_an_initial_result_of_another_grid_or_kind_is_refused_naming_it():
    earlier = rodmol.simulate(_arm(4), 0.02, initial="straight")
    with pytest.raises(rodmol.ParameterError, match=r"83 entries \(N = 4 elements\), this model's 121"):
        rodmol.simulate(_arm(6), 0.04, initial=earlier)
    with pytest.raises(rodmol.ParameterError, match="a Result cannot start a run of a System"):
        rodmol.simulate(rodmol.System({"arm": _arm(4)}), 0.04, initial=earlier)
    with pytest.raises(rodmol.ParameterError, match="`overwrite=True` needs `out`"):
        rodmol.simulate(_arm(4), 0.02, overwrite=True)


def test_a_refused_initial_state_leaves_the_run_overwrite_would_replace(tmp_path):
    first = rodmol.simulate(_arm(4), 0.02, out=tmp_path, initial="straight")
    collapsed = np.zeros_like(first.states[-1])
    with pytest.raises(rodmol.ParameterError, match="not a state of this model: element 0 inverted"):
        rodmol.simulate(_arm(4), 0.02, out=tmp_path, overwrite=True, initial=collapsed)
    np.testing.assert_array_equal(rodmol.load_result(tmp_path).states, first.states)


def test_a_sink_that_cannot_resume_is_refused_before_any_work(tmp_path):
    from rodmol.output.stream import RunWriter
    from rodmol.output.system_stream import SystemRunWriter

    with pytest.raises(rodmol.ParameterError, match="holds no run to resume"):
        rodmol.simulate(_arm(4), 0.02, out=RunWriter(tmp_path / "rod"), resume=True)
    with pytest.raises(rodmol.ParameterError, match="holds no run to resume"):
        rodmol.simulate(rodmol.System({"arm": _arm(4)}), 0.02, out=SystemRunWriter(tmp_path / "system"),
                        resume=True)

    class Forgetful:  # streams, but keeps no settings to check a resumed call against
        chunk_frames = 10

        def __init__(self):
            self.begin = self.frames = self.end = self.resume_point = lambda *args: None

    with pytest.raises(rodmol.ParameterError, match="cannot resume \\(it has no check, record_settings\\)"):
        rodmol.simulate(_arm(4), 0.02, out=Forgetful(), resume=True)
