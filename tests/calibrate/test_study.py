"""The worsened-model study (Table V) on a synthetic fetching recording."""

from experiments import paper_spec, reconstruct

from rodmol.calibrate import synthetic, worsened_models


def test_worsened_models_order_their_errors_as_the_physics_says(dask_client, tmp_path):
    """The recording comes from the full model (with 1 px of camera noise), so the
    full model fits best; the paper's Table V order follows: the viscosity barely
    matters, the added mass more, and without drag the arm swings far off."""
    spec = paper_spec("fetching")
    measured = reconstruct(synthetic.synthesize(spec, noise_px=1.0, rate=25.0, seed=1))
    study = worsened_models(spec, measured, client=dask_client)
    mean = {name: e.mean_average for name, e in study.errors.items()}
    tip = {name: e.tip_average for name, e in study.errors.items()}
    assert list(mean) == ["full model", "linear elastic", "no added mass", "no drag"]
    assert all(o.success for o in study.outcomes.values())
    assert mean["full model"] < 0.01  # the reconstruction noise only
    assert mean["full model"] < mean["linear elastic"] < mean["no added mass"] < mean["no drag"]
    assert tip["full model"] < tip["linear elastic"] < tip["no added mass"] < tip["no drag"]
    assert mean["no drag"] > 5 * mean["no added mass"]
    assert "| no drag |" in study.table()
    assert study.plot(tmp_path / "table5.png").stat().st_size > 10_000
