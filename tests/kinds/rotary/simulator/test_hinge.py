import numpy as np
import pytest

from ema.kinds.rotary.simulator.hinge import denoised_hinge_nm, local_line
from ema.model.checks import InputError

RATE_HZ = 10_000.0


def _plain_local_line(values: np.ndarray, width: int) -> np.ndarray:
    """The same by its definition: a line fitted to the ``width`` samples nearest each sample."""
    n, half = len(values), width // 2
    out = np.empty(n)
    for i in range(n):
        first = min(max(i - half, 0), n - width)
        t = np.arange(first, first + width)
        out[i] = np.polyval(np.polyfit(t, values[first : first + width], 1), i)
    return out


def test_the_local_line_equals_its_definition_and_keeps_a_line():
    rng = np.random.default_rng(4)
    values = rng.normal(size=257)
    np.testing.assert_allclose(local_line(values, 41), _plain_local_line(values, 41), atol=1e-10)
    np.testing.assert_allclose(local_line(values[:40], 41), _plain_local_line(values[:40], 39), atol=1e-10)
    line = 3.0 - 0.25 * np.arange(100.0)
    np.testing.assert_allclose(local_line(line, 31), line, atol=1e-9)


def test_the_compiled_reading_equals_its_formula_written_plainly():
    rng = np.random.default_rng(8)
    hinge, position = rng.normal(50.0, 3.0, 300), np.cumsum(rng.normal(0.0, 0.05, 300))
    width = 41  # 4 ms at 10 kHz
    slow = _plain_local_line(hinge, width)
    fast = position - _plain_local_line(position, width)
    want = slow + np.sum((hinge - slow) * fast) / np.sum(fast**2) * fast
    np.testing.assert_allclose(denoised_hinge_nm(hinge, position, RATE_HZ, span_s=0.004), want, atol=1e-9)


def test_a_fast_deflection_term_is_kept_and_its_slope_is_measured():
    t = np.arange(2_000) / RATE_HZ
    position_deg = 2.0 * np.sign(np.sin(2 * np.pi * 15 * t)) * (1 - np.exp(-t / 0.003))  # steps, 15 Hz
    slow_nm = 400.0 + 120.0 * np.sin(2 * np.pi * 1.5 * t)  # a short-period swing
    hinge = slow_nm - 12.0 * position_deg
    read = denoised_hinge_nm(hinge, position_deg, RATE_HZ)
    inner = slice(200, -200)  # near the ends a straight line stands in for the sine's curvature
    assert np.max(np.abs(read - hinge)[inner]) < 0.01 * np.ptp(hinge)


def test_sensor_noise_is_averaged_down_by_the_square_root_of_the_window():
    rng = np.random.default_rng(11)
    t = np.arange(4_000) / RATE_HZ
    swing_deg = 1.5 * np.sin(2 * np.pi * 8 * t)
    truth = 300.0 - 12.0 * swing_deg
    hinge = truth + rng.normal(0.0, 2.0, t.size)
    inner = slice(400, -400)
    quiet = denoised_hinge_nm(hinge, swing_deg, RATE_HZ) - truth
    assert np.std(quiet[inner]) < 2.0 / np.sqrt(401) * 1.5  # 401 samples in 40 ms
    # a real position sensor's noise passes through the slope: 12 N·m/deg · 0.01° per sample
    noisy = denoised_hinge_nm(hinge, swing_deg + rng.normal(0.0, 0.01, t.size), RATE_HZ) - truth
    assert np.std(noisy[inner]) == pytest.approx(np.hypot(np.std(quiet[inner]), 0.12), rel=0.15)
    ends = np.r_[0:200, -200:0]  # lines through the 401 nearest samples: no sample left to its own noise
    assert np.std(quiet[ends]) < 2.0 / np.sqrt(401) * 3


def test_a_batch_row_equals_its_single_window_and_a_held_elevator_reads_the_plain_mean():
    rng = np.random.default_rng(5)
    hinge = rng.normal(100.0, 2.0, (3, 600))
    position = np.cumsum(rng.normal(0.0, 0.02, (3, 600)), axis=1)
    position[2] = 0.5  # held: no fast deflection at all
    together = denoised_hinge_nm(hinge, position, RATE_HZ)
    for row in range(3):
        np.testing.assert_allclose(denoised_hinge_nm(hinge[row], position[row], RATE_HZ), together[row], atol=1e-12)
    np.testing.assert_allclose(together[2], local_line(hinge[2], 401), atol=1e-12)


def test_mismatched_signals_are_named():
    with pytest.raises(InputError) as error:
        denoised_hinge_nm(np.zeros(10), np.zeros(11), RATE_HZ)
    assert error.value.field == "signals"
