import numpy as np

from sim.params import HealthParams
from sim.synthetic import synthetic_window
from sim.window import Window
from training.conditioning import MAX_RATE_HZ, MAX_SAMPLES, averaging_factor, prepare


def test_averaging_keeps_rate_and_samples_bounded():
    assert averaging_factor(5_000, 10_000.0) == 1
    assert averaging_factor(50_000, 100_000.0) == 10
    assert averaging_factor(100_000, 10_000.0) == 10  # a 10 s window is processed at 1 kHz
    for n, rate in ((1_000_000, 100_000.0), (30_000, 12_800.0), (100, 1_000.0)):
        f = averaging_factor(n, rate)
        assert rate / f <= MAX_RATE_HZ and n / f <= MAX_SAMPLES


def test_averaged_samples_are_the_means_of_the_longer_intervals():
    window = synthetic_window(HealthParams.single(), seed=1, duration_s=0.05, sample_rate_hz=40_000.0)
    prepared = prepare(window)
    assert prepared.factor == 4 and prepared.window.sample_rate_hz == 10_000.0
    np.testing.assert_allclose(
        prepared.window.signals["current_a"][:3], window.signals["current_a"][:12].reshape(3, 4).mean(1)
    )


def test_a_command_past_the_end_stops_is_measured_not_refused():
    window = synthetic_window(HealthParams.single(), seed=2, duration_s=0.05)
    signals = dict(window.signals, command_deg=np.where(np.arange(500) < 100, 45.0, 0.0))
    assert prepare(Window(signals)).command_clipped_fraction == 0.2
