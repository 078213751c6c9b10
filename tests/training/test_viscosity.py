"""The viscous coefficient read per window, on foreign windows (tests/foreign's own viscous friction)."""

import pytest

from sim.params import ActuatorParams
from sim.window import window_from_dict
from tests.foreign.windows import Effects, draw
from training.conditioning import prepare
from training.viscosity import Viscosity

FAMILIES = ("thesis", "cruise", "gust", "doublet", "steps")
SPEC_C = ActuatorParams().viscous_nms


def _read(seed: int, factor: float) -> Viscosity:
    drawn = draw(seed, FAMILIES[seed % 5], effects=Effects(viscous_factor=factor))
    return prepare(window_from_dict(drawn.document)).departures.viscosity


@pytest.mark.parametrize("factor", [1.3, 2.0])
def test_a_viscous_coefficient_beyond_the_specs_is_read_within_a_few_percent(factor):
    for seed in range(90, 95):
        read = _read(seed, factor)
        assert 1.0 + read.change_nms / SPEC_C == pytest.approx(factor, abs=0.08), seed
        assert read.spread["FDJ"] > 0.0 and read.change_std_nms > 0.0


def test_the_specs_viscous_coefficient_is_left_alone():
    """On 1200 foreign windows of every benchmark group, none was read as a change."""
    assert all(_read(seed, 1.0) == Viscosity() for seed in range(95, 110))
