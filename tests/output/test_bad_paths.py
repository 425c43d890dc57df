"""Damaged result files and directories where files go: a rodmol error naming
the file and what is wrong, before any work, never a raw OSError, BadZipFile
or numpy's pickle message."""

import shutil

import numpy as np
import pytest

import rodmol
from rodmol.errors import ParameterError

MATERIAL = rodmol.Material(E=110e3, nu=0.5, mu=300.0, rho=1080.0)
MODEL = rodmol.Model(rodmol.Rod(0.3, (0.012, 0.005), MATERIAL), 4)


@pytest.fixture(scope="module")
def written(tmp_path_factory):
    """A result saved as .npz and streamed as result.h5 with two chunks."""
    folder = tmp_path_factory.mktemp("written")
    result = rodmol.simulate(MODEL, 0.02, output_dt=0.005, initial="straight")
    result.save(folder / "result.npz")
    rodmol.output.stream.RunWriter(folder / "run", chunk_frames=2).write_result(result)
    return folder, result


def copy(source, target):
    shutil.copytree(source, target) if source.is_dir() else shutil.copy(source, target)
    return target


def truncate(path, keep=0.5):
    data = path.read_bytes()
    path.write_bytes(data[:int(len(data) * keep)])


@pytest.mark.parametrize("damage, what", [
    (lambda p: truncate(p), "truncated"),
    (lambda p: p.write_bytes(b"\x93NUMPY" + bytes(100)), "not a file rodmol wrote"),
    (lambda p: p.write_text("t, T\n0, 1\n"), "not a file rodmol wrote"),
    (lambda p: np.savez(p.with_suffix(""), x=np.zeros(3)), "damaged"),  # a zip without our keys
])
def test_damaged_npz(written, tmp_path, damage, what):
    path = copy(written[0] / "result.npz", tmp_path / "result.npz")
    damage(path)
    with pytest.raises(ParameterError, match=rf"cannot read the result file '{path}': it is (?:{what})"):
        rodmol.load_result(path)


@pytest.mark.parametrize("damage, what", [
    (lambda run: truncate(run / "result.h5"), "truncated"),
    (lambda run: (run / "result.h5").write_bytes(b"garbage" * 10), "not a file rodmol wrote"),
    (lambda run: truncate(run / "frames" / "chunk_000000.h5", 0.3), "truncated"),
    (lambda run: (run / "frames" / "chunk_000001.h5").unlink(), "missing"),
])
def test_damaged_run_directory(written, tmp_path, damage, what):
    run = copy(written[0] / "run", tmp_path / "run")
    damage(run)
    with pytest.raises(ParameterError, match=rf"cannot read the result file '{run}/.*': it is {what}"):
        result = rodmol.load_result(run)
        result.positions  # the chunks are read on first access  # noqa: B018


def test_an_undamaged_copy_reads_back(written, tmp_path):
    run = copy(written[0] / "run", tmp_path / "run")
    np.testing.assert_array_equal(rodmol.load_result(run).positions, written[1].positions)


def test_no_result_there(tmp_path):
    with pytest.raises(ParameterError, match="no result.h5 or result.npz"):
        rodmol.load_result(tmp_path)
    with pytest.raises(ParameterError, match="no such result file"):
        rodmol.load_result(tmp_path / "missing.npz")
    with pytest.raises(ParameterError, match="`path` must be a file or directory name, got 5"):
        rodmol.load_result(5)


def test_directories_where_files_go_are_refused_before_work(written, tmp_path):
    result = written[1]
    (tmp_path / "folder").mkdir()
    with pytest.raises(ParameterError, match="`path` = '.*folder' is a directory, where rodmol writes a file"):
        result.save(tmp_path / "folder")
    for name, fmt in (("result.h5", "xdmf"), ("rod.xdmf", "xdmf"), ("result.npz", "vtp"), ("rod.pvd", "vtp")):
        (tmp_path / fmt / name).mkdir(parents=True)
        with pytest.raises(ParameterError, match=f"'{tmp_path / fmt / name}' is a directory"):
            rodmol.write_series(result, tmp_path / fmt, format=fmt)
        (tmp_path / fmt / name).rmdir()
    (tmp_path / "file").write_text("")
    with pytest.raises(ParameterError, match="output directory `directory` = .*a file of that name is in the way"):
        rodmol.write_series(result, tmp_path / "file")
    with pytest.raises(ParameterError, match="output directory `out` = .*a file of that name is in the way"):
        rodmol.simulate(MODEL, 0.01, out=tmp_path / "file")


def test_command_line_on_a_damaged_run(written, tmp_path, capsys):
    from rodmol.cli import commands as cli

    run = copy(written[0] / "run", tmp_path / "run")
    truncate(run / "result.h5")
    assert cli.main(["plot", str(run)]) == cli.EXIT_USAGE
    err = capsys.readouterr().err
    assert "Traceback" not in err and f"cannot read the result file '{run / 'result.h5'}': it is truncated" in err
