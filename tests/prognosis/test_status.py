"""A status is earned: no "due" without a time base and a spread of windows (and never a life in a unit the
windows do not have)."""

import datetime as dt

import pytest

from ema.estimate.documents import parameter
from ema.kinds.rotary.pipeline import estimate_window
from ema.kinds.rotary.synthetic import synthetic_window
from ema.model.actuator import THESIS
from ema.model.params import HealthParams
from ema.prognosis.documents import Stored
from ema.prognosis.prognose import prognose
from ema.prognosis.status import status_of, summary
from tests.service.conftest import SMALL


@pytest.fixture(scope="module")
def base():
    return estimate_window(synthetic_window(HealthParams.single(), seed=1, duration_s=0.1), SMALL, actuator=THESIS)


def _history(base, fdjs, **times):
    """Stored windows of FDJ ``fdjs``, each with the time fields given as lists (absent: none)."""
    stored = []
    for i, fdj in enumerate(fdjs):
        window = base.window.model_copy(update={name: values[i] for name, values in times.items()})
        estimates = base.estimates.model_copy(update={"FDJ": parameter(fdj, 2e-4, 0.05, unit="N·m")})
        document = base.model_copy(update={"window_id": f"w{i}", "window": window, "estimates": estimates})
        stored.append(Stored(**document.model_dump(by_alias=True), id=i + 1, stored_at=f"2026-11-26T10:00:0{i}+00:00"))
    return stored


def test_windows_without_a_time_base_trend_in_windows_and_are_never_due(base):
    stored = _history(base, [0.050, 0.055, 0.060, 0.065, 0.070])  # a collapse, if storage time were time
    prognosis = prognose("a", stored, THESIS)
    assert prognosis.time_unit == "windows" and prognosis.notes[0].code == "time_by_window_order"
    status, _, _ = status_of(stored[-1], prognosis, THESIS, len(stored))
    assert status != "due"
    life = prognosis.remaining_life["FDJ"]
    assert life.rul is None or life.status == "crossing predicted"  # counted in windows, the unit it has


def test_windows_logged_within_a_second_are_not_enough_history(base):
    start = dt.datetime(2026, 11, 26, 10, tzinfo=dt.UTC)
    stamps = [(start + dt.timedelta(seconds=0.2 * i)).isoformat() for i in range(5)]
    stored = _history(base, [0.050, 0.055, 0.060, 0.065, 0.070], recorded_at=stamps)
    prognosis = prognose("a", stored, THESIS)
    assert prognosis.time_unit == "days" and prognosis.remaining_life["FDJ"].status == "span too short"
    status, soonest, reason = status_of(stored[-1], prognosis, THESIS, len(stored))
    assert status in ("not enough history", "watch") and soonest is None and "days" in reason


def test_a_crossed_threshold_is_due_once_the_windows_are_evidence(base):
    few = _history(base, [0.080, 0.081, 0.080, 0.082, 0.081])  # five windows in order: a span of four
    assert status_of(few[-1], prognose("a", few, THESIS), THESIS, len(few))[0] == "watch"
    enough = _history(base, [0.080, 0.081, 0.080, 0.082, 0.081], flight_hours=[0, 5, 10, 15, 20])
    assert status_of(enough[-1], prognose("a", enough, THESIS), THESIS, len(enough))[0] == "due"


def test_a_spread_of_flight_hours_earns_a_forecast(base):
    stored = _history(base, [0.050, 0.053, 0.056, 0.059, 0.062, 0.065], flight_hours=[0, 20, 40, 60, 80, 100])
    prognosis = prognose("a", stored, THESIS)
    assert prognosis.remaining_life["FDJ"].status == "crossing predicted"
    assert status_of(stored[-1], prognosis, THESIS, len(stored))[::2] == ("watch", "FDJ: a crossing is predicted")


