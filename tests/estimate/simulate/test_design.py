import numpy as np
import pytest

from ema.estimate.simulate.design import binned, halton, shifted_copies
from ema.model.checks import InputError


def test_halton_is_seeded_and_in_the_unit_cube():
    a, b = halton(50, 3), halton(50, 3)
    np.testing.assert_array_equal(a, b)
    assert a.min() >= 0 and a.max() < 1
    assert not np.array_equal(a, halton(50, 4))


def test_a_halton_design_names_its_dimensions_when_there_are_too_many():
    with pytest.raises(InputError, match="dims"):
        halton(4, 0, dims=9)


def test_binned_means_each_equal_part_of_the_window():
    values = np.arange(12.0)
    np.testing.assert_array_equal(binned(values, 3), [1.5, 5.5, 9.5])


def test_shifted_copies_keep_the_misfits_values_and_size():
    misfit = np.arange(8.0) - 3.5
    copies = shifted_copies(misfit, 5, seed=2)
    assert copies.shape == (5, 8)
    for row in copies:
        np.testing.assert_array_equal(np.sort(np.abs(row)), np.sort(np.abs(misfit)))
    np.testing.assert_array_equal(copies, shifted_copies(misfit, 5, seed=2))
