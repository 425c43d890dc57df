"""The calibration commands: rodmol study, identify and sweep (in-process, serial)."""

import json

import numpy as np
from experiments import paper_spec

from rodmol.calibrate import MarkerTracks, write_marker_tracks
from rodmol.cli.commands import main


def measured_bending(path, **overrides):
    """Markers of the bending test at N = 10 (2 s), written as a measured track."""
    from rodmol.calibrate import apply

    result = apply(paper_spec("bending", t_end=2.0), overrides).simulate()
    keep = slice(None, None, 4)
    write_marker_tracks(path, MarkerTracks(result.t[keep], result.markers[keep], ("L1", "L2", "L3", "L")))
    return path


def test_sweep_command_writes_a_grid(tmp_path, capsys):
    code = main(["sweep", "--example", "bending", "--n-elements", "10", "--t-end", "0.5", "--serial",
                 "--set", "material.E=90e3,110e3", "--set", "medium.drag=true,false", "--out", str(tmp_path),
                 "--quiet"])
    assert code == 0
    assert sorted(p.name for p in tmp_path.iterdir())[:4] == ["run_0000", "run_0001", "run_0002", "run_0003"]
    assert (tmp_path / "summary.md").read_text().count("\n") == 2 + 4


def test_sweep_command_reports_a_bad_key(tmp_path, capsys):
    runs = tmp_path / "runs.csv"
    runs.write_text('material.E,"medium.Cy,Cz"\n90e3,2\n100e3\n')
    code = main(["sweep", "--example", "bending", "--serial", "--runs", str(runs), "--out", str(tmp_path)])
    assert code == 2 and "runs.csv:3: 1 values for the 2 keys" in capsys.readouterr().err


def test_identify_command_fits_e(tmp_path, capsys):
    measured = measured_bending(tmp_path / "markers.csv", **{"material.E": 95e3})
    code = main(["identify", "--example", "bending", "--n-elements", "10", "--t-end", "2", "--serial",
                 "--measured", str(measured), "--fit", "material.E=50e3:200e3", "--out", str(tmp_path / "fit"),
                 "--quiet"])
    assert code == 0
    fit = json.loads((tmp_path / "fit" / "fit.json").read_text())
    assert fit["parameters"] == ["material.E"] and np.isclose(fit["value"][0], 95e3, rtol=1e-4)
    assert (tmp_path / "fit" / "errors.png").stat().st_size > 10_000


def test_study_command_prints_table_v(tmp_path, capsys):
    measured = measured_bending(tmp_path / "markers.csv")
    code = main(["study", "--example", "bending", "--n-elements", "10", "--t-end", "2", "--serial",
                 "--measured", str(measured), "--out", str(tmp_path / "study")])
    out = capsys.readouterr().out
    assert code == 0 and "| full model | 0.00% | 0.00% |" in out and "| no drag |" in out
    assert (tmp_path / "study" / "errors.png").is_file()
