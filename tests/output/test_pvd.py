"""The ``.pvd`` collections of a ``.vtp`` series: written in O(frames) in all, valid XML at
every moment a run can be killed, readable by ParaView's readers (pyvista's here)."""

import os
import xml.etree.ElementTree as ET
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

import rodmol
from rodmol.output import writers
from rodmol.output.writers import SeriesWriter, read_pvd

IO = Path("/proc/self/io")


def bytes_written():
    """The bytes this process has handed to write system calls so far (Linux)."""
    return int(dict(line.split(": ") for line in IO.read_text().splitlines())["wchar"])


def collection_cost(folder, frames, monkeypatch):
    """(bytes written, final size of rod.pvd) of a series of ``frames`` frames listed after each
    one (flush_interval 0), the frame files themselves not written: the collections' own cost."""
    monkeypatch.setattr(writers, "save_vtp", lambda mesh, path: None)
    monkeypatch.setitem(writers.MESHES, "rod", lambda result, k: None)
    run = SimpleNamespace(t=0.01 * np.arange(frames))
    before = bytes_written()
    with SeriesWriter(folder, ("rod",), flush_interval=0.0) as writer:
        for k in range(frames):
            writer.write(run, k)
    return bytes_written() - before, (folder / "rod.pvd").stat().st_size


@pytest.mark.skipif(not IO.exists(), reason="counts the bytes written through /proc/self/io (Linux)")
@pytest.mark.parametrize("frames", [150, 600])
def test_a_long_series_writes_its_collection_in_linear_bytes(frames, tmp_path, monkeypatch):
    """Listing every frame as it is written (the worst case of the half-second flushes) writes
    a bounded multiple of the collection's own size: the entries once, the whole file at each
    doubling of its room (at most four times its size in all), the last rewrite (rewriting the
    whole collection each time wrote frames/2 times its size: O(frames^2))."""
    written, size = collection_cost(tmp_path, frames, monkeypatch)
    assert len(read_pvd(tmp_path / "rod.pvd")) == frames
    assert written < 6 * size + 64 * 1024, (written, size)


def test_the_collection_is_valid_after_every_write_and_no_write_crosses_a_page(tmp_path, monkeypatch):
    """A process is killed between two system calls, and a write into the page cache is not cut
    inside a page: each state the file passes through is a valid collection of complete frames."""
    from rodmol.output import pvd

    monkeypatch.setattr(writers, "save_vtp", lambda mesh, path: Path(path).touch())
    monkeypatch.setitem(writers.MESHES, "rod", lambda result, k: None)
    states, pwrite = [], os.pwrite

    def watched(fd, data, offset):
        assert offset // pvd.PAGE == (offset + len(data) - 1) // pvd.PAGE, (offset, len(data))
        done = pwrite(fd, data, offset)
        states.append(read_pvd(tmp_path / "rod.pvd"))  # parses: valid XML
        return done

    monkeypatch.setattr(os, "pwrite", watched)
    run = SimpleNamespace(t=0.5 * np.arange(700))
    with SeriesWriter(tmp_path, ("rod",), flush_interval=0.0) as writer:
        for k in range(len(run.t)):
            writer.write(run, k)
            if k % 97 == 0:  # flushes of many frames too
                writer.flush_interval = 0.0 if k % 2 else 1e9
    final = read_pvd(tmp_path / "rod.pvd")
    assert [t for t, _ in final] == list(run.t) and len(states) > 50
    for listed in states:  # each a prefix of the series: frames in order, none torn
        assert listed == final[:len(listed)]
    assert ET.parse(tmp_path / "rod.pvd").getroot().find("Collection")[-1].get("file") == "vtk/rod_000699.vtp"


@pytest.fixture(scope="module")
def result():
    return rodmol.simulate(rodmol.paper_arm(6, tensions={11: 0.5}), 0.05, initial="straight", output_dt=0.005)


def test_a_series_cut_short_is_read_by_paraviews_reader(result, tmp_path):
    """Killed after some frames (no close: its room still in the file), the collections list the
    frames written, and pyvista's PVD reader (ParaView's format) reads them."""
    pv = pytest.importorskip("pyvista")
    writer = SeriesWriter.for_result(result, tmp_path, flush_interval=0.0)
    for k in range(7):
        writer.write(result, k)
    assert b"     " in (tmp_path / "rod.pvd").read_bytes()  # the room kept for more frames
    reader = pv.get_reader(str(tmp_path / "rod.pvd"))
    np.testing.assert_array_equal(reader.time_values, result.t[:7])
    reader.set_active_time_value(result.t[6])
    mesh = reader.read()[0]
    np.testing.assert_allclose(mesh.points, result.positions[6], atol=1e-15)
    writer.close()  # the room goes: the file as small as its entries
    assert b"     " not in (tmp_path / "rod.pvd").read_bytes().replace(b"    <DataSet", b"")
    assert len(read_pvd(tmp_path / "rod.pvd")) == 7


def test_a_full_disk_while_adding_leaves_the_entries_before(tmp_path, monkeypatch):
    """A write that fails (a full disk) leaves the collection valid, listing what it listed;
    the entries are added by the next flush that succeeds."""
    import errno

    from rodmol.output.pvd import PAGE, Collection

    collection = Collection(tmp_path / "rod.pvd")
    collection.add(0.0, "vtk/rod_000000.vtp")
    collection.flush()
    pwrite, calls = os.pwrite, []

    def full(fd, data, offset):
        calls.append(offset)
        if len(calls) == 2:  # the first page of entries lands, then the disk is full
            raise OSError(errno.ENOSPC, "No space left on device")
        return pwrite(fd, data, offset)

    monkeypatch.setattr(os, "pwrite", full)
    for k in range(1, 90):  # more than a page of entries, within the room
        collection.add(0.1 * k, f"vtk/rod_{k:06d}.vtp")
    with pytest.raises(OSError, match="No space left"):
        collection.flush()
    assert calls[1] // PAGE > calls[0] // PAGE  # the second page failed (the first blanked again)
    assert [t for t, _ in read_pvd(tmp_path / "rod.pvd")] == [0.0]
    monkeypatch.undo()
    collection.flush()
    assert len(read_pvd(tmp_path / "rod.pvd")) == 90
