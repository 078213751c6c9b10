import signal

import numpy as np
import pytest

from ema.kinds.rotary.simulator.commands import (
    COMMAND_LIMIT_DEG,
    family_knots,
    knots_from_samples,
    random_command_coefficients,
    random_command_knots,
)
from ema.model.bounds import COMMAND_FAMILIES
from ema.model.checks import InputError


def test_random_command_starts_at_zero_and_passes_its_nodes_within_25_degrees():
    rng = np.random.default_rng(5)
    coefficients = random_command_coefficients(0.5, rng)
    nodes = np.polyval(coefficients, np.linspace(0, 0.5, 6))
    assert abs(nodes[0]) < 1e-9
    assert np.all(np.abs(nodes) <= 25.0 + 1e-9)
    assert len(coefficients) == 6  # 5th order


def test_commands_are_seeded_and_within_the_travel_limit():
    a = random_command_knots(5000, 10_000.0, np.random.default_rng(1), n_commands=20)
    b = random_command_knots(5000, 10_000.0, np.random.default_rng(1), n_commands=20)
    np.testing.assert_array_equal(a, b)
    assert a.shape == (20, 5001)
    assert np.abs(a).max() <= COMMAND_LIMIT_DEG
    assert len({tuple(row[::500]) for row in a}) == 20  # Case 2: every command differs


def test_a_command_over_no_time_is_refused_not_redrawn_forever():
    def endless(*_):
        raise AssertionError("still redrawing after 20 s")

    previous = signal.signal(signal.SIGALRM, endless)
    signal.alarm(20)
    try:
        with pytest.warns(RuntimeWarning), pytest.raises(InputError) as refused:
            random_command_knots(0, 10_000.0, np.random.default_rng(0))
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, previous)
    assert refused.value.field == "n_samples"


def test_knots_from_samples_recovers_a_smooth_command_from_its_interval_means():
    coefficients = random_command_coefficients(0.5, np.random.default_rng(2))
    edges = np.arange(501) / 1000.0
    antiderivative = np.polyint(coefficients)
    means = np.diff(np.polyval(antiderivative, edges)) * 1000.0  # what a logger averaging at 1 kHz records
    rebuilt = knots_from_samples(means)[0]
    truth = np.polyval(coefficients, edges)
    second = np.abs(np.polyval(np.polyder(coefficients, 2), edges))
    inside = slice(2, -2)
    # fourth order inside; within a cell of an extremum the limiter costs at most |f''|·Δt²/6
    np.testing.assert_array_less(np.abs(rebuilt - truth)[inside], (1e-5 + second * 1e-6 / 6)[inside])
    np.testing.assert_array_less(np.abs(rebuilt - truth), 1e-3 + second * 1e-6 / 6)  # third order at the ends


def test_knots_from_samples_do_not_ring_at_a_step():
    means = np.concatenate([np.zeros(10), [0.3], np.full(10, 10.0)])  # a 10° step 70 % into cell 10
    knots = knots_from_samples(means)[0]
    assert knots.min() >= 0.0 and knots.max() <= 10.0
    np.testing.assert_array_equal(knots[:10], 0.0)
    np.testing.assert_array_equal(knots[12:], 10.0)


@pytest.mark.parametrize("family", COMMAND_FAMILIES)
def test_every_family_is_seeded_finite_and_within_a_flights_deflections(family):
    a = family_knots(family, 5000, 10_000.0, np.random.default_rng(1))
    b = family_knots(family, 5000, 10_000.0, np.random.default_rng(1))
    np.testing.assert_array_equal(a, b)
    assert a.shape == (5001,) and np.all(np.isfinite(a)) and np.abs(a).max() <= 28.0
    assert np.ptp(a) > 1.0  # it moves


def test_an_unknown_family_is_named():
    with pytest.raises(InputError, match="command"):
        family_knots("barrel-roll", 100, 10_000.0, np.random.default_rng(0))
