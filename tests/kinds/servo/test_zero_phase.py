"""The zero-phase low-passes a servo's motion is read through: closed forms of each design, and SciPy's own
designs and filtfilt (the reference MATLAB's agrees with) reproduced on a signal drawn here."""

import numpy as np
import pytest
from scipy import signal

from ema.kinds.servo.zero_phase import _lfilter, butter_lowpass, cheby1_lowpass, filtfilt

ORDERS = (1, 2, 3, 4, 5, 8)
CUTOFFS = (0.01, 0.08, 0.3, 0.7, 0.99)
WELL_CONDITIONED = CUTOFFS[1:-1]  # an 8th order's polynomials at the band's ends lose digits (MATLAB's, SciPy's too)


def _gain(b: np.ndarray, a: np.ndarray, share_of_nyquist: float) -> float:
    z = np.exp(1j * np.pi * share_of_nyquist)
    return abs(np.polyval(b, z) / np.polyval(a, z))


@pytest.mark.parametrize("order", ORDERS)
def test_a_butterworth_passes_dc_whole_and_is_3_db_down_at_its_cutoff(order: int) -> None:
    for cutoff in WELL_CONDITIONED:
        b, a = butter_lowpass(order, cutoff)
        assert _gain(b, a, 0.0) == pytest.approx(1.0, rel=1e-8)
        assert _gain(b, a, cutoff) == pytest.approx(1.0 / np.sqrt(2.0), rel=1e-8)
        assert _gain(b, a, 1.0) == pytest.approx(0.0, abs=1e-8)  # its zeros at the Nyquist rate


@pytest.mark.parametrize("order", ORDERS)
def test_a_chebyshev_starts_at_its_ripples_top_or_bottom_and_ends_the_band_at_the_bottom(order: int) -> None:
    ripple_db = 0.5
    bottom = 10.0 ** (-ripple_db / 20.0)
    for cutoff in WELL_CONDITIONED:
        b, a = cheby1_lowpass(order, ripple_db, cutoff)
        assert _gain(b, a, 0.0) == pytest.approx(bottom if order % 2 == 0 else 1.0, rel=1e-8)
        assert _gain(b, a, cutoff) == pytest.approx(bottom, rel=1e-8)
        band = [_gain(b, a, f) for f in np.linspace(0.0, cutoff, 200)]
        assert bottom - 1e-8 <= min(band) and max(band) <= 1.0 + 1e-8


@pytest.mark.parametrize("order", ORDERS)
def test_the_designs_are_scipys(order: int) -> None:
    for cutoff in CUTOFFS:
        for ours, theirs in (
            (butter_lowpass(order, cutoff), signal.butter(order, cutoff)),
            (cheby1_lowpass(order, 0.05, cutoff), signal.cheby1(order, 0.05, cutoff)),
        ):
            for mine, reference in zip(ours, theirs, strict=True):
                np.testing.assert_allclose(mine, reference, rtol=1e-12, atol=1e-15 * np.max(np.abs(reference)))


def test_filtfilt_is_scipys_and_the_compiled_filter_its_plain_loop() -> None:
    walk = np.cumsum(np.random.default_rng(11).normal(size=6000))
    for b, a in (signal.butter(4, 0.02), signal.cheby1(8, 0.05, 0.08), signal.cheby1(8, 0.05, 0.27)):
        padlen = 3 * (len(a) - 1)
        np.testing.assert_allclose(filtfilt(b, a, walk, padlen), signal.filtfilt(b, a, walk, padlen=padlen), atol=1e-9)
        b1, a1 = b / a[0], a / a[0]
        compiled, plain = np.empty_like(walk), np.empty_like(walk)
        _lfilter(b1, a1, walk, np.linspace(-1.0, 1.0, len(a) - 1), compiled)
        _lfilter.py_func(b1, a1, walk, np.linspace(-1.0, 1.0, len(a) - 1), plain)
        np.testing.assert_array_equal(compiled, plain)


def test_a_constant_comes_out_unchanged_from_its_first_sample() -> None:
    b, a = butter_lowpass(4, 0.05)
    np.testing.assert_allclose(filtfilt(b, a, np.full(500, 3.25), 12), 3.25, rtol=1e-7)


def test_a_cutoff_off_the_band_and_a_pad_past_the_signal_are_refused_by_name() -> None:
    """Callers' errors, not a user's (the servo's reading refuses a log too short to filter first)."""
    with pytest.raises(ValueError, match="cutoff"):
        butter_lowpass(4, 1.0)
    with pytest.raises(ValueError, match="padlen"):
        filtfilt(*butter_lowpass(4, 0.1), np.ones(10), 10)
