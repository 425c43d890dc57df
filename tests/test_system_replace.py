"""System.replace rebuilds a system from its parts as given, and a
SystemResult pickles after its parts were read (what calibration's runs do)."""

import pickle

import numpy as np
import pytest

import rodmol

MATERIAL = rodmol.Material(E=1e5, nu=0.5, mu=300.0, rho=1080.0)


def _beam(n=6):
    return rodmol.Model(rodmol.Rod(0.2, radius=0.01, material=MATERIAL), n)


def _pinned_beam():
    """A beam pinned at its base (a base body) and clamped at its tip (a penalty hold)."""
    return rodmol.System({"beam": _beam()}, joints=[rodmol.Joint(("beam", "base"), "world", kind="pin"),
                                                    rodmol.Joint(("beam", "tip"), "world")])


def test_replace_rebuilds_from_the_given_parts_not_the_joined_ones():
    system = _pinned_beam()
    assert len(system.rods["beam"].loads) == 1 and list(system.bodies) == ["beam.base"]
    stiffer = rodmol.Model(rodmol.Rod(0.2, radius=0.01, material=rodmol.Material(E=2e5, nu=0.5, rho=1080.0)), 6)
    new = system.replace(rods={"beam": stiffer}, medium="water")
    assert new.rods["beam"].rod.material.E == 2e5 and new.rods["beam"].medium.rho == 1022.0
    assert len(new.rods["beam"].loads) == 1 and list(new.bodies) == ["beam.base"]  # one hold, one base body
    assert [h.name for h in new.rods["beam"].loads] == [h.name for h in system.rods["beam"].loads]
    assert system.rods["beam"].rod.material.E == 1e5 and system.medium.rho == 0.0  # unchanged


def test_replace_refuses_a_part_the_system_does_not_have():
    with pytest.raises(rodmol.ParameterError, match=r"`rods`: the system has no part named 'beem'; did you mean "
                                                    r"'beam'\? \(rods: \['beam'\]\)"):
        _pinned_beam().replace(rods={"beem": _beam()})


def test_a_system_result_pickles_after_its_rods_were_read():
    body = rodmol.RigidBody(0.05, (1e-5, 1e-5, 1e-5))
    system = rodmol.System({"arm": _beam(4)}, {"head": body}, [rodmol.Joint(("head", (0.0, 0.0, 0.0)),
                                                                             ("arm", "base"))])
    result = rodmol.simulate(system, 0.02, output_dt=0.01)
    tip = result["arm"].tip  # builds the rod's Result, its base replaying the body's motion
    again = pickle.loads(pickle.dumps(result))
    assert np.array_equal(again["arm"].tip, tip) and np.array_equal(again["head"].position, result["head"].position)
