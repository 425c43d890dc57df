"""A system's run directory: each rod's files as a single rod's, system.h5, bodies.xdmf."""

import shutil

import numpy as np
import pytest

import rodmol
from rodmol.bodies import mesh_properties
from rodmol.errors import ParameterError
from rodmol.output.system_files import body_surface
from rodmol.output.system_stream import SystemRunWriter


@pytest.fixture(scope="module")
def written(tmp_path_factory, two_arms):
    out = tmp_path_factory.mktemp("system")
    return rodmol.simulate(two_arms(), 0.06, output_dt=0.02, out=out), out


def test_the_directory_reads_back_as_the_run(written):
    result, out = written
    back = rodmol.load_result(out)
    assert isinstance(back, rodmol.system_result.SystemResult) and back.names == result.names
    assert back.success and np.array_equal(back.t, result.t) and np.array_equal(back.states, result.states)
    for field in ("position", "quaternion", "velocity", "angular_velocity", "rotation"):
        assert np.array_equal(getattr(back["head"], field), getattr(result["head"], field)), field
    for name in result.rods:  # each rod's own run directory (a name unfit for a file gets a key)
        assert np.allclose(back[name].positions, result[name].positions, rtol=0, atol=1e-12)
        assert np.array_equal(back[name].tensions, result[name].tensions)
    assert (out / "right" / "rod.xdmf").is_file() and (out / "rod_1" / "rod.xdmf").is_file()
    with pytest.raises(ParameterError, match="needs the System"):
        back.momentum()


def test_the_bodies_view_draws_the_body_at_its_pose(tmp_path, two_arms):
    import re

    import h5py

    result = rodmol.simulate(two_arms(), 0.06, output_dt=0.01, out=SystemRunWriter(tmp_path, chunk_frames=2))
    view = (tmp_path / "bodies.xdmf").read_text()
    fragments = re.findall(r'href="([^"]+)"', view)
    assert fragments == [f"frames/chunk_{k:06d}.xmf" for k in range(3)]  # frames 0-2, 3-4, 5-6
    grids = sum((tmp_path / f).read_text().count('<Grid Name="head" GridType="Uniform">') for f in fragments)
    assert grids == len(result.t)
    points, triangles = body_surface(result.assembly.bodies["head"].body)
    placed = []
    for fragment in fragments:
        with h5py.File(tmp_path / fragment.replace(".xmf", ".h5")) as handle:
            placed.append(handle["view/head_points"][()])
            assert np.array_equal(handle["view/head_triangles"][()], triangles)
    head = result["head"]
    expected = head.position[:, None, :] + np.einsum("nij,pj->npi", head.rotation, points)
    assert np.allclose(np.concatenate(placed), expected, atol=1e-7)  # single precision


def test_system_h5_is_an_index_of_chunk_files_written_once(tmp_path, two_arms):
    """system.h5 is an index (times and chunk names), not the frames: each chunk's states and
    bodies go to a chunk file written once; the run's SystemResult and load_result agree."""
    import h5py

    result = rodmol.simulate(two_arms(), 0.06, output_dt=0.01, out=SystemRunWriter(tmp_path, chunk_frames=2))
    with h5py.File(tmp_path / "system.h5") as index:
        assert "states" not in index and list(index["chunk_frames"][()]) == [3, 2, 2]
        assert np.array_equal(index["t"][()], result.t)
    sizes = [(tmp_path / "frames" / f"chunk_{k:06d}.h5").stat().st_size for k in (1, 2)]
    assert sizes[0] == sizes[1]  # the second and third chunks: as many frames, as many bytes
    back = rodmol.load_result(tmp_path)
    assert np.array_equal(back.states, result.states)
    assert np.array_equal(back["head"].quaternion, result["head"].quaternion)


def _last_chunk(run, rod):
    return sorted((run / rod / "frames").glob("chunk_*.h5"))[-1]


@pytest.mark.parametrize("damage, words", [
    (lambda run: shutil.rmtree(run / "right"), "the rod 'right' of the system's run '{run}': its result file "
                                                "'{run}/right/result.h5' is missing"),
    (lambda run: (run / "rod_1" / "result.h5").write_bytes(b"garbage" * 10),
     "the rod 'left arm' of the system's run '{run}': cannot read the result file '{run}/rod_1/result.h5': "
     "it is not a file rodmol wrote"),
    (lambda run: _last_chunk(run, "right").unlink(), "the rod 'right' of the system's run '{run}': cannot "
                                                     "read the result file '{run}/right/frames/chunk_"),
])
def test_a_rods_missing_or_damaged_files_are_named_when_the_system_is_loaded(written, tmp_path, damage, words):
    run = shutil.copytree(written[1], tmp_path / "run")
    damage(run)
    with pytest.raises(ParameterError) as caught:
        rodmol.load_result(run)  # before: loaded, then a raw FileNotFoundError on first access to the rod
    assert words.format(run=run) in str(caught.value)


