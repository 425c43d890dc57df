"""A System runs through the rod's own backends (rodmol.solve.backends.BACKENDS, one table): CVODE's
one driver with the linear solvers the system offers, its failures read as a rod's, its steps stop
at its inputs' knots, and its options are the rod's."""

import warnings

import numpy as np
import pytest

import rodmol

MATERIAL = rodmol.Material(E=1e5, nu=0.5, mu=300.0, rho=1080.0)


def _arm(tension, n=8):
    return rodmol.Model(rodmol.Rod(0.2, radius=0.01, material=MATERIAL), n, gravity=(0.0, 0.0, 0.0),
                        cables=[rodmol.Cable((0.005, 0.0), 0.2, tension=tension)])


def test_a_system_that_fails_reads_as_the_same_rod_failing():
    """An overloaded thin rod alone and as a one-rod System (GMRES both): the same stop, the same
    where, when and why, the System's naming the rod. Its message said neither how far the solver
    got nor in how many steps, and its stats had no steps."""
    rod = rodmol.Rod(0.3, 0.005, rodmol.Material(E=110e3, nu=0.5, mu=300.0, rho=1080.0))
    model = rodmol.Model(rod, 20, medium="water",
                         cables=[rodmol.Cable((0.004, 0.0), 0.3, tension=[(0.0, 0.0), (0.1, 5.0)])])
    runs = []
    for thing in (model, rodmol.System({"arm": model}, medium="water")):
        with pytest.warns(RuntimeWarning):
            runs.append(rodmol.simulate(thing, 1.0, initial="straight", linsolver="gmres"))
    alone, system = runs
    assert not alone.success and not system.success
    assert alone.message.startswith("CVODE stopped after t = 0.04 s (last output frame; the solver reached")
    head, cause = alone.message.split("): ", 1)
    assert system.message == f"{head}): rod 'arm': {cause}" and "turns by" in cause
    assert system.stats["steps"] == alone.stats["steps"] and f"in {alone.stats['steps']} steps" in head
    np.testing.assert_array_equal(system.t, alone.t)


def test_a_systems_steps_stop_at_the_knots_of_its_inputs():
    """A rod at rest takes long steps; a 4 ms pulse of its cable, given as knots, starts between
    two of them. The System's CVODE strode over it (the rod never moved); it now bends the rod as
    the Model's run does."""
    pulse = [(0.0, 0.0), (0.3, 0.0), (0.302, 0.5), (0.304, 0.0)]
    arm = _arm(pulse)
    alone = rodmol.simulate(arm, 0.4, output_times=[0.35], initial="straight")
    system = rodmol.simulate(rodmol.System({"arm": arm}, gravity=(0.0, 0.0, 0.0)), 0.4, output_times=[0.35])
    moved = alone.tip[-1] - alone.tip[0]
    assert np.linalg.norm(moved) > 1e-4  # m: the pulse swings the tip
    tip = system["arm"].tip
    np.testing.assert_allclose(tip[-1] - tip[0], moved, atol=1e-3 * np.linalg.norm(moved))


def test_a_linear_solver_the_system_does_not_offer_is_refused_before_its_directory_is_made(tmp_path):
    """The run's directory (and a folder per rod) was made before the refusal."""
    out = tmp_path / "run"
    with pytest.raises(rodmol.ParameterError, match="unknown `linsolver` 'band' for ") as refused:
        rodmol.simulate(rodmol.System({"arm": _arm(0.1, 4)}), 0.1, linsolver="band", out=out)
    assert all(f"'{name}'" in str(refused.value) for name in ("gmres", "sparse", "dense"))  # those offered
    assert not out.exists()


def test_the_rods_cvode_options_run_a_system():
    """``jacobian`` and ``max_nonlin_iters`` were unknown options for a System."""
    system = rodmol.System({"arm": _arm([(0.0, 0.0), (0.05, 0.2)], 4)}, gravity=(0.0, 0.0, 0.0))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        runs = [rodmol.simulate(system, 0.1, rtol=1e-8, output_dt=0.05, linsolver="sparse", **options)
                for options in ({}, {"jacobian": "compiled"}, {"max_nonlin_iters": 5})]
    assert all(run.success and run.stats["linear_solver"] == "sparse" for run in runs)
    for run in runs[1:]:
        np.testing.assert_allclose(run["arm"].tip, runs[0]["arm"].tip, atol=1e-7 * 0.2)
    with pytest.raises(rodmol.ParameterError, match="jacobian='compiled' with linsolver='dense': a system's"):
        rodmol.simulate(system, 0.1, linsolver="dense", jacobian="compiled")


def test_a_systems_inputs_are_never_read_past_the_end_of_its_run():
    """CVODE's last step ends at t_end, as a rod's: the System's driver stepped past it and
    failed on an input recorded up to the end only."""
    def tension(t):
        if t > 0.2:
            raise ValueError(f"no tension recorded after 0.2 s (t = {t})")
        return 0.1 * t / 0.2

    system = rodmol.System({"arm": _arm(tension)}, gravity=(0.0, 0.0, 0.0))
    run = rodmol.simulate(system, 0.2, output_dt=0.05)
    assert run.success and run.t[-1] == 0.2
