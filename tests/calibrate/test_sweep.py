"""Sweeps: a LocalCluster with 2 workers returns the numbers of serial runs."""

import csv

import numpy as np
import pytest
from experiments import paper_spec

from rodmol import ParameterError, load_result
from rodmol.calibrate import apply, grid, sweep


def test_grid_is_every_combination():
    runs = grid({"material.E": [1, 2, 3], "medium.Cy,Cz": [4, 5]})
    assert len(runs) == 6 and runs[1] == {"material.E": 1, "medium.Cy,Cz": 5}


def test_sweep_on_a_local_cluster_equals_serial_runs(dask_client, tmp_path):
    spec = paper_spec("bending", t_end=1.0)
    overrides = grid({"material.E": [90e3, 130e3], "medium.Cy,Cz": [2.0, 3.0]})
    done = []
    runs = sweep(spec, overrides, client=dask_client, out=tmp_path, keep=True,
                 progress=lambda i, n: done.append((i, n)))
    assert done[-1] == (4, 4)
    for o, run in zip(overrides, runs.runs):
        serial = apply(spec, o).simulate()
        assert run.success and run.overrides == o
        assert np.array_equal(run.result.markers, serial.markers)
        assert np.array_equal(run.result.internal_force, serial.internal_force)
    # Stiffer arms bend less: the tip travels less with E = 130 kPa than 90 kPa.
    travel = {(r.overrides["material.E"], r.overrides["medium.Cy,Cz"]): r.value["tip_travel"] for r in runs.runs}
    assert travel[(130e3, 2.0)] < travel[(90e3, 2.0)]
    with open(tmp_path / "summary.csv") as handle:
        rows = list(csv.DictReader(handle))
    assert len(rows) == 4 and rows[3]["material.E"] == "130000.0"
    saved = load_result(tmp_path / "run_0003" / "result.npz")
    assert np.array_equal(saved.markers, runs.runs[3].result.markers)


def test_sweep_with_output_reads_results_back_from_files(tmp_path):
    spec = paper_spec("bending", t_end=0.3)
    runs = sweep(spec, [{"material.E": 9e4}], client="serial", out=tmp_path)
    assert runs.runs[0].result is None
    assert np.array_equal(runs.result(0).markers, apply(spec, {"material.E": 9e4}).simulate().markers)


def test_bad_overrides_stop_the_sweep_before_any_run():
    with pytest.raises(ParameterError, match="unknown override 'material.X'"):
        sweep(paper_spec("bending"), [{"material.E": 1e5}, {"material.X": 1}], client="serial")
