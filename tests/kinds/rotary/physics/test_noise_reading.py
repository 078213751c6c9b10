"""The window's noise, measured through the public pipeline stages on foreign windows whose sensors
sit behind moving-average filters (``ema.model.noise`` draws AR(1) noise: another shape)."""

import numpy as np
import pytest

from ema.estimate.stats import robust_variance
from ema.kinds.rotary.dataset import simulate_noisy
from ema.kinds.rotary.physics.features import as_read
from ema.kinds.rotary.physics.friction import solve_window
from ema.kinds.rotary.physics.noise_reading import noise_of, second_difference_variances
from ema.kinds.rotary.physics.scenario import scenario_from_window
from ema.model.actuator import THESIS
from ema.model.params import HealthParams
from ema.model.window import window_from_dict
from tests.foreign.windows import draw, filter_widths

RATE = 10_000.0
SENSORS = ("position_deg", "motor_speed_radps", "current_a", "hinge_moment_nm")


def _measured_and_realized(seed: int, family: str, widths: dict[str, int]):
    d = draw(seed, family, filter_samples=widths)
    window = window_from_dict(d.document)
    physics = solve_window(as_read(window.signals, RATE), RATE, drive=THESIS.params)
    at = HealthParams.single(fdj_nm=float(physics.fdj_nm[0]), eta_o=float(physics.eta_o[0]))
    scenario = scenario_from_window(window, drive=THESIS.params, hinge=THESIS.hinge)
    measured = simulate_noisy(scenario, at, window, at, seed=0, clean_last=1).noise  # read against the clean lane
    clean = d.clean_signals()
    return measured, {name: window.signals[name] - clean[name] for name in SENSORS}


@pytest.mark.parametrize("filtered", [False, True])
def test_a_windows_noise_is_read_with_its_std_and_its_low_frequency_density(filtered):
    """A W-sample moving average's noise has the low-frequency density of σ²·W. Read too low, the stds
    would be too narrow: at most 20 % under; read high, they are only wider: the model's own departures
    from the foreign loop count as noise (up to ~1.6x on the current), so up to 70 % over."""
    for seed, family in ((61, "cruise"), (62, "gust"), (63, "doublet"), (64, "steps")):
        widths = filter_widths(seed) if filtered else {}
        measured, realized = _measured_and_realized(seed, family, widths)
        for name in SENSORS:
            sigma, rho = getattr(measured, name), measured.correlation(name, RATE)
            assert sigma == pytest.approx(realized[name].std(), rel=0.2), (seed, name)
            read = sigma * np.sqrt((1 + rho) / (1 - rho))
            true = realized[name].std() * np.sqrt(widths.get(name, 1))
            if name in ("current_a", "hinge_moment_nm"):  # what the estimates feel most
                assert 0.8 < read / true < 1.7, (seed, name, read / true)


def test_white_and_moving_average_noise_are_told_apart_by_their_structure():
    rng = np.random.default_rng(5)
    white = rng.standard_normal(5000)
    assert noise_of(white, RATE, 64) == (pytest.approx(1.0, rel=0.05), 0.0)
    for width in (3, 10, 30):
        averaged = np.convolve(rng.standard_normal(5000 + width - 1), np.ones(width) / np.sqrt(width), mode="valid")
        sigma, tau_s = noise_of(averaged, RATE, 64)
        rho = np.exp(-1 / (tau_s * RATE))
        assert sigma == pytest.approx(1.0, rel=0.1)
        assert (1 + rho) / (1 - rho) == pytest.approx(width, rel=0.25)  # a moving average's T is its width


def test_a_short_windows_mismatch_at_its_sharp_motions_is_not_read_as_correlation():
    """A 0.1 s window's difference from its clean simulation: white noise plus a few ms-wide departures
    where the motion turns sharply (their S grows as L⁴, unlike any noise's). Read over all 16 lags,
    6 of 20 such windows gave T over 1.5 (up to 2.5): simulations that noisy widen the stds for nothing."""
    t = np.arange(1000)
    over = 0
    for seed in range(20):
        rng = np.random.default_rng(seed)
        bumps = zip(rng.uniform(-8, 8, 3), rng.uniform(100, 900, 3), rng.uniform(5, 15, 3), strict=True)
        mismatch = sum(a * np.exp(-0.5 * ((t - centre) / width) ** 2) for a, centre, width in bumps)
        sigma, tau_s = noise_of(rng.standard_normal(1000) + mismatch, RATE, 16)
        assert sigma == pytest.approx(1.0, rel=0.15)
        rho = np.exp(-1 / (tau_s * RATE)) if tau_s > 0 else 0.0
        over += (1 + rho) / (1 - rho) > 1.5
    assert over <= 2


def test_a_difference_from_a_simulation_that_never_levels_off_is_read_white():
    """A smooth mismatch large enough to grow through all 16 lags (S rising as L⁴): against a
    simulation it is the model's, and the noise is read from the first lag; against the signal's own
    smoothing (the hinge moment), a rise through every lag is a long correlation and is kept."""
    t = np.arange(5000)
    for amplitude, period in ((300, 300), (1000, 500)):
        rng = np.random.default_rng(amplitude)
        difference = rng.standard_normal(5000) + amplitude * np.sin(2 * np.pi * t / period)
        assert noise_of(difference, RATE, 16) == (pytest.approx(1.0, rel=0.1), 0.0)
        sigma, tau_s = noise_of(difference, RATE, 16, rising_is_noise=True)
        assert sigma > 3.0 and tau_s > 0.0


def test_the_compiled_second_difference_variances_equal_the_plain_robust_variance():
    """The fast path (compiled, both medians in one pass per lag) against ``robust_variance`` of NumPy's
    second difference: equal to the last bit, on odd and even lengths, with ties (a quantized sensor)."""
    rng = np.random.default_rng(11)
    for trial in range(40):
        n = int(rng.integers(30, 3000))
        x = np.cumsum(rng.standard_t(3, n)) * 0.05 + rng.uniform(0.1, 2.0) * rng.standard_normal(n)
        x = np.round(x, 1) if trial % 4 == 0 else x
        plain = [robust_variance(x[2 * lag :] - 2 * x[lag:-lag] + x[: -2 * lag]) for lag in range(1, 13)]
        assert np.array_equal(second_difference_variances(x, 1, 12), plain)
        assert second_difference_variances(x, 5, 4) == []  # no lags asked: none read
