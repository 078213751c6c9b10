"""The current's lag behind the speed, read on foreign windows whose sensors are filtered here (the
filter acts on the signal and its noise, as a real one does: tests/foreign filters only the noise)."""

import numpy as np
import pytest

from ema.kinds.rotary.prepare.alignment import Lags, aligned
from ema.model.actuator import THESIS
from ema.model.window import window_from_dict
from tests.foreign.physics import Effects, Flight
from tests.foreign.windows import draw, noisy

FAMILIES = ("thesis", "cruise", "gust", "doublet", "steps")
RATE = 10_000.0


def moving_average(values: np.ndarray, width: int) -> np.ndarray:
    """Causal: each sample the mean of itself and the width − 1 before (delay (width − 1) / 2)."""
    padded = np.concatenate([np.full(width - 1, values[0]), values])
    return np.convolve(padded, np.ones(width) / width, mode="valid")


def first_order(values: np.ndarray, tau_samples: float) -> np.ndarray:
    """y[k] = a·y[k−1] + (1 − a)·x[k]: an RC low-pass, low-frequency delay a / (1 − a) samples."""
    a, out, state = np.exp(-1.0 / tau_samples), np.empty_like(values), values[0]
    for k, x in enumerate(values):
        state = a * state + (1.0 - a) * x
        out[k] = state
    return out


def _window(seed: int, filters: dict):
    drawn = draw(seed, FAMILIES[seed % 5], noise_level=0)
    signals = noisy(drawn.clean_signals(), np.random.default_rng(seed), 1.0)
    for name, apply in filters.items():
        signals[name] = apply(signals[name])
    return window_from_dict({**drawn.document, "signals": {k: v.tolist() for k, v in signals.items()}})


@pytest.mark.parametrize("seed", range(5))
def test_a_filtered_current_or_speed_is_read_late_by_its_filters_delay(seed):
    width = 2 + seed  # 0.5–2.5 samples of delay
    _, lags = aligned(_window(seed, {"current_a": lambda x: moving_average(x, width)}), drive=THESIS.params)
    assert lags.current_s * RATE == pytest.approx((width - 1) / 2, abs=0.1)
    _, lags = aligned(_window(seed, {"motor_speed_radps": lambda x: moving_average(x, width)}), drive=THESIS.params)
    assert lags.current_s * RATE == pytest.approx(-(width - 1) / 2, abs=0.1)
    tau, a = 1.0 + seed, np.exp(-1.0 / (1.0 + seed))
    _, lags = aligned(_window(seed, {"current_a": lambda x: first_order(x, tau)}), drive=THESIS.params)
    # an RC filter delays fast content less than slow; Eq. 5.1 reads it at the accelerations
    assert lags.current_s * RATE == pytest.approx(a / (1 - a), rel=0.1)


def test_a_filtered_hinge_moment_is_read_late_by_about_its_filters_delay():
    """The filter's delay read from its noise's correlation: 0.70–1.15 of it on 20 foreign windows, median
    0.91; that it delays the moment too, from the deflection and the equation error
    (``ema.kinds.rotary.prepare.hinge_lag``)."""
    read, weights = [], []
    for seed in range(5):
        width = 10 + 7 * seed  # 0.45–1.8 ms late
        _, lags = aligned(
            _window(seed, {"hinge_moment_nm": lambda x, w=width: moving_average(x, w)}), drive=THESIS.params
        )
        read.append(lags.hinge_filter_s * RATE / ((width - 1) / 2))
        weights.append(lags.hinge_weight)
        assert 0.0 < lags.hinge_s <= 1.3 * lags.hinge_filter_s or lags.hinge_weight < 0.9
    assert all(0.65 < r < 1.25 for r in read), read
    assert sum(w > 0.9 for w in weights) >= 4, weights  # the noise alone behind a filter: 0.31 on 24


def test_noise_correlated_after_an_unfiltered_moment_is_mostly_not_taken_for_its_delay():
    """tests/foreign's ``filter_samples``: the noise behind a 10–40 sample filter, the moment not. Its
    correlation reads as a filter's delay; the deflection and the equation error weigh it down, and what
    weight is left goes into the stds with the spread of the lags it is left on."""
    weights = []
    for seed in range(12):
        drawn = draw(seed, FAMILIES[seed % 5], filter_samples={"hinge_moment_nm": 10 + 3 * seed})
        _, lags = aligned(window_from_dict(drawn.document), drive=THESIS.params)
        if lags.hinge_filter_s:
            weights.append(lags.hinge_weight)
            if 0.05 < lags.hinge_weight < 0.95:
                assert lags.spread["FDJ"] > 0.0
    assert len(weights) >= 8 and np.mean(weights) < 0.4 and max(weights) < 0.9, weights  # filtered: 0.89 on 24


def test_unfiltered_sensors_are_left_as_logged():
    for seed in range(5, 15):
        window = _window(seed, {})
        out, lags = aligned(window, drive=THESIS.params)
        assert lags == Lags() and out is window, seed


def test_the_hinge_lags_read_uncertainty_is_carried_as_a_spread_only_where_one_is_read():
    """Behind a 30-sample filter FDJ moves with the lag; its ±15 % band goes into the stds."""
    _, lags = aligned(_window(3, {"hinge_moment_nm": lambda x: moving_average(x, 30)}), drive=THESIS.params)
    assert lags.hinge_s > 0 and 0.0 < lags.spread["FDJ"] < 2e-3 and lags.spread["eta_O"] >= 0.0
    assert aligned(_window(3, {}), drive=THESIS.params)[1] == Lags()


@pytest.mark.parametrize(
    ("seed", "effects"),
    [
        (0, Effects(current_sensor_gain=1.06)),
        (1, Effects(current_sensor_gain=0.94)),
        (2, Effects(current_sensor_gain=1.10)),
        (0, Effects(inertia_factor=0.8)),
        (1, Effects(inertia_factor=1.2)),
    ],
)
def test_a_drive_constant_off_the_documents_is_not_read_as_a_lag(seed, effects):
    """After a step the current decays while the shaft accelerates: a gain's trace γ·k_T·I and an inertia's
    ΔJ·dω/dt then look like a shifted current (a 6 % gain was read 5 samples late, a rotor 20 % light 9 samples
    early); each shift is fitted with both free, and no lag is left."""
    drawn = draw(seed, "stops", effects=effects, duration_s=1.5, flight=Flight(airspeed_mps=100.0, altitude_m=5000.0))
    assert aligned(window_from_dict(drawn.document), drive=THESIS.params)[1].current_s == 0.0