def test_a_friction_that_falls_past_a_lower_level_is_due_and_both_levels_are_shown(base):
    """A screw losing its preload: FDJ falling through the document's lower level is a crossing like a rise."""
    from ema.model.actuator import actuator_from_dict

    document = THESIS.model_dump(by_alias=True)
    document["thresholds"] = {"fdj_above_nm": 0.075, "fdj_below_nm": 0.035}
    actuator = actuator_from_dict(document)
    fdjs = [0.05 - 0.003 * i for i in range(8)]  # 0.050 down to 0.029
    stored = _history(base, fdjs, flight_hours=[10.0 * i for i in range(8)])
    prognosis = prognose("a/1", stored, actuator)
    assert prognosis.remaining_life["FDJ"].threshold == 0.035 and prognosis.remaining_life["FDJ"].direction == "below"
    line = summary(prognosis, stored[-1], len(stored), actuator, None)
    assert line.status == "due" and line.thresholds_below["FDJ"].level == 0.035
    assert line.thresholds["FDJ"].level == 0.075 and line.repeatability_stds["FDJ"] is not None


def test_a_document_without_nominal_or_level_trends_nothing_says_why_and_keeps_its_line(base):
    """A servo's document before ema calibrate (no nominal, no thresholds): no level to trend towards, said per
    parameter; its fleet line still stands (no healthy range to judge by). Given a level, the trend comes."""
    from pathlib import Path

    from ema.model.actuator import read_actuator

    servo = read_actuator(Path(__file__).resolve().parents[2] / "examples" / "emps" / "actuator.json")
    assert servo.nominal is None and servo.limits("FDJ") == [] and servo.limits("eta_O") == []
    stored = _history(base, [0.050, 0.053, 0.056, 0.059, 0.062, 0.065], flight_hours=[0, 20, 40, 60, 80, 100])
    prognosis = prognose("a", stored, servo)
    assert prognosis.trends == {}
    assert {n.parameter for n in prognosis.notes if n.code == "no_threshold"} == {"FDJ", "eta_O", "eta_A"}
    line = summary(prognosis, stored[-1], len(stored), servo, 1)
    assert line.status == "not enough history" and "no failure level" in line.reason
    assert line.thresholds == {}
    levelled = servo.model_copy(update={"thresholds": servo.thresholds.model_copy(update={"fdj_above_n": 0.075})})
    prognosis = prognose("a", stored, levelled)
    assert list(prognosis.trends) == ["FDJ"] and prognosis.remaining_life["FDJ"].status == "crossing predicted"


def test_an_efficiency_that_rises_is_a_change_its_line_watches(base):
    """η_O rising steadily (drawn here as a line; the rig's friction falling is ``test_rig_history``): away from
    its lower level, so no degradation, yet a change the prognosis says and the status watches. A steady η_O
    says nothing."""
    hours = [0, 20, 40, 60, 80, 100, 120, 140]
    for etas, said in (([0.80, 0.81, 0.82, 0.83, 0.84, 0.85, 0.86, 0.87], True), ([0.85] * 8, False)):
        stored = [
            s.model_copy(
                update={"estimates": s.estimates.model_copy(update={"eta_O": parameter(e, 2e-3, 0.85, unit="1")})}
            )
            for s, e in zip(_history(base, [0.05] * 8, flight_hours=hours), etas, strict=True)
        ]
        prognosis = prognose("a", stored, THESIS)
        away = [n for n in prognosis.notes if n.code == "moving_away" and n.parameter == "eta_O"]
        assert prognosis.remaining_life["eta_O"].status == "no degradation detected"
        assert bool(away) == said and all("eta_O rises by" in n.text and "thresholds." not in n.text for n in away)
        status, _, reason = status_of(stored[-1], prognosis, THESIS, len(stored))
        assert (status == "watch" and "eta_O" in reason) == said


def test_a_friction_that_rises_away_from_its_only_level_below_names_the_level_above(base):
    """A document with a lower FDJ level only (no nominal, so no default upper one): a rise is the change the
    note says, and the level it names is the upper one, in the kind's unit."""
    from pathlib import Path

    from ema.model.actuator import read_actuator

    servo = read_actuator(Path(__file__).resolve().parents[2] / "examples" / "emps" / "actuator.json")
    below = servo.model_copy(update={"thresholds": servo.thresholds.model_copy(update={"fdj_below_n": 0.04})})
    stored = _history(base, [0.050, 0.052, 0.054, 0.056, 0.058, 0.060], flight_hours=[0, 20, 40, 60, 80, 100])
    prognosis = prognose("a", stored, below)
    away = [n for n in prognosis.notes if n.code == "moving_away"]
    assert prognosis.remaining_life["FDJ"].direction == "below" and len(away) == 1
    assert "FDJ rises by" in away[0].text and "a level above (thresholds.fdj_above_n)" in away[0].text
