"""A signal within DeferredSignals asks the run to stop and raises nowhere (not in a weakref
callback, where a KeyboardInterrupt is printed and lost); every backend, a rod's and a
system's, stops at its next step with the frames done, the uninterrupted run's."""

import gc
import signal
import sys
import warnings
import weakref
from pathlib import Path

import numpy as np
import pytest

import rodmol
from rodmol.discretise.assembly import Assembly
from rodmol.solve.interrupts import DeferredSignals, stop_reason

TWO_ARMS = Path(__file__).resolve().parents[2] / "examples" / "two_arms.toml"


class Thing:
    pass


def test_a_signal_asks_a_stop_raises_nowhere_and_a_second_forces_it(monkeypatch):
    lost = []
    monkeypatch.setattr(sys, "unraisablehook", lost.append)
    before = signal.getsignal(signal.SIGINT)
    with DeferredSignals() as signals:
        thing = Thing()
        ref = weakref.ref(thing, lambda _: signal.raise_signal(signal.SIGINT))
        del thing  # the signal arrives inside the weakref's callback
        gc.collect()
        assert ref() is None and not lost  # a KeyboardInterrupt there would be printed and lost
        assert stop_reason() == "interrupted by SIGINT" and signals.signal == signal.SIGINT
        with pytest.raises(KeyboardInterrupt):  # the user insists: at once
            signal.raise_signal(signal.SIGTERM)
        signals.forcing = False
        signal.raise_signal(signal.SIGINT)  # only counted (writing stops between frames on it)
        assert signals.count == 3 and signals.signal == signal.SIGINT
    assert stop_reason() is None and signal.getsignal(signal.SIGINT) is before


def _stopped(run, t_stop):
    """``run(progress)`` with SIGINT raised once the progress passed ``t_stop`` [s]."""
    def progress(t, t_end):
        if t > t_stop and not stop_reason():
            signal.raise_signal(signal.SIGINT)

    with DeferredSignals(), warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        return run(progress)


def assert_prefix(stopped, whole):
    assert not stopped.success and "interrupted by SIGINT" in stopped.message
    assert 2 <= len(stopped.t) < len(whole.t)
    np.testing.assert_array_equal(stopped.states, whole.states[:len(stopped.t)])


@pytest.mark.parametrize("backend", ["cvode", "rk23", "galpha"])
def test_a_rods_backend_stops_at_its_next_step_with_the_frames_done(backend):
    model = rodmol.paper_arm(6, tensions={11: 0.5})
    options = dict(initial="straight", output_dt=0.005, backend=backend,
                   **({"dt": 1e-4} if backend == "galpha" else {}))
    whole = rodmol.simulate(model, 0.05, **options)
    stopped = _stopped(lambda progress: rodmol.simulate(model, 0.05, progress=progress, **options), 0.02)
    assert_prefix(stopped, whole)
    assert stopped.t[-1] < 0.035  # at the next step, not the end


@pytest.mark.parametrize("linsolver", ["gmres", "dense", "sparse"])
def test_a_systems_cvode_stops_inside_its_step_or_after_it_with_the_frames_done(monkeypatch, linsolver):
    """Asked inside CVODE's step to the next output (the right-hand side): gmres and dense leave the
    step at once, sparse at its end (an exception cannot leave its linear solver)."""
    system = rodmol.load_scenario(TWO_ARMS).model
    whole = rodmol.simulate(system, 0.1, output_dt=0.01, linsolver=linsolver)
    rates = Assembly.__call__

    def asked_inside(self, t, y, out=None):
        if t > 0.035 and not stop_reason():
            signal.raise_signal(signal.SIGINT)
        return rates(self, t, y, out)

    monkeypatch.setattr(Assembly, "__call__", asked_inside)
    stopped = _stopped(lambda progress: rodmol.simulate(system, 0.1, output_dt=0.01, linsolver=linsolver), 1.0)
    assert_prefix(stopped, whole)
    assert stopped.t[-1] <= 0.04 + 1e-12  # within a step of being asked


def test_a_systems_stepping_backend_stops_at_its_next_step():
    system = rodmol.load_scenario(TWO_ARMS).model
    whole = rodmol.simulate(system, 0.05, output_dt=0.005, backend="rk23")
    stopped = _stopped(lambda progress: rodmol.simulate(system, 0.05, output_dt=0.005, backend="rk23",
                                                        progress=progress), 0.02)
    assert_prefix(stopped, whole)
