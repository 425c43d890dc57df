"""Identification of E, mu and Cy = Cz from synthetic camera data."""

import numpy as np
from experiments import TRUTH, pulse_spec, reconstruct

from rodmol.calibrate import apply, identify, synthetic

BOUNDS = {"material.E": (30e3, 400e3), "material.mu": (30.0, 3000.0), "medium.Cy,Cz": (0.3, 10.0)}


def test_identification_recovers_e_mu_and_cy_from_camera_data(dask_client):
    """Markers seen by the two synthetic cameras with 1 px of noise, rebuilt by
    DLT and triangulation; the fit starts 30% off and lands within 3%, with
    uncertainties that cover its errors."""
    spec = pulse_spec()
    recording = synthetic.synthesize(spec, TRUTH, noise_px=1.0, seed=3)
    measured = reconstruct(recording)
    start = apply(spec, {"material.E": 1.3 * 110e3, "material.mu": 0.7 * 300.0, "medium.Cy,Cz": 1.3 * 2.5})
    fit = identify(start, measured, BOUNDS, client=dask_client)
    assert fit.success, fit.message
    for name, true in TRUTH.items():
        value, sigma = fit.values[name], fit.sigma[fit.names.index(name)]
        assert abs(value - true) < 0.03 * true, fit.table(TRUTH)
        assert abs(value - true) < 5 * sigma + 0.005 * true, fit.table(TRUTH)
    assert fit.errors_after.mean_average < 0.1 * fit.errors_before.mean_average
    assert fit.residual < 2e-3  # about the reconstruction's noise (1.4 mm rms per pixel)
    assert np.allclose(fit.start, [143e3, 210.0, 3.25])
