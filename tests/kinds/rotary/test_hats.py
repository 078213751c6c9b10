"""The generic curves' basis is sound."""

import numpy as np

from ema.kinds.rotary.hats import hats, uniform_knots


def test_hats_are_a_partition_of_unity_without_the_first():
    x = np.linspace(-1, 3, 101)
    knots = uniform_knots(x, 5)
    basis = hats(x, knots)
    assert basis.shape == (101, 4)
    u = np.clip((x - knots[0]) / (knots[1] - knots[0]), 0.0, len(knots) - 1.0)  # held past the ends
    first = np.maximum(0.0, 1.0 - u)
    np.testing.assert_allclose(basis.sum(axis=1) + first, 1.0, atol=1e-12)
