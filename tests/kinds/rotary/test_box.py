import numpy as np
import pytest

from ema.kinds.rotary.box import MIN_HALF_SPAN, Box, box_around, draw, physical
from ema.model.checks import InputError


def test_the_box_is_centred_on_the_estimate_and_at_least_its_minimum_width():
    box = box_around(0.05, 1e-6, 0.85, 1e-6, 0.05)
    assert np.mean(box.fdj_nm) == pytest.approx(0.05)
    assert box.fdj_nm[1] - box.fdj_nm[0] == pytest.approx(2 * MIN_HALF_SPAN["fdj_nm"] * 0.05)
    assert box.eta_o == pytest.approx((0.85 - MIN_HALF_SPAN["eta_o"], 0.85 + MIN_HALF_SPAN["eta_o"]))
    wide = box_around(0.05, 0.004, 0.85, 0.02, 0.05)
    assert wide.fdj_nm[1] - wide.fdj_nm[0] > box.fdj_nm[1] - box.fdj_nm[0]


def test_worn_actuators_are_not_capped_but_the_box_stays_physical():
    worn = box_around(0.125, 0.001, 0.47, 0.004, 0.05)  # 2.5x nominal friction, Case 1C efficiency
    assert worn.fdj_nm[0] < 0.125 < worn.fdj_nm[1]
    assert worn.eta_o[0] < 0.47 < worn.eta_o[1]
    edge = box_around(0.05, 0.001, 0.99, 0.02, 0.05)  # near η_O = 1: shifted inside, not shrunk
    assert edge.eta_o[1] == physical(0.05).eta_o[1]
    assert edge.eta_o[1] - edge.eta_o[0] == pytest.approx(2 * 6.0 * 0.02)


def test_draws_fill_the_box_evenly_with_static_above_dynamic_friction():
    box = Box(fdj_nm=(0.04, 0.06), eta_o=(0.7, 0.9))
    health = draw(box, 64, seed=1)
    assert np.all(health.fsj_nm > health.fdj_nm)
    unit = box.normalize(health.fdj_nm, health.eta_o)
    counts, _, _ = np.histogram2d(unit[:, 0], unit[:, 1], bins=4, range=[[0, 1], [0, 1]])
    assert counts.min() >= 2  # 64 points in 16 cells: no holes (uniform draws leave some ~1 time in 3)
    np.testing.assert_allclose(box.denormalize(unit)[0], health.fdj_nm)


def test_a_non_finite_centre_is_named():
    with pytest.raises(InputError, match="fdj_nm"):
        box_around(float("nan"), 0.001, 0.8, 0.01, 0.05)


def test_the_physical_limits_follow_the_actuators_nominal_friction():
    """A heavier actuator's FDJ of 0.6 N·m is worn, not impossible: the box stays around it."""
    assert physical(0.08).fdj_nm == pytest.approx((0.008, 0.8))
    box = box_around(0.6, 0.001, 0.8, 0.01, 0.08)
    assert box.fdj_nm[0] < 0.6 < box.fdj_nm[1]
