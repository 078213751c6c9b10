"""The tail check of the accuracy benchmark: its expected counts and its fresh noise draws."""

import math

import numpy as np

from benchmarks.tails import BOUND, expected_over
from tests.foreign.windows import draw


def test_expected_over_is_the_gaussian_tail() -> None:
    at_95 = BOUND / 1.959964  # P(|N(0, s)| > BOUND) = 5 %
    assert math.isclose(expected_over(np.array([at_95] * 20)), 1.0, rel_tol=1e-4)
    assert expected_over(np.array([BOUND / 10, 0.0])) < 1e-20


def test_a_noise_seed_redraws_the_noise_alone() -> None:
    def noise(**kw):
        drawn = draw(5, "gust", duration_s=0.1, **kw)
        clean = draw(5, "gust", duration_s=0.1, noise_level=0.0)
        signals = {
            name: np.asarray(values) - clean.document["signals"][name]
            for name, values in drawn.document["signals"].items()
        }
        return drawn, signals

    logged, as_logged = noise()
    again, fresh = noise(noise_seed=1)
    assert again.truth == logged.truth and np.array_equal(noise()[1]["current_a"], as_logged["current_a"])
    for name in ("current_a", "motor_speed_radps", "hinge_moment_nm"):
        assert not np.allclose(fresh[name], as_logged[name])
        assert 0.85 < np.std(fresh[name]) / np.std(as_logged[name]) < 1.15  # the same level, 1000 samples
