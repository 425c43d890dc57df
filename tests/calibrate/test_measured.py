"""Measured-data tables: round trips, missing samples, line-numbered errors."""

import numpy as np
import pytest

import rodmol
from rodmol import ParameterError
from rodmol.calibrate import (
    MarkerTracks,
    PixelTracks,
    TensionLog,
    read_control_points,
    read_marker_tracks,
    read_pixel_tracks,
    read_tension_log,
    write_control_points,
    write_marker_tracks,
    write_pixel_tracks,
    write_tension_log,
)
from rodmol.calibrate.variants import apply, spec_of


def test_tracks_round_trip_with_missing_samples(tmp_path):
    t = np.arange(5) * 0.01
    xyz = np.random.default_rng(0).normal(size=(5, 2, 3))
    xyz[2, 1] = np.nan
    write_marker_tracks(tmp_path / "m.csv", MarkerTracks(t, xyz, ("L1", "L")))
    back = read_marker_tracks(tmp_path / "m.csv")
    assert back.names == ("L1", "L")
    assert np.allclose(back.t, t) and np.allclose(back.xyz, xyz, equal_nan=True, rtol=1e-9)
    uv = xyz[..., :2] * 100
    write_pixel_tracks(tmp_path / "p.csv", PixelTracks(t, uv, ("L1", "L")))
    assert np.allclose(read_pixel_tracks(tmp_path / "p.csv").uv, uv, equal_nan=True, rtol=1e-9)
    write_control_points(tmp_path / "c.csv", xyz[:, 0], uv[:, 0])
    c_xyz, c_uv = read_control_points(tmp_path / "c.csv")
    assert np.allclose(c_xyz, xyz[:, 0]) and np.allclose(c_uv, uv[:, 0])


def test_tracks_until_keep_the_samples_up_to_the_time_and_refuse_an_empty_cut():
    t = np.arange(5) * 0.5
    xyz = np.arange(30.0).reshape(5, 2, 3)
    cut = MarkerTracks(t, xyz, ("a", "b")).until(1.0)
    assert np.array_equal(cut.t, [0.0, 0.5, 1.0]) and np.array_equal(cut.xyz, xyz[:3])
    assert cut.names == ("a", "b")
    with pytest.raises(ParameterError, match="t_end"):
        MarkerTracks(t + 1.0, xyz, ("a", "b")).until(0.5)


def test_tracks_without_header_get_default_names(tmp_path):
    (tmp_path / "m.csv").write_text("# a comment\n0,1,2,3\n\n0.1,1,2,3.5\n")
    tracks = read_marker_tracks(tmp_path / "m.csv")
    assert tracks.names == ("marker 1",) and tracks.xyz[1, 0, 2] == 3.5


@pytest.mark.parametrize("text, message", [
    ("t,a.x,a.y,a.z\n0,1,2,3\n0.1,1,2\n", r"m.csv:3: expected 4 columns"),
    ("t,a.x,a.y,a.z\n0,1,2,3\n0.1,1,x,3\n", r"m.csv:3: not a number 'x'"),
    ("t,a.x,a.y,a.z\n0,1,2,3\n0,1,2,3\n", r"m.csv:3: time 0.0 s does not increase"),
    ("t,a.x,a.y,a.z\n0,1,2,3\n,1,2,3\n", r"m.csv:3: missing time"),
    ("t,a.x,a.y\n0,1,2\n", r"m.csv:2: expected 3 columns"),
    ("t,a.x,a.y,a.z\n", r"no marker position rows"),
])
def test_bad_marker_files_name_the_line(tmp_path, text, message):
    (tmp_path / "m.csv").write_text(text)
    with pytest.raises(ParameterError, match=message):
        read_marker_tracks(tmp_path / "m.csv")


def test_tension_log_reads_named_columns_and_refuses_gaps_and_negatives(tmp_path):
    path = tmp_path / "log.csv"
    path.write_text("t, cable 11, cable 2\n0, 0, 0\n0.5, 2.0, 1.0\n1.0, 2.0, -0.01\n")
    with pytest.raises(ParameterError, match=r"log.csv:4: negative tension"):
        read_tension_log(path)
    log = read_tension_log(path, clip_negative=True)
    assert log.names == ("cable 11", "cable 2") and log.values[2, 1] == 0.0
    path.write_text("t, cable 11\n0, 0\n0.5,\n")
    with pytest.raises(ParameterError, match=r"log.csv:3: missing tension"):
        read_tension_log(path)


def test_tension_log_drives_the_paper_arm(tmp_path):
    """A log written and read back drives cables 11 and 2 exactly as its knots say."""
    t = np.linspace(0.0, 1.0, 11)
    log = TensionLog(t, np.column_stack([2.0 * t, 1.0 + 0.0 * t]), ("cable 11", "2"))
    write_tension_log(tmp_path / "log.csv", log)
    spec = apply(spec_of(rodmol.paper_arm(10), 1.0), read_tension_log(tmp_path / "log.csv").overrides())
    tensions = spec.model.tensions(0.55)
    assert tensions[10] == pytest.approx(1.1) and tensions[1] == pytest.approx(1.0)
    assert np.count_nonzero(tensions) == 2
