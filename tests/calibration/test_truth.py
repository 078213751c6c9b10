"""A calibration's errors against a truth: every constant the report carries, before and after; a truth that names
none, or a value no actuator of the document can have, refused naming it."""

import math

import pytest

from ema.calibration.documents import Learned, LinearCalibration
from ema.calibration.truth import refuse_truth, reported, with_truth_errors
from ema.model.actuator import THESIS
from ema.model.checks import InputError


def _report() -> LinearCalibration:
    """A report's constants alone (the rest of a report plays no part in its errors)."""
    return LinearCalibration.model_construct(
        estimates_before={"FDJ": 0.8},
        estimates_after={"FDJ": 1.1},
        learned=[
            Learned(name="current_per_nm_a", value=2.5, std=0.1, unit="A/(N·m)"),
            Learned(name="FDJ", value=9.9, std=0.1, unit="N·m"),
        ],
    )


def test_the_estimates_after_win_over_a_learned_value_of_the_same_name():
    before, after = reported(_report())
    assert before == {"FDJ": 0.8}
    assert after == {"current_per_nm_a": 2.5, "FDJ": 1.1}


def test_each_named_constant_is_compared_before_where_it_has_a_value_and_after():
    report = with_truth_errors(_report(), {"FDJ": 1.0, "current_per_nm_a": 2.0, "eta_A": 0.5})
    assert report.error_before == pytest.approx({"FDJ": 0.2})
    assert report.error_after == pytest.approx({"FDJ": 0.1, "current_per_nm_a": 0.5})
    assert report.error_pct_before == pytest.approx({"FDJ": 20.0})
    assert report.error_pct_after == pytest.approx({"FDJ": 10.0, "current_per_nm_a": 25.0})


def test_a_truth_of_zero_has_an_absolute_error_only_and_no_truth_changes_nothing():
    report = with_truth_errors(_report(), {"FDJ": 0.0})
    assert report.error_after == pytest.approx({"FDJ": 1.1}) and report.error_pct_after is None
    assert with_truth_errors(_report(), None).error_after is None


def test_a_truth_naming_nothing_the_report_carries_is_refused_naming_what_it_carries():
    with pytest.raises(InputError, match="names fdj; this calibration reports current_per_nm_a, FDJ") as caught:
        with_truth_errors(_report(), {"fdj": 1.0})
    assert caught.value.field == "truth"


@pytest.mark.parametrize(
    ("truth", "field", "said"),
    [
        ({"FDJ": -0.05}, "truth.FDJ", "allows"),
        ({"FDJ": 0.05, "eta_O": 1.2}, "truth.eta_O", "allows < 1"),
        ({"mass_of_nothing": math.nan}, "truth.mass_of_nothing", "finite"),
        ({}, "truth", "names no constant"),
    ],
)
def test_a_value_the_document_does_not_allow_is_refused_naming_the_entry(truth, field, said):
    with pytest.raises(InputError, match=said) as caught:
        refuse_truth(truth, THESIS)
    assert caught.value.field == field


def test_a_truth_the_document_allows_passes():
    refuse_truth({"FDJ": 0.05, "eta_O": 0.85, "FSJ": 0.1, "flight_constant": 3.0}, THESIS)
