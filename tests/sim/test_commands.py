import numpy as np

from sim.commands import (
    COMMAND_LIMIT_DEG,
    knots_from_samples,
    random_command_coefficients,
    random_command_knots,
)


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


def test_knots_from_samples_recovers_a_smooth_command_from_its_interval_means():
    coefficients = random_command_coefficients(0.5, np.random.default_rng(2))
    edges = np.arange(501) / 1000.0
    antiderivative = np.polyint(coefficients)
    means = np.diff(np.polyval(antiderivative, edges)) * 1000.0  # what a logger averaging at 1 kHz records
    rebuilt = knots_from_samples(means)[0]
    truth = np.polyval(coefficients, edges)
    np.testing.assert_allclose(rebuilt[2:-2], truth[2:-2], atol=1e-5)  # fourth order inside
    np.testing.assert_allclose(rebuilt, truth, atol=1e-3)  # third order at the ends
