import numpy as np
import pytest

from ema.kinds.rotary.simulator.sensor_noise import _correlate, add_seeded_noise, add_sensor_noise
from ema.model.noise import SensorNoise, ar1_mean_variance

RATE = 10_000.0


def test_the_correlating_kernel_equals_the_plain_recursion():
    white = np.random.default_rng(0).standard_normal((3, 50))
    plain = white.copy()
    rho = 0.8
    for row in plain:
        for k in range(1, len(row)):
            row[k] = rho * row[k - 1] + np.sqrt(1 - rho**2) * row[k]
    fast = white.copy()
    _correlate(fast, rho)
    np.testing.assert_allclose(fast, plain, rtol=1e-12)


def test_white_noise_is_drawn_as_before_correlation_existed():
    signals = {"current_a": np.zeros((2, 100)), "command_deg": np.ones((2, 100))}
    noisy = add_sensor_noise(signals, SensorNoise(), np.random.default_rng(1))
    expected = 0.05 * np.random.default_rng(1).standard_normal((2, 100), dtype=np.float32).astype(np.float64)
    np.testing.assert_array_equal(noisy["current_a"], expected)
    np.testing.assert_array_equal(noisy["command_deg"], signals["command_deg"])


def test_correlated_noise_has_its_std_its_lag_one_correlation_and_the_scatter_of_its_means():
    noise = SensorNoise(current_a=0.05, current_a_corr_s=4e-4)  # τ = 4 samples
    rho = noise.correlation("current_a", RATE)
    assert rho == pytest.approx(np.exp(-0.25))
    x = add_sensor_noise({"current_a": np.zeros((200, 2000))}, noise, np.random.default_rng(2), RATE)["current_a"]
    assert x.std() == pytest.approx(0.05, rel=0.02)
    assert np.mean(x[:, 1:] * x[:, :-1]) / x.var() == pytest.approx(rho, abs=0.01)
    means = x[:, :400].reshape(200, 20, 20).mean(axis=2)  # 4000 means of 20 consecutive samples
    assert means.std() == pytest.approx(noise.mean_std("current_a", 20, RATE), rel=0.05)
    assert ar1_mean_variance(0.0, 20) == pytest.approx(1 / 20)


def test_correlated_noise_without_a_rate_is_refused():
    with pytest.raises(ValueError, match="sample rate"):
        add_sensor_noise({"current_a": np.zeros(10)}, SensorNoise(current_a_corr_s=1e-3), np.random.default_rng(0))


@pytest.mark.parametrize("noise", [SensorNoise(), SensorNoise(current_a=0.0, hinge_moment_nm_corr_s=0.002)])
def test_seeded_noise_equals_a_fresh_generator_of_that_seed_every_time(noise):
    rng = np.random.default_rng(3)
    signals = {name: rng.normal(size=(5, 300)) for name in ("position_deg", "current_a", "hinge_moment_nm")}
    want = add_sensor_noise(signals, noise, np.random.default_rng(12), 10_000.0)
    for _ in range(2):  # the second call reads the kept draws: still equal, and they were not scaled in place
        got = add_seeded_noise(signals, noise, 12, 10_000.0)
        for name in signals:
            np.testing.assert_array_equal(got[name], want[name])
    other = add_seeded_noise({k: v[:, :200] for k, v in signals.items()}, noise, 12, 10_000.0)
    assert other["position_deg"].shape == (5, 200)
