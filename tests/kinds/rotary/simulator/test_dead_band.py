"""The dead band's path: closed forms, and the compiled loop against a plain one."""

import numpy as np
import pytest

from ema.kinds.rotary.simulator.dead_band import dead_band_paths
from ema.model.checks import InputError


def _plain(travel: np.ndarray, half_width: float, start: float) -> np.ndarray:
    out, y = [], travel[0] + start * half_width
    for x in travel:
        y = min(max(y, x - half_width), x + half_width)
        out.append(y)
    return np.array(out)


def test_the_compiled_paths_equal_the_plain_loop():
    rng = np.random.default_rng(5)
    travel = np.cumsum(rng.normal(size=2000)) * 1e-3
    halves, starts = rng.uniform(0.0, 0.02, 7), rng.uniform(-1.0, 1.0, 7)
    paths = dead_band_paths(travel, halves, starts)
    for row, (h, s) in enumerate(zip(halves, starts, strict=True)):
        np.testing.assert_allclose(paths[row], _plain(travel, h, s), rtol=0, atol=1e-15)


def test_no_band_passes_the_travel_and_a_band_cuts_each_swing_by_its_width():
    t = np.linspace(0.0, 1.0, 4001)
    travel = 0.1 * np.sin(2 * np.pi * 3 * t)  # amplitude 0.1 rad, three swings
    np.testing.assert_array_equal(dead_band_paths(travel, np.zeros(1), np.zeros(1))[0], travel)
    path = dead_band_paths(travel, np.array([0.01]), np.array([0.0]))[0]
    later = t > 0.5  # after the first reversals the path swings 2·(0.1 − 0.01)
    assert np.ptp(path[later]) == pytest.approx(2 * (0.1 - 0.01), abs=1e-6)
    assert np.max(np.abs(path - travel)) <= 0.01 + 1e-15


def test_bad_arguments_are_named():
    with pytest.raises(InputError, match="half_widths_rad"):
        dead_band_paths(np.zeros(3), np.array([-1.0]), np.zeros(1))
    with pytest.raises(InputError, match="travel_rad"):
        dead_band_paths(np.array([0.0, np.nan]), np.zeros(1), np.zeros(1))
