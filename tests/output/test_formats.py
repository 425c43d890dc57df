"""The formats' one table: every writer and reader takes the formats from it, so a new
entry is written, read back, chosen on the command line and in a scenario file."""

import json
from types import SimpleNamespace

import numpy as np
import pytest
from scenario_texts import MINIMAL

import rodmol
from rodmol import run_sinks
from rodmol.cli import commands as cli
from rodmol.errors import ParameterError
from rodmol.output.formats import FORMATS, Format, load_result, write_series
from rodmol.scenario.file import ScenarioError, parse_scenario


@pytest.fixture(scope="module")
def result():
    return rodmol.simulate(rodmol.scenarios.get("bending").model(6), 0.03, output_dt=0.01)


@pytest.mark.parametrize("name", list(FORMATS))
def test_every_format_reads_back_what_it_wrote(result, tmp_path, name):
    write_series(result, tmp_path, format=name)
    back = load_result(tmp_path)
    assert (tmp_path / FORMATS[name].result_file).is_file()
    np.testing.assert_array_equal(back.t, result.t)
    np.testing.assert_array_equal(back.positions, result.positions)
    np.testing.assert_array_equal(back.tensions, result.tensions)


def _toy_format(written):
    """A format that writes the tip as JSON: its writer, reader and after-run writer."""

    def write(result, directory, every=None):
        path = directory / "result.tip"
        path.write_text(json.dumps({"t": list(map(float, result.t)), "tip": result.tip.tolist()}))
        written.append(path)
        return path

    def read(path):
        data = json.loads(path.read_text())
        return SimpleNamespace(t=np.array(data["t"]), tip=np.array(data["tip"]))

    def write_run(result, options, directory, stopped):
        return {"result": write(result, directory), "frames": len(result.t)}

    return Format("toy", "the tip as JSON", "result.tip", read, write, write_run=write_run,
                  before_run=lambda directory, options: None)


def test_a_new_entry_is_all_a_new_format_needs(result, tmp_path, monkeypatch, capsys):
    written = []
    monkeypatch.setitem(FORMATS, "toy", _toy_format(written))
    assert write_series(result, tmp_path / "direct", format="toy") == tmp_path / "direct" / "result.tip"
    back = load_result(tmp_path / "direct")
    np.testing.assert_array_equal(back.t, result.t)
    np.testing.assert_array_equal(back.tip, result.tip)
    spec = parse_scenario(MINIMAL + '\n[output]\nformat = "toy"\n')
    assert spec.output.format == "toy"
    code = cli.main(["run", "--example", "bending", "--n-elements", "6", "--t-end", "0.02", "--format", "toy",
                     "--out", str(tmp_path / "cli"), "--quiet"])
    assert code == 0 and written[-1] == tmp_path / "cli" / "result.tip"
    assert len(load_result(tmp_path / "cli").t) == 3


def test_unknown_formats_are_refused_naming_the_tables(result, tmp_path, capsys):
    with pytest.raises(ParameterError, match=r"unknown `format` 'xmdf'; did you mean 'xdmf'\?; use 'xdmf' or 'vtp'"):
        write_series(result, tmp_path, format="xmdf")
    with pytest.raises(ScenarioError, match="format"):
        parse_scenario(MINIMAL + '\n[output]\nformat = "toy"\n')
    with pytest.raises(SystemExit):
        cli.main(["run", "--example", "bending", "--format", "toy"])
    assert "invalid choice: 'toy' (choose from 'xdmf', 'vtp')" in capsys.readouterr().err


def test_simulate_streams_into_the_registered_directory_sink(tmp_path, monkeypatch):
    made = []
    monkeypatch.setattr(run_sinks, "_factory", list(run_sinks._factory))
    original = run_sinks._factory[0]

    def factory(directory, *, resume, overwrite):
        made.append((directory, resume, overwrite))
        return original(directory, resume=resume, overwrite=overwrite)

    run_sinks.register_directory(factory)
    model = rodmol.scenarios.get("bending").model(6)
    streamed = rodmol.simulate(model, 0.02, out=tmp_path / "run", overwrite=True)
    assert made == [(tmp_path / "run", False, True)]
    np.testing.assert_array_equal(streamed.positions, rodmol.simulate(model, 0.02).positions)

