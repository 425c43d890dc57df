"""The errors of eq. (15) over time, their averages (Table IV) and the plots."""

import numpy as np
import pytest
from experiments import paper_spec

from rodmol.calibrate import MarkerTracks, paper_errors, plot_errors, write_marker_tracks
from rodmol.calibrate.paper_errors import table

L = 0.418


@pytest.fixture(scope="module")
def bending():
    return paper_spec("bending").simulate()


def shifted(result, times):
    """Measured markers: the run's, the tip moved by 1 cm along x, the others by 2 cm along y."""
    flat = result.markers.reshape(len(result.t), -1)
    xyz = np.stack([np.interp(times, result.t, c) for c in flat.T], axis=1).reshape(len(times), 4, 3)
    xyz[:, 3, 0] += 0.01
    xyz[:, :3, 1] += 0.02
    return xyz


def test_known_shifts_give_eq15_and_the_actuated_phase(bending, tmp_path):
    times = np.arange(0.0, 6.0 + 1e-9, 0.04)
    xyz = shifted(bending, times)
    xyz[10, 2] = np.nan  # an occluded marker: no error at that sample
    path = tmp_path / "measured.csv"
    write_marker_tracks(path, MarkerTracks(times, xyz, ("L1", "L2", "L3", "L")))
    errors = paper_errors(bending, path, name="bending")
    finite = np.isfinite(errors.mean)
    assert list(np.flatnonzero(~finite)) == [10]
    assert np.allclose(errors.tip[finite], 0.01 / L, rtol=1e-6)
    assert np.allclose(errors.mean[finite], (0.01 + 3 * 0.02) / (4 * L), rtol=1e-6)
    assert errors.mean_average == pytest.approx((0.01 + 3 * 0.02) / (4 * L), rel=1e-6)
    # Cable 11 pulls above 5% of 2 N from t = 0.025 s to the end of its release at 4.475 s.
    assert errors.t[errors.actuated].min() == pytest.approx(0.04)
    assert errors.t[errors.actuated].max() == pytest.approx(4.44)
    assert "| bending | 4.19% | 2.39% |" in table([errors])
    png = plot_errors([errors], tmp_path / "errors.png", "bending")
    assert png.stat().st_size > 10_000


def test_actuated_phase_can_be_given(bending):
    times = np.arange(0.0, 6.0 + 1e-9, 0.04)
    errors = paper_errors(bending, shifted(bending, times), times=times, actuated=(1.0, 2.0))
    assert np.count_nonzero(errors.actuated) == 26
    assert errors.actuated_tip_average == pytest.approx(0.01 / L, rel=1e-6)


def test_samples_after_a_short_run_have_no_error(bending):
    times = np.arange(0.0, 8.0 + 1e-9, 0.5)  # beyond the 6 s run
    xyz = np.concatenate([shifted(bending, times[times <= 6.0]), np.zeros((4, 4, 3))])
    errors = paper_errors(bending, xyz, times=times)
    assert np.all(np.isnan(errors.tip[times > 6.0])) and np.all(np.isfinite(errors.tip[times <= 6.0]))
