import numpy as np
import pytest

from ema.estimate.assess.blend import best_blend


def test_blend_prefers_the_better_estimator_and_never_loses_to_it():
    rng = np.random.default_rng(0)
    truth = rng.uniform(0, 1, 200)
    good, poor = truth + 0.01 * rng.normal(size=200), truth + 0.05 * rng.normal(size=200)
    blend = best_blend(truth, good, poor)
    assert blend.weight_network > 0.9
    assert blend.rms_error <= blend.rms_error_network + 1e-12
    assert best_blend(truth, poor, good).weight_network < 0.1


def test_independent_equal_errors_blend_half_and_half():
    rng = np.random.default_rng(1)
    truth = np.zeros(20_000)
    blend = best_blend(truth, rng.normal(size=20_000), rng.normal(size=20_000))
    assert blend.weight_network == pytest.approx(0.5, abs=0.02)
    assert blend.rms_error == pytest.approx(np.sqrt(0.5), rel=0.03)
