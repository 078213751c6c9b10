"""How far readings scatter beyond their own stds (Paule and Mandel's rule): a geared servo's repeatability about its
nominal, a ball screw's about its runs' mean, on readings drawn here with a known scatter."""

import numpy as np
import pytest

from ema.estimate.stats import between_runs_std


def test_the_scatter_beyond_equal_own_stds_is_recovered():
    rng = np.random.default_rng(11)
    own = np.full(4000, 0.03)
    values = 0.9 + rng.normal(0.0, np.hypot(0.03, 0.04), size=own.size)
    assert between_runs_std(values, own, 0.9) == pytest.approx(0.04, rel=0.05)


def test_precise_runs_that_scatter_are_not_hidden_by_imprecise_ones():
    """900 runs read to 0.001 scatter by 0.05, 100 read to 2: the whole spread less the mean own variance is noise
    (this draw: 0; others 0.09 to 0.34), weighed run by run the precise runs' scatter stands."""
    rng = np.random.default_rng(14)
    own = np.r_[np.full(900, 0.001), np.full(100, 2.0)]
    values = 0.1 + rng.normal(0.0, 1.0, size=own.size) * np.hypot(own, 0.05)
    assert np.var(values, ddof=1) < np.mean(own**2)  # the rule it replaces reads no scatter
    tau = between_runs_std(values, own, 0.1)
    assert tau == pytest.approx(0.05, rel=0.05)
    z = (values - 0.1) / np.hypot(own, tau)
    assert float(np.mean(z**2)) == pytest.approx(1.0, abs=1e-9)  # the rule's own equation, solved


def test_an_offset_from_the_nominal_is_scatter_and_own_stds_that_explain_all_leave_none():
    own = np.full(100, 0.02)
    offset = np.full(100, 0.93)  # every run 0.03 above a nominal of 0.90, read to 0.02
    assert between_runs_std(offset, own, 0.90) == pytest.approx(np.sqrt(0.03**2 - 0.02**2))
    rng = np.random.default_rng(13)
    assert between_runs_std(0.9 + rng.normal(0.0, 0.01, 100), own, 0.9) == 0.0
    assert between_runs_std(np.array([]), np.array([]), 0.9) == 0.0


def test_about_their_own_mean_the_scatter_is_recovered_and_an_offset_is_not():
    """A ball screw's runs, judged against each other: their common offset is no scatter (n − 1 degrees of freedom)."""
    rng = np.random.default_rng(15)
    own = rng.uniform(0.01, 0.05, size=3000)
    values = 5.0 + rng.normal(0.0, 1.0, size=own.size) * np.hypot(own, 0.02)
    assert between_runs_std(values, own) == pytest.approx(0.02, rel=0.05)
    assert between_runs_std(values + 1.0, own) == pytest.approx(between_runs_std(values, own), rel=1e-6)
    assert between_runs_std(values[:2], own[:2]) == 0.0  # two readings tell no scatter from their mean
