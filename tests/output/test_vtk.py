"""VTK series: written with VTK's XML writer, read back with VTK's own readers."""

import re
import xml.etree.ElementTree as ET

import numpy as np
import pytest

import rodmol
from rodmol.output.formats import write_series
from rodmol.output.writers import SeriesWriter, frame_indices, read_pvd

pv = pytest.importorskip("pyvista")


@pytest.fixture(scope="module")
def result():
    """The paper's arm, coarse, pulled by cable 11 (anchored inside) and 2: a short run."""
    model = rodmol.scenarios.get("fetching").model(10)
    return rodmol.simulate(model, 0.05, output_dt=0.01)


def test_series_round_trip(result, tmp_path):
    pvd = write_series(result, tmp_path, format="vtp")
    assert pvd == tmp_path / "rod.pvd"
    root = ET.parse(pvd).getroot()
    assert root.get("type") == "Collection"
    entries = read_pvd(pvd)
    np.testing.assert_array_equal([t for t, _ in entries], result.t)
    for k, (_, path) in enumerate(entries):
        mesh = pv.read(path)
        assert isinstance(mesh, pv.PolyData) and mesh.n_cells == 1 and mesh.n_lines == 1
        np.testing.assert_allclose(mesh.points, result.positions[k], rtol=0, atol=1e-15)
        np.testing.assert_array_equal(mesh.point_data["radius [m]"], result.radius)
        np.testing.assert_array_equal(mesh.point_data["curvature [1/m]"], result.curvature[k])
        np.testing.assert_array_equal(mesh.point_data["internal moment [N m]"], result.internal_moment[k])
        np.testing.assert_array_equal(mesh.point_data["frame y [-]"], result.rotations[k][:, :, 1])
        assert mesh.field_data["time [s]"][0] == result.t[k]


def test_every_array_name_carries_its_unit(result, tmp_path):
    write_series(result, tmp_path, format="vtp")
    for part in ("rod", "cables", "markers"):
        mesh = pv.read(read_pvd(tmp_path / f"{part}.pvd")[-1][1])
        names = [n for n in (*mesh.point_data.keys(), *mesh.cell_data.keys()) if n != "vtkOriginalIds"]
        assert names, part
        for name in names:
            assert re.fullmatch(r".+ \[[^\]]+\]", name), f"{part}: {name!r} has no [unit]"
    rod = pv.read(read_pvd(tmp_path / "rod.pvd")[0][1])
    expected = {"radius [m]", "s [m]", "linear strain [-]", "curvature [1/m]", "velocity [m/s]",
                "angular velocity [rad/s]", "internal force [N]", "internal moment [N m]",
                "frame x [-]", "frame y [-]", "frame z [-]", "external force [N/m]",
                "external moment [N m/m]"}
    assert expected <= set(rod.point_data.keys())


def test_cables_end_at_their_anchor_at_u_plus_R_p(result, tmp_path):
    write_series(result, tmp_path, format="vtp")
    k = len(result.t) - 1
    cables = pv.read(read_pvd(tmp_path / "cables.pvd")[k][1])
    assert cables.n_cells == len(result.meta["cables"]) == 12
    np.testing.assert_array_equal(cables.cell_data["tension [N]"], result.tensions[k])
    for i, info in enumerate(result.meta["cables"]):
        cell = cables.get_cell(i)
        points, s = cell.points, cables.point_data["s [m]"][cell.point_ids]
        assert s[-1] == pytest.approx(info["anchor"]) and np.all(s <= info["anchor"] + 1e-12)
        p = np.array([0.0, *info["offset"]])
        node = 1  # a node on every cable's path
        np.testing.assert_allclose(points[node], result.positions[k, node] + result.rotations[k, node] @ p,
                                   atol=1e-15)
    markers = pv.read(read_pvd(tmp_path / "markers.pvd")[k][1])
    np.testing.assert_allclose(markers.points, result.markers[k], atol=1e-15)
    assert list(markers.field_data["marker names"]) == [m["name"] for m in result.meta["markers"]]


def test_every_nth_frame_and_the_last(result, tmp_path):
    assert frame_indices(6, 2) == [0, 2, 4, 5] and frame_indices(0, 3) == []
    write_series(result, tmp_path, every=4, format="vtp")
    times = [t for t, _ in read_pvd(tmp_path / "rod.pvd")]
    np.testing.assert_array_equal(times, result.t[frame_indices(len(result.t), 4)])


