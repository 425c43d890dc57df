"""Models, systems and results pickle (sweeps and identification send them to
other processes); inputs that pickle cannot store are named in the error."""

import pickle

import numpy as np
import pytest

import rodmol
from rodmol.discretise.sampling import SAMPLED, Sampled
from rodmol.scenario.file import parse_scenario

#: A scenario with every kind of input a file can give: the paper's tensions,
#: a moving base, a point force from knots, a distributed force and a floor.
SCENARIO = """
name = "everything"
arm = "paper"
scenario = "bending"
[discretization]
n_elements = 10
[solver]
t_end = 0.5
[base]
velocity = [0.0, 0.01, 0.0]
[[load]]
type = "point_force"
s = 0.418
force = [[0.0, 0.0, 0.0, 0.0], [0.5, 0.0, 0.0, 0.02]]
[[load]]
type = "distributed_force"
force = [0.0, 0.0, 0.01]
[[load]]
type = "plane_contact"
point = [0.0, -0.2, 0.0]
normal = [0.0, 1.0, 0.0]
stiffness = 100.0
"""


def test_scenario_model_round_trips_and_runs_the_same():
    spec = parse_scenario(SCENARIO)
    copy = pickle.loads(pickle.dumps(spec.model))
    assert np.array_equal(copy.s_nodes, spec.model.s_nodes)
    assert all(np.array_equal(getattr(Sampled(copy), name), getattr(Sampled(spec.model), name))
               for name in SAMPLED)
    a = rodmol.simulate(spec.model, 0.2)
    b = rodmol.simulate(copy, 0.2)
    assert np.array_equal(a.markers, b.markers) and np.array_equal(a.external_force, b.external_force)


def test_result_round_trips_lazily_and_after_access():
    spec = parse_scenario(SCENARIO)
    result = rodmol.simulate(spec.model, 0.5)
    lazy = pickle.loads(pickle.dumps(result))  # before any derived array was read
    for name in rodmol.result.ARRAYS:
        assert np.array_equal(getattr(lazy, name), getattr(result, name)), name
    again = pickle.loads(pickle.dumps(result))  # after: the arrays themselves
    assert np.array_equal(again.internal_moment, result.internal_moment)
    assert (again.success, again.message, again.meta) == (result.success, result.message, result.meta)


def test_system_pickles_as_its_model():
    system = rodmol.SemiDiscrete(rodmol.paper_arm(8, tensions={11: 1.0}))
    copy = pickle.loads(pickle.dumps(system))
    y = rodmol.straight_state(system.model)
    assert np.array_equal(copy(0.0, y), system(0.0, y))


def test_inline_function_inputs_are_named_in_the_error():
    model = rodmol.paper_arm(8, tensions={11: lambda t: min(t, 1.0)})
    with pytest.raises(pickle.PicklingError, match=r"cable 'cable 11' tension is an inline Python function"):
        pickle.dumps(model)
    loaded = rodmol.paper_arm(8, loads=[rodmol.DistributedForce(lambda s, t: (0.0, 0.0, 1.0))])
    with pytest.raises(pickle.PicklingError, match=r"load 'distributed force'"):
        pickle.dumps(loaded)