def test_a_body_without_mesh_is_drawn_as_the_ellipsoid_of_its_mass_and_inertia():
    body = rodmol.RigidBody(2.0, np.diag([0.01, 0.02, 0.025]), centre_of_mass=(0.1, -0.2, 0.3))
    points, triangles = body_surface(body)
    volume, centre, inertia = mesh_properties(points, triangles)  # of the drawn, closed surface
    assert np.allclose(centre, body.centre_of_mass, atol=1e-12)
    assert np.allclose(body.mass / volume * inertia, body.inertia, rtol=0.02)  # a polyhedron, 16 x 32
    sphere = rodmol.RigidBody(2.0, (0.02, 0.02, 0.02))
    assert np.allclose(np.linalg.norm(body_surface(sphere)[0], axis=1), np.sqrt(0.02 / (0.4 * 2.0)))


def test_a_meshed_body_is_drawn_as_the_surface_its_mass_came_from(tmp_path):
    import meshio

    corners = np.array([[x, y, z] for x in (0, 0.3) for y in (0, 0.2) for z in (0, 0.1)], dtype=float)
    inward = np.array([[0, 1, 3, 2], [4, 6, 7, 5], [0, 4, 5, 1], [2, 3, 7, 6], [0, 2, 6, 4], [1, 5, 7, 3]])[:, ::-1]
    meshio.write(tmp_path / "box.obj", meshio.Mesh(corners, [("quad", inward)]))  # quads, every one facing in
    body = rodmol.RigidBody.from_mesh(tmp_path / "box.obj", 500.0)
    points, triangles = body_surface(body)  # before: no triangles to draw (and no body: "has no triangles")
    a, b, c = (points[triangles[:, i]] for i in range(3))
    assert np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6.0 == pytest.approx(body.volume, rel=1e-12)  # outward
    assert body.mass == pytest.approx(500.0 * 0.006, rel=1e-12)


def test_an_earlier_run_is_kept_and_a_finished_one_is_not_resumed(written, two_arms):
    result, out = written
    with pytest.raises(ParameterError, match="overwrite"):
        rodmol.simulate(two_arms(), 0.02, output_dt=0.02, out=out)
    with pytest.raises(ParameterError, match="finished"):
        rodmol.simulate(two_arms(), 0.06, output_dt=0.02, out=out, resume=True)
    assert np.array_equal(rodmol.load_result(out).t, result.t)  # untouched


def test_plot_draws_every_part(written, tmp_path):
    from rodmol.output.pictures import plot

    result, _ = written
    paths = plot(result, tmp_path)
    assert len(paths) == 3 and all(p.stat().st_size > 10_000 for p in paths)


def test_render_draws_every_rod_and_body(written, tmp_path):
    pytest.importorskip("pyvista")
    from PIL import Image

    from rodmol.output.pictures import render

    _, out = written
    (png,) = render(rodmol.load_result(out), tmp_path, size=(320, 240), frames=0)
    pixels = np.asarray(Image.open(png).convert("RGB"), dtype=float)
    body = np.all(np.abs(pixels - (0.8 * 255, 0.55 * 255, 0.35 * 255)) < 60, axis=-1).mean()  # the head's colour
    drawn = np.any(np.abs(pixels - pixels[0, 0]) > 30, axis=-1).mean()
    assert body > 0.002 and drawn > body + 0.01  # the head, and the rods besides


def test_every_part_gets_its_own_file_name_and_none_is_the_runs_own():
    from rodmol.output.system_files import SYSTEM, _keys

    for names in (["rod_1", "a b"], ["system.h5", "bodies.xdmf", "arm"], ["rod_0_", "x/y", "rod_0"]):
        keys = _keys(names, "rod")
        assert len(set(keys.values())) == len(names) and not set(keys.values()) & set(SYSTEM), keys
        assert all(keys[n] == n for n in names if n.isidentifier() and n not in SYSTEM)


def test_a_result_read_back_is_written_again_as_it_was(written, tmp_path):
    """write_series of a SystemResult without its System (read from files): the same frames, the
    bodies drawn from their stored surfaces, the views showing every 3rd frame and the last."""
    result, out = written
    rodmol.write_series(rodmol.load_result(out), tmp_path, every=3)
    again = rodmol.load_result(tmp_path)
    assert again.success and np.array_equal(again.states, result.states)
    for field in ("position", "quaternion", "velocity", "angular_velocity"):
        assert np.array_equal(getattr(again["head"], field), getattr(result["head"], field)), field
    assert np.array_equal(again["head"].surface[1], body_surface(result.assembly.bodies["head"].body)[1])
    grids = (tmp_path / "frames" / "chunk_000000.xmf").read_text().count('<Grid Name="head" GridType="Uniform">')
    assert grids == 2  # frames 0 and 3 of 4
    assert np.array_equal(again["right"].positions, rodmol.load_result(out)["right"].positions)
