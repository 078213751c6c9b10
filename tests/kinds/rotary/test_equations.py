"""The equation-error problem: closed forms of its columns."""

import numpy as np
import pytest

from ema.kinds.rotary.backlash import width_rad
from ema.kinds.rotary.equations import cogging_columns, equations, motor_angle_rad
from ema.kinds.rotary.synthetic import synthetic_window
from ema.model.actuator import THESIS
from ema.model.noise import NO_NOISE
from ema.model.params import HealthParams


def test_motor_angle_integrates_the_interval_mean_speed():
    angle = motor_angle_rad(np.full(10, 100.0), np.zeros(10), 1000.0, 500.0)
    np.testing.assert_allclose(np.diff(angle), 0.1)


def test_a_cogging_column_carries_the_logs_interval_mean_attenuation():
    rate, speed, order = 10_000.0, 300.0, 12.0
    t = (np.arange(4000) + 0.5) / rate
    angle = speed * t
    columns = cogging_columns(angle, np.full(4000, speed), rate, [order])[order]
    # The interval mean of sin(pθ) over an interval where θ advances by ω/f is sinc(pω/2f) times the centre value.
    exact = np.array([np.mean(np.sin(order * speed * (k / rate + np.arange(1000) / 1000 / rate))) for k in range(4000)])
    middle = slice(100, 3900)  # the 2 ms smoothing attenuates further; compare after it, away from the ends
    from ema.kinds.rotary.simulator.residual import smoothed

    np.testing.assert_allclose(columns[middle, 0], smoothed(exact, rate)[middle], atol=2e-3)


def test_the_dead_band_width_is_read_from_the_windows_own_angles():
    window = synthetic_window(HealthParams.single(), seed=3, noise=NO_NOISE)
    problem = equations([window.signals], window.sample_rate_hz, [], drive=THESIS.params)
    # BLK of Table 3.1, within the few % that smoothing over the reversals takes (the noise floor's
    # copies carry the same, so ema.kinds.rotary.backlash reads extra width against them, not against BLK)
    assert width_rad(problem) == pytest.approx(5e-3, rel=0.1)


@pytest.mark.parametrize("gear_ratio", [20.0, 500.0])
@pytest.mark.parametrize("eta_o", [0.6, 0.85])
def test_the_tied_base_holds_eq_3_4_near_the_windows_efficiency(gear_ratio, eta_o):
    """t = FDJ + k_aid(η_O)·a + k_opp(η_O)·o exactly (Eq. 3.4): the tied design, linearized where the free fit
    sits, reproduces it with k_opp as its load coefficient."""
    from dataclasses import replace

    from ema.calibration.held_out import score
    from ema.model.params import load_factors

    rng = np.random.default_rng(7)
    e = equations([synthetic_window(HealthParams.single(), seed=1).signals], 10_000.0, [], drive=THESIS.params)
    a, o = rng.uniform(0, 0.1, e.m) * (rng.random(e.m) < 0.5), rng.uniform(0, 0.1, e.m)
    k_aid, k_opp = load_factors(eta_o, gear_ratio)
    base = np.column_stack([np.ones(e.m), a, o])
    tied = replace(e, y=0.05 + k_aid * a + k_opp * o, base=base, gear_ratio=gear_ratio)
    design, fixed = tied.tied
    solution = score(design, tied.y - fixed, e.folds)
    assert np.sqrt(solution.rss / e.m) < 1e-4 * 0.05
    assert solution.beta[1] == pytest.approx(k_opp, rel=1e-3)
