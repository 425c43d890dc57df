"""From experiment to model: measured data in, stereo reconstruction (the
paper's DLT, section V-C), the paper's error study (eq. 15, Tables IV and V),
parameter identification, sweeps, and the linearisation for control.

Runs go to a dask.distributed cluster (a LocalCluster by default, see
:mod:`~rodmol.calibrate.parallel`). Modules: :mod:`~.measured` (CSV tables),
:mod:`~.dlt` (cameras, triangulation), :mod:`~.variants` (dotted overrides),
:mod:`~.paper_errors`, :mod:`~.study`, :mod:`~.identify`, :mod:`~.sweep`,
:mod:`~.linearize` and :mod:`~.linear_model` (reduced and sampled forms for
model-predictive control), :mod:`~.synthetic` (the project's synthetic experiment).
"""

from .dlt import Camera, calibrate_dlt, reprojection_errors, triangulate
from .identify import Fit, identify
from .linear_model import LinearModel
from .linearize import linearize
from .measured import (
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
from .paper_errors import ErrorTable, paper_errors, plot_errors
from .study import VARIANTS, Study, worsened_models
from .sweep import Sweep, grid, sweep
from .variants import apply, spec_of

__all__ = [
    "VARIANTS", "Camera", "ErrorTable", "Fit", "LinearModel", "MarkerTracks", "PixelTracks", "Study", "Sweep",
    "TensionLog", "apply", "calibrate_dlt", "grid", "identify", "linearize", "paper_errors",
    "plot_errors", "read_control_points", "read_marker_tracks", "read_pixel_tracks",
    "read_tension_log", "reprojection_errors", "spec_of", "sweep", "triangulate",
    "worsened_models", "write_control_points", "write_marker_tracks", "write_pixel_tracks",
    "write_tension_log",
]
