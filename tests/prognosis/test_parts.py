"""The prognosis's parts on closed forms and draws of known truth (drawn here, not by the code under test): each
law recovers a curve of its own family, the excess scatter and the robust line read what was put in, the laws
are weighed towards the one that drew the history, and a known line's crossing is where the line says."""

import numpy as np
import pytest

from ema.prognosis.forecast import forecast
from ema.prognosis.laws import BY_NAME, law_curve
from ema.prognosis.rul import remaining_life
from ema.prognosis.trend import Series, excess_variance, robust_polynomial
from ema.prognosis.weigh import weigh

S = np.linspace(0.0, 1.0, 30)


@pytest.mark.parametrize(
    ("law", "shape", "curve"),
    [
        ("linear", 0.0, 0.05 + 0.02 * S),
        ("quadratic", 0.0, 0.05 + 0.01 * S + 0.03 * S**2),
        ("exponential", 2.0, 0.05 + 0.01 * np.expm1(2.0 * S) / 2.0),
        ("power", 3.0, 0.05 + 0.02 * S**3.0),
    ],
)
def test_each_law_finds_a_curve_of_its_own_family_exactly(law, shape, curve):
    curve = law_curve(BY_NAME[law], S, curve, np.full(len(S), 1e8))
    best = int(np.argmax(curve.weights))
    assert BY_NAME[law].shapes[best] == pytest.approx(shape)
    mean, _ = curve.predictive(np.array([0.5, 1.5]))
    truth = {"linear": lambda s: 0.05 + 0.02 * s, "quadratic": lambda s: 0.05 + 0.01 * s + 0.03 * s**2}
    truth |= {"exponential": lambda s: 0.05 + 0.01 * np.expm1(2.0 * s) / 2.0, "power": lambda s: 0.05 + 0.02 * s**3}
    assert mean == pytest.approx(truth[law](np.array([0.5, 1.5])), rel=1e-6)


def test_the_excess_scatter_is_what_the_stated_stds_leave_unexplained():
    rng = np.random.default_rng(11)
    sigma, tau = 1e-3, 2e-3
    residual = rng.normal(0.0, np.hypot(sigma, tau), 4000)
    variance, robust = np.full(4000, sigma**2), np.ones(4000)
    assert np.sqrt(excess_variance(residual, variance, robust, 3999)) == pytest.approx(tau, rel=0.05)
    explained = rng.normal(0.0, sigma, 4000)
    assert excess_variance(explained * 0.9, variance, robust, 3999) == 0.0  # within the stds: none


def test_a_line_read_robustly_is_not_pulled_by_a_reading_thirty_stds_off():
    rng = np.random.default_rng(12)
    x = np.linspace(-1.0, 0.0, 25)
    values = 0.06 + 0.01 * x + rng.normal(0.0, 1e-4, 25)
    values[7] += 3e-3
    curve = robust_polynomial(x, values, np.full(25, 1e-8), 1)
    plain = np.polyfit(x, values, 1)[0]
    assert abs(curve["beta"][1] - 0.01) < 0.5 * abs(plain - 0.01)  # pulled less than half as far as a plain line
    assert int(np.argmin(curve["robust"])) == 7 and curve["robust"][7] < 0.5


def test_the_laws_are_weighed_towards_the_one_that_drew_the_history():
    rng = np.random.default_rng(13)
    s = np.linspace(0.0, 1.0, 24)
    values = 0.05 + 0.002 * np.expm1(4.0 * s) + rng.normal(0.0, 2e-4, 24)  # wear that speeds up
    weighed = weigh(s, values, np.full(24, 1.0 / 2e-4**2))
    names = [curve.law.name for curve in weighed.curves]
    assert weighed.weights[names.index("linear")] < 0.05
    assert weighed.weights[names.index("exponential")] + weighed.weights[names.index("power")] > 0.5


@pytest.mark.parametrize("direction", ["above", "below"])
def test_a_straight_line_crosses_its_threshold_where_the_line_says(direction):
    """FDJ moving 1e-4 per hour from 0.05 over 100 h, read to 1e-5: the level 0.065 (or 0.035 falling) is 50 h
    past the last window."""
    sign = 1.0 if direction == "above" else -1.0
    rng = np.random.default_rng(14)
    hours = np.linspace(0.0, 100.0, 21)
    values = 0.05 + sign * 1e-4 * hours + rng.normal(0.0, 1e-5, 21)
    s = hours / 100.0
    fc = forecast(weigh(s, values, np.full(21, 1e10)), t_first=0.0, span=100.0)
    life = remaining_life("FDJ", fc, 0.05 + sign * 0.015, direction)
    assert life.status == "crossing predicted"
    assert life.rul == pytest.approx(50.0, rel=0.05) and life.rul_low <= 50.0 <= life.rul_high


def test_a_series_is_put_in_time_order_and_cut_with_its_windows():
    series = Series("FDJ", np.array([3.0, 1.0, 2.0]), np.array([0.3, 0.1, 0.2]), np.array([1.0, 1.0, 1.0]), "cab")
    ordered = series.in_time_order()
    assert list(ordered.times) == [1.0, 2.0, 3.0] and list(ordered.window_ids) == ["a", "b", "c"]
    assert list(ordered.values) == [0.1, 0.2, 0.3] and list(ordered.first(2).window_ids) == ["a", "b"]