def test_incremental_writer_lists_only_complete_frames(result, tmp_path):
    writer = SeriesWriter.for_result(result, tmp_path, flush_interval=0.0)
    assert read_pvd(writer.pvd()) == []  # an empty, valid collection from the start
    writer.write(result, 0)
    writer.write(result, 1)
    assert [t for t, _ in read_pvd(writer.pvd())] == list(result.t[:2])
    assert not list(tmp_path.glob("*.part"))
    # A new writer in the same directory keeps the old series unless asked to replace it.
    with pytest.raises(rodmol.ParameterError, match="rod.pvd' exists: .* overwrite=True"):
        SeriesWriter.for_result(result, tmp_path)
    assert [t for t, _ in read_pvd(writer.pvd())] == list(result.t[:2])
    again = SeriesWriter.for_result(result, tmp_path, overwrite=True)
    assert read_pvd(again.pvd()) == [] and not list((tmp_path / "vtk").glob("*.vtp"))


def test_tube_of_radius_is_the_tapered_body(result, tmp_path):
    write_series(result, tmp_path, every=10, format="vtp")
    rod = pv.read(read_pvd(tmp_path / "rod.pvd")[0][1])
    tube = rod.tube(scalars="radius [m]", absolute=True, n_sides=24)
    base = tube.points[np.abs(tube.points[:, 0]) < 1e-9]
    assert np.max(np.linalg.norm(base[:, 1:], axis=1)) == pytest.approx(result.radius[0], rel=1e-6)


@pytest.fixture(scope="module")
def loaded():
    """A rod on a frictionless floor, pushed sideways at its tip and twisted along its length."""
    rod = rodmol.Rod(0.3, 0.01, rodmol.Material(1e5, 0.5, 10.0, 1000.0))
    loads = [rodmol.PointForce(0.3, [(0.0, 0.0, 0.0, 0.0), (0.04, 0.0, 0.0, 0.02)]),
             rodmol.DistributedMoment((0.001, 0.0, 0.0)),
             rodmol.PlaneContact((0.0, -0.05, 0.0), (0.0, 1.0, 0.0), 1e4)]
    return rodmol.simulate(rodmol.Model(rod, 12, loads=loads), 0.04, output_dt=0.01)


def test_external_loads_are_written_as_in_the_result(loaded, tmp_path):
    write_series(loaded, tmp_path, format="vtp")
    entries = read_pvd(tmp_path / "rod.pvd")
    assert len(entries) == len(loaded.t) == 5
    for k, (_, path) in enumerate(entries):
        mesh = pv.read(path)
        np.testing.assert_array_equal(mesh.point_data["external force [N/m]"], loaded.external_force[k])
        np.testing.assert_array_equal(mesh.point_data["external moment [N m/m]"], loaded.external_moment[k])
    last = pv.read(entries[-1][1])
    force, moment = last.point_data["external force [N/m]"], last.point_data["external moment [N m/m]"]
    assert np.all(force[0] == 0.0) and np.all(moment[0] == 0.0)  # the clamp carries none
    # Global frame: away from the floor, the dead moment density is (0.001, 0, 0) exactly.
    free = np.flatnonzero(force[:, 1] == 0.0)[1:]
    assert len(free) >= 3
    np.testing.assert_allclose(moment[free], [[0.001, 0.0, 0.0]] * len(free), rtol=0, atol=1e-15)
    # The tip node carries the point force (0, 0, 0.02) N as a density over the
    # length it stands for (ds/2 in the default, centred scheme); the
    # frictionless floor pushes along +y only.
    assert force[-1, 2] == pytest.approx(0.02 / (loaded.s[1] / 2), rel=1e-12)
    np.testing.assert_allclose(force[:-1, 2], 0.0, rtol=0, atol=1e-14)
    assert np.max(force[:, 1]) > 0.5  # the floor pushes up where the rod rests on it


def test_a_precurved_rod_is_drawn_in_its_rest_shape_at_t0(tmp_path):
    """The view's first frame is the undeformed precurved rod (a quarter circle of
    radius R, tip near (R, R, 0)), with its rest curvature on the nodes."""
    bend = 0.1
    rod = rodmol.Rod(0.5 * np.pi * bend, 0.005, rodmol.Material(E=1e5, nu=0.5, mu=50.0, rho=1000.0),
                     rest_curvature=(0.0, 0.0, 1.0 / bend))
    run = rodmol.simulate(rodmol.Model(rod, 8, gravity=(0.0, 0.0, -9.81)), 0.01, initial="straight",
                          output_dt=0.01)
    mesh = pv.read(read_pvd(write_series(run, tmp_path, format="vtp"))[0][1])
    # the chords ds R(mid) q of an arc of angle phi are long by about phi^2 / 24 (1.6e-3 here)
    np.testing.assert_allclose(mesh.points[-1], [bend, bend, 0.0], atol=3e-3 * bend)
    np.testing.assert_allclose(mesh.point_data["curvature [1/m]"][:, 2], 1.0 / bend, rtol=1e-12)
