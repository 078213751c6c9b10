import numpy as np
import pytest

from ema.estimate.learn.network import (
    LearnConfig,
    initial_layers,
    learn_network,
    mse_and_gradient,
    predict,
    split_indices,
)
from ema.model.checks import InputError


def test_split_is_75_15_10_and_disjoint():
    parts = split_indices(1000, (0.75, 0.15, 0.10), np.random.default_rng(0))
    assert [len(parts[k]) for k in ("train", "val", "test")] == [750, 150, 100]
    assert len(np.unique(np.concatenate(list(parts.values())))) == 1000


def test_learns_a_smooth_map_round_trip():
    rng = np.random.default_rng(1)
    targets = rng.uniform(0, 1, (400, 2))
    basis = rng.normal(size=(2, 60))
    inputs = targets @ basis + 0.3 * np.sin(targets @ basis) + 1e-4 * rng.normal(size=(400, 60))
    result = learn_network(inputs, targets, LearnConfig(hidden=30, components=8))
    assert result.test_mse < 1e-4
    assert result.stop_reason in ("validation", "goal", "max_epochs", "converged")
    np.testing.assert_allclose(predict(result.model, inputs[:5]), np.clip(targets[:5], 0, 1), atol=0.03)


def test_early_stopping_after_12_validation_failures_keeps_the_best_weights():
    rng = np.random.default_rng(2)
    inputs, targets = rng.normal(size=(200, 20)), rng.uniform(0, 1, (200, 2))  # nothing to learn: overfits
    result = learn_network(inputs, targets, LearnConfig(hidden=50, components=None, max_epochs=500))
    assert result.stop_reason == "validation"
    validation = [v for _, v in result.history]
    best_epoch = int(np.argmin(validation))
    assert result.epochs == best_epoch + 1 + 12
    assert result.val_mse == pytest.approx(min(validation))


def test_training_is_seeded():
    rng = np.random.default_rng(3)
    inputs, targets = rng.normal(size=(100, 10)), rng.uniform(0, 1, (100, 2))
    a = learn_network(inputs, targets, LearnConfig(hidden=8, max_epochs=20, seed=5))
    b = learn_network(inputs, targets, LearnConfig(hidden=8, max_epochs=20, seed=5))
    np.testing.assert_array_equal(predict(a.model, inputs), predict(b.model, inputs))


def test_predictions_saturate_to_the_target_range():
    rng = np.random.default_rng(4)
    inputs = rng.normal(size=(100, 5))
    result = learn_network(inputs, rng.uniform(0, 1, (100, 2)), LearnConfig(hidden=4, max_epochs=5))
    out = predict(result.model, 1e3 * inputs)
    assert out.min() >= 0.0 and out.max() <= 1.0


def test_bad_settings_are_named():
    with pytest.raises(InputError, match="hidden_units"):
        LearnConfig(hidden=0)
    with pytest.raises(InputError, match="optimizer"):
        LearnConfig(optimizer="sgd")


def test_the_gradient_is_the_losss_derivative():
    """Back-propagation written out equals central differences of the MSE, weight by weight."""
    rng = np.random.default_rng(5)
    z, y = rng.normal(size=(30, 6)), rng.uniform(0, 1, (30, 2))
    layers = initial_layers(6, 7, y, rng)
    weights = layers.weights + 0.3 * rng.normal(size=layers.weights.size)  # off the start: every part has a slope
    _, gradient = mse_and_gradient(weights, layers, z, y)
    step = 1e-6

    def loss(w: np.ndarray) -> float:
        return mse_and_gradient(w, layers, z, y)[0]

    steps = step * np.eye(weights.size)
    numeric = np.array([(loss(weights + e) - loss(weights - e)) / (2 * step) for e in steps])
    np.testing.assert_allclose(gradient, numeric, rtol=1e-6, atol=1e-9)


def test_the_conjugate_gradient_learns_the_same_map():
    """The thesis trained by a conjugate gradient; SciPy's reaches the same map on a learnable problem."""
    rng = np.random.default_rng(6)
    targets = rng.uniform(0, 1, (300, 2))
    inputs = targets @ rng.normal(size=(2, 40)) + 1e-4 * rng.normal(size=(300, 40))
    result = learn_network(inputs, targets, LearnConfig(hidden=20, components=6, optimizer="cg"))
    assert result.test_mse < 1e-3
