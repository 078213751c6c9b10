"""The pipeline's configuration: a size under its earlier published name is read, two values for one refused."""

import pytest

from ema.estimate.config import PipelineConfig
from ema.model.checks import InputError, validated


def test_a_size_under_its_earlier_name_is_read_and_two_values_are_refused():
    assert validated(PipelineConfig, {"check_windows": 9}, "config").check_simulations == 9
    assert validated(PipelineConfig, {"check_windows": 9, "check_simulations": 9}, "config").check_windows == 9
    with pytest.raises(InputError, match="check_windows: is the earlier name of check_simulations"):
        validated(PipelineConfig, {"check_windows": 9, "check_simulations": 10}, "config")
