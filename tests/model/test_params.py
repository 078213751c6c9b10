import numpy as np
import pytest

from ema.model.checks import InputError
from ema.model.params import DEFAULT_RANGES, IRREVERSIBLE_RANGES, HealthParams, HealthRanges, eta_a_from_eta_o


def test_eq_3_4_reproduces_the_thesis_case_1c_range():
    assert eta_a_from_eta_o(0.44, 500.0) == pytest.approx(-0.2668, abs=3e-4)  # the thesis prints 4 digits
    assert eta_a_from_eta_o(0.66, 500.0) == pytest.approx(0.4864, abs=3e-4)


def test_eq_3_4_at_nominal_and_its_limits():
    assert eta_a_from_eta_o(0.85, 500.0) == pytest.approx(0.824, abs=1e-3)
    assert eta_a_from_eta_o(1.0, 500.0) == pytest.approx(1.0)
    eta_o = np.linspace(0.3, 1.0, 50)
    assert np.all(np.diff(eta_a_from_eta_o(eta_o, 500.0)) > 0)  # monotonic: η_A is a function of η_O


def test_uniform_draws_stay_in_range_and_are_seeded():
    a = HealthParams.uniform(1000, DEFAULT_RANGES, np.random.default_rng(3))
    b = HealthParams.uniform(1000, DEFAULT_RANGES, np.random.default_rng(3))
    np.testing.assert_array_equal(a.fdj_nm, b.fdj_nm)
    for values, (low, high) in ((a.fsj_nm, (0.08, 0.12)), (a.fdj_nm, (0.04, 0.06)), (a.eta_o, (0.68, 0.98))):
        assert low <= values.min() and values.max() <= high
        assert values.max() - values.min() > 0.9 * (high - low)


def test_case_1c_ranges_make_eta_a_change_sign():
    draws = HealthParams.uniform(500, IRREVERSIBLE_RANGES, np.random.default_rng(0))
    eta_a = draws.eta_a(500.0)
    assert eta_a.min() < 0 < eta_a.max()
    assert IRREVERSIBLE_RANGES.nominal_eta_o == 0.55


@pytest.mark.parametrize(
    ("kwargs", "field"),
    [
        ({"fsj_nm": [0.1, np.nan], "fdj_nm": [0.05, 0.05], "eta_o": [0.8, 0.8]}, "fsj_nm"),
        ({"fsj_nm": [0.1], "fdj_nm": [0.05, 0.05], "eta_o": [0.8, 0.8]}, "health"),
        ({"fsj_nm": [0.1], "fdj_nm": [-0.05], "eta_o": [0.8]}, "fdj_nm"),
        ({"fsj_nm": [0.1], "fdj_nm": [0.05], "eta_o": [1.2]}, "eta_o"),
    ],
)
def test_bad_health_names_the_field(kwargs, field):
    with pytest.raises(InputError) as error:
        HealthParams(**{k: np.asarray(v) for k, v in kwargs.items()})
    assert error.value.field == field


def test_bad_ranges_name_the_field():
    with pytest.raises(InputError, match="nominal_eta_o"):
        HealthRanges(nominal_eta_o=0.5)
    with pytest.raises(InputError, match="fdj_nm"):
        HealthRanges(fdj_nm=(0.06, 0.04))
