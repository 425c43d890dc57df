"""Identification of E, mu and Cy = Cz from synthetic camera data."""

import numpy as np
import pytest
from experiments import TRUTH, pulse_spec, reconstruct

from rodmol.calibrate import apply, identify, synthetic
from rodmol.calibrate.parallel import SERIAL
from rodmol.errors import ParameterError

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


@pytest.mark.slow
def test_the_exact_jacobian_reaches_the_same_optimum_in_fewer_runs():
    """jacobian="exact" (the runs' own sensitivities) against the forward differences, serially:
    the same optimum to a fraction of its uncertainty, with one run per iteration."""
    spec = pulse_spec()
    measured = reconstruct(synthetic.synthesize(spec, TRUTH, noise_px=1.0, seed=3))
    start = apply(spec, {"material.E": 1.3 * 110e3, "medium.Cy,Cz": 1.3 * 2.5})
    bounds = {k: BOUNDS[k] for k in ("material.E", "medium.Cy,Cz")}
    differences = identify(start, measured, bounds, client=SERIAL)
    exact = identify(start, measured, bounds, client=SERIAL, jacobian="exact")
    assert exact.success and differences.success
    print(differences.values, differences.sigma, differences.runs, exact.values, exact.sigma, exact.runs)
    assert np.all(np.abs(exact.value - differences.value) < 0.3 * np.maximum(exact.sigma, differences.sigma))
    np.testing.assert_allclose(exact.sigma, differences.sigma, rtol=0.2)
    assert exact.runs < differences.runs / 3


@pytest.mark.parametrize("options, words", [(dict(jacobian="exactly"), "did you mean 'exact'"),
                                            (dict(jacobian="exact", parameters={"solver.t_end": (0.1, 100.0)}),
                                             "setting of the run")])
def test_a_jacobian_that_cannot_be_is_refused_before_any_run(options, words):
    spec = pulse_spec()
    measured = reconstruct(synthetic.synthesize(spec, TRUTH, noise_px=0.0, seed=3))
    parameters = options.pop("parameters", {"material.E": (30e3, 400e3)})
    with pytest.raises(ParameterError, match=words):
        identify(spec, measured, parameters, client=SERIAL, **options)
