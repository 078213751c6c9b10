from dataclasses import replace

import numpy as np
import pytest

from ema.kinds.rotary.prepare.alignment import Lags
from ema.kinds.rotary.prepare.conditioning import (
    GLITCH_ACTIVITY,
    MAX_RATE_HZ,
    RESAMPLED_MAX_SAMPLES,
    averaging_factor,
    prepare,
    widened,
)
from ema.kinds.rotary.prepare.departures.viscosity import Viscosity
from ema.kinds.rotary.prepare.departures.zero_offset import ZeroOffset
from ema.kinds.rotary.prepare.step_lag import StepLag
from ema.kinds.rotary.synthetic import synthetic_window
from ema.model.actuator import THESIS
from ema.model.params import HealthParams
from ema.model.window import Window, window_from_dict
from tests.foreign.windows import NOISE, draw, worn


def test_averaging_keeps_rate_and_samples_bounded():
    assert averaging_factor(5_000, 10_000.0) == 1
    assert averaging_factor(50_000, 100_000.0) == 10
    assert averaging_factor(100_000, 10_000.0) == 2  # a 10 s window is processed at 5 kHz
    assert averaging_factor(1_000_000, 100_000.0) == 20  # ... however fast it was logged
    for n, rate in ((1_000_000, 100_000.0), (30_000, 12_800.0), (100, 1_000.0)):
        f = averaging_factor(n, rate)
        assert rate / f <= MAX_RATE_HZ and n / f <= RESAMPLED_MAX_SAMPLES


def test_averaged_samples_are_the_means_of_the_longer_intervals():
    window = synthetic_window(HealthParams.single(), seed=1, duration_s=0.05, sample_rate_hz=40_000.0)
    prepared = prepare(window, actuator=THESIS)
    assert prepared.factor == 4 and prepared.window.sample_rate_hz == 10_000.0
    np.testing.assert_allclose(
        prepared.window.signals["current_a"][:3], window.signals["current_a"][:12].reshape(3, 4).mean(1)
    )


def test_a_command_past_the_end_stops_is_measured_not_refused():
    window = synthetic_window(HealthParams.single(), seed=2, duration_s=0.05)
    signals = dict(window.signals, command_deg=np.where(np.arange(500) < 100, 45.0, 0.0))
    assert prepare(Window(signals), actuator=THESIS).command_clipped_fraction == 0.2


FAMILIES = ("thesis", "cruise", "gust", "doublet", "steps")


def _foreign(seed: int, rate: float) -> Window:
    return window_from_dict(draw(seed, FAMILIES[seed % 5], sample_rate_hz=rate, duration_s=0.2).document)


@pytest.mark.parametrize("rate", [1_000.0, 10_000.0, 100_000.0])
def test_no_sample_of_a_foreign_window_is_taken_for_a_glitch(rate):
    """A 1 kHz log's fastest turns reach 36 noise stds from sample to sample: legitimate, and kept."""
    for seed in range(10):
        window = _foreign(seed, rate)
        assert prepare(window, actuator=THESIS).glitches == {}, seed


@pytest.mark.parametrize(
    ("drawn", "label"),
    [
        (lambda: worn(90009, family="steps", sample_rate_hz=1_000.0), "worn, steps"),
        (lambda: worn(90029, family="steps", sample_rate_hz=1_000.0), "worn, steps"),
        (lambda: draw(90002, "gust", sample_rate_hz=1_000.0), "gust"),
        (lambda: draw(90008, "doublet", sample_rate_hz=2_000.0), "doublet"),
    ],
)
def test_a_current_pulse_at_a_reversal_is_no_glitch_at_a_low_log_rate(drawn, label):
    """At 1–2 kHz the current's kick as the motion reverses lasts 2–3 samples, 300 noise stds tall,
    between flanks that agree: these windows' pulses were taken for glitches before the rule said
    a glitch's flanks are quiet and a burst lasts at most 0.3 ms."""
    assert prepare(window_from_dict(drawn().document), actuator=THESIS).glitches == {}, label


def test_glitches_are_found_and_replaced_by_the_line_between_their_flanks():
    """Spikes of 50–1000 noise stds (an EMI burst, a bit error; two may fall side by side), drawn here,
    on foreign windows. One a few times the steps of a fast slew beside it may stay: it is the motion's
    size there, not the noise's."""
    found = planted = 0
    for seed in range(10):
        window, rng = _foreign(seed, 10_000.0), np.random.default_rng(seed)
        signals = dict(window.signals)
        for name, sigma in NOISE.items():
            at = rng.choice(np.arange(5, window.n_samples - 5), size=3, replace=False)
            signals[name] = signals[name].copy()
            signals[name][at] += rng.choice([-1, 1], 3) * rng.uniform(50, 1000, 3) * sigma
            planted += 3
        prepared = prepare(replace(window, signals=signals), actuator=THESIS)
        found += sum(prepared.glitches.values())
        for name, sigma in NOISE.items():  # repaired to within the noise, or a few local steps, of the log
            left = np.abs(prepared.window.signals[name] - window.signals[name])
            steps = np.abs(np.diff(window.signals[name]))
            local = np.array([np.median(steps[max(0, k - 10) : k + 10]) for k in range(len(left))])
            assert np.all(left < np.maximum(5 * sigma, 2 * GLITCH_ACTIVITY * local)), name
    assert found >= 0.95 * planted


def test_what_conditioning_could_not_settle_widens_the_stds_in_quadrature():
    prepared = prepare(synthetic_window(HealthParams.single(), seed=1), actuator=THESIS)
    departures = replace(
        prepared.departures, offset=ZeroOffset(spread={"FDJ": 3e-4}), viscosity=Viscosity(spread={"FDJ": 0.0})
    )
    lags, step = Lags(spread={"FDJ": 12e-4, "eta_O": 0.0}), StepLag(spread={"eta_O": 0.0075})
    prepared = replace(prepared, lags=lags, departures=departures, step=step)
    assert widened({"FDJ": 4e-4, "eta_O": 0.01}, prepared) == pytest.approx({"FDJ": 13e-4, "eta_O": 0.0125})
