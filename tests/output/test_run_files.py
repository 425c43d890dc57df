"""An earlier run is never replaced by accident: no abbreviated options on the
command line, a run in the output directory kept unless --overwrite (or
``overwrite=True``), and a replaced run leaves none of its files (pictures
included) while files that are not rodmol's stay."""

import shutil
from pathlib import Path

import pytest

import rodmol
from rodmol.cli import commands as cli
from rodmol.output import h5result, run_files

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
SMALL = ["run", str(EXAMPLES / "uniform_arm_air.toml"), "--n-elements", "6", "--t-end", "0.05", "--quiet"]


def run_cli(capsys, *args):
    code = cli.main([*map(str, args)])
    captured = capsys.readouterr()
    assert "Traceback" not in captured.err
    return code, captured.err


def listing(directory):
    return sorted(p.relative_to(directory).as_posix() for p in Path(directory).rglob("*") if p.is_file())


@pytest.mark.parametrize("argv, wrong", [
    ([*SMALL, "--n-element", "10"], "--n-element"),
    ([*SMALL, "--overw"], "--overw"),
    (["sweep", str(EXAMPLES / "fetching.toml"), "--se", "solver.rtol=1e-5"], "--se"),
    (["render", "x", "--frame", "3"], "--frame"),
])
def test_abbreviated_options_are_refused(capsys, tmp_path, argv, wrong):
    with pytest.raises(SystemExit) as exited:
        cli.main([*argv, "--out", str(tmp_path)] if argv[0] == "run" else argv)
    assert exited.value.code == 2
    assert f"unrecognized arguments: {wrong}" in capsys.readouterr().err
    assert not list(tmp_path.iterdir())


def test_a_finished_run_is_kept_unless_overwrite(tmp_path, capsys):
    out = tmp_path / "run"
    assert run_cli(capsys, *SMALL, "--out", out)[0] == 0
    before = {name: (out / name).read_bytes() for name in listing(out)}
    code, err = run_cli(capsys, *SMALL[:-3], "--n-elements", "4", "--t-end", "0.05", "--quiet", "--out", out)
    assert code == 2 and f"{str(out)!r} holds a finished run to t = 0.05 s, N = 6" in err and "--overwrite" in err
    assert {name: (out / name).read_bytes() for name in listing(out)} == before
    # The series format's run too.
    assert run_cli(capsys, *SMALL, "--format", "vtp", "--out", tmp_path / "vtp")[0] == 0
    code, err = run_cli(capsys, *SMALL, "--out", tmp_path / "vtp")
    assert code == 2 and "result.npz" in err
    # From Python alike.
    model = rodmol.load_scenario(EXAMPLES / "uniform_arm_air.toml").model.replace(n_elements=6)
    with pytest.raises(rodmol.ParameterError, match="holds a finished run.*overwrite=True"):
        rodmol.simulate(model, 0.05, out=out)
    with pytest.raises(rodmol.ParameterError, match="rtol"):  # bad input: refused before the old run goes
        rodmol.simulate(model, 0.02, out=out, overwrite=True, rtol=-1.0)
    with pytest.raises(rodmol.ParameterError, match="holds a finished run"):  # a writer made by hand too
        rodmol.output.stream.RunWriter(out)
    assert {name: (out / name).read_bytes() for name in listing(out)} == before
    assert rodmol.simulate(model, 0.02, out=out, overwrite=True).success
    with pytest.raises(rodmol.ParameterError, match="either `resume` or `overwrite=True`"):
        rodmol.simulate(model, 0.02, out=out, overwrite=True, resume=True)


def test_an_unfinished_run_suggests_resume_or_overwrite(tmp_path, capsys):
    out = tmp_path / "run"
    assert run_cli(capsys, *SMALL, "--out", out, "--max-wall-time", "1e-9")[0] == 1  # stopped at once
    code, err = run_cli(capsys, *SMALL, "--out", out)
    assert code == 2 and "holds a run stopped at t = 0 s of 0.05 s" in err
    assert "continue it with `--resume`, or replace it with `--overwrite`" in err
    assert run_cli(capsys, *SMALL, "--out", out, "--resume", "--overwrite")[0] == 2


def test_overwrite_leaves_nothing_of_the_old_run_and_keeps_other_files(tmp_path, capsys):
    old, fresh = tmp_path / "old", tmp_path / "fresh"
    # The old run: more chunks, the series format's files, pictures, half-written temporaries.
    assert run_cli(capsys, *SMALL, "--out", old, "--chunk-frames", "1")[0] == 0
    assert run_cli(capsys, *SMALL, "--out", old / "series", "--format", "vtp")[0] == 0
    for name in listing(old / "series"):
        (old / name).parent.mkdir(exist_ok=True)
        (old / "series" / name).rename(old / name)
    for name in (*run_files.RENDERED, *run_files.PLOTTED, ".result.h5.x1.part", "frames/.chunk_000009.h5.y.part"):
        (old / name).write_bytes(b"old")
    shutil.rmtree(old / "series")
    assert len(list((old / "frames").glob("chunk_*.h5"))) == 3 and (old / "vtk").is_dir()
    ours = ["notes.txt", ".result.h5.notes", "frames/mine.h5", "vtk/mine.vtp", "chunk_000000.h5"]
    for name in ours:
        (old / name).write_text("not rodmol's")
    assert run_cli(capsys, *SMALL, "--out", old, "--overwrite")[0] == 0
    assert run_cli(capsys, *SMALL, "--out", fresh)[0] == 0
    assert listing(old) == sorted(listing(fresh) + ours)
    assert all((old / name).read_text() == "not rodmol's" for name in ours)
    # Without files of another's, the run's folders go too.
    run_files.clear(fresh)
    assert listing(fresh) == [] and not (fresh / h5result.FRAMES).exists()


def test_the_run_files_are_what_runs_and_pictures_write(tmp_path, capsys):
    assert run_cli(capsys, *SMALL, "--out", tmp_path / "a")[0] == 0
    assert run_cli(capsys, *SMALL, "--out", tmp_path / "b", "--format", "vtp")[0] == 0
    for folder in ("a", "b"):
        assert sorted(run_files.run_files(tmp_path / folder)) == sorted(
            p for p in (tmp_path / folder).rglob("*") if p.is_file())
