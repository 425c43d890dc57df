"""Distributed runs survive faults: a worker killed mid-task has its task rerun
(nothing lost, the numbers of serial runs), and a run that fails comes back as
a failed row with its message instead of ending the sweep."""

import numpy as np
from experiments import KillOnce

import rodmol
from rodmol.calibrate import apply, spec_of, sweep

ROD = rodmol.Rod(0.3, (0.012, 0.005), rodmol.Material(E=110e3, nu=0.5, mu=300.0, rho=1080.0))


def small_spec(**cable):
    cables = [rodmol.Cable((0.004, 0.0), 0.3, name="pull", **cable)] if cable else []
    return spec_of(rodmol.Model(ROD, 4, medium="water", cables=cables), 0.05, output_dt=0.01)


def assert_serial(spec, runs):
    for run in runs:
        serial = apply(spec, run.overrides).simulate()
        assert run.success, run.message
        np.testing.assert_array_equal(run.result.states, serial.states)


def test_a_worker_killed_mid_task_is_rerun(dask_client, tmp_path):
    marker = tmp_path / "killed"
    spec = small_spec(tension=KillOnce(marker))
    overrides = [{"material.E": e} for e in (90e3, 110e3, 130e3)]
    runs = sweep(spec, overrides, client=dask_client, keep=True)
    assert marker.exists()  # a worker did die, in the middle of a run
    assert [r.overrides for r in runs.runs] == overrides
    assert_serial(spec, runs.runs)


def test_a_failing_run_is_a_failed_row(dask_client):
    spec = small_spec()
    overrides = [{"medium.rho": 1000.0}, {"medium.rho": 1e308}, {"medium.rho": 1200.0}]
    runs = sweep(spec, overrides, client=dask_client, keep=True)
    assert [r.success for r in runs.runs] == [True, False, True]
    row = runs.rows()[1]
    assert not row["success"] and row["medium.rho"] == 1e308
    assert row["message"].startswith("ParameterError: physical parameters out of any meaningful range")
    assert "the medium's density `rho` = 1e+308 kg/m^3" in row["message"]
    assert_serial(spec, [runs.runs[0], runs.runs[2]])
    serial = sweep(spec, overrides, client="serial")  # the same rows without dask
    assert [r.message for r in serial.runs] == [r.message for r in runs.runs]
