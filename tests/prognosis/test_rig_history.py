"""A real rig's history (Ruiz-Carcel and Starr 2018; Cranfield CORD 5097649): a spalled screw loses its preload
and its friction falls, away from the level above that its remaining life watches. The history says so, and the
status asks for a look; healthy runs logged apart say nothing."""

from pathlib import Path

import pytest

from ema.kinds import estimate
from ema.kinds.linear.calibration_report import calibrate_linear
from ema.model.actuator import read_actuator
from ema.model.logmap import read_logmap, read_mapped
from ema.model.window import window_from_dict
from ema.prognosis.documents import Stored
from ema.prognosis.prognose import prognose
from ema.prognosis.status import status_of

RIG = Path(__file__).resolve().parents[2] / "examples" / "ballscrew-rig"


def _runs(state: str, load: int, numbers: range) -> list:
    paths = sorted((RIG / "runs").glob(f"{state}_load{load}_run*.csv"))
    return [window_from_dict(read_mapped(paths[n], read_logmap(RIG / "log-map.json"))) for n in numbers]


@pytest.fixture(scope="module")
def document():
    """The drive learned on half the healthy runs at each load; the histories read the other half."""
    healthy = _runs("normal", 20, range(5)) + _runs("normal", 40, range(5))
    return calibrate_linear(healthy, read_actuator(RIG / "actuator.json"))[1]


def _stored(windows: list, document) -> list[Stored]:
    """Each window's estimate as the history stores it, in the order given (the runs carry no time)."""
    return [
        Stored(**estimate(w, actuator=document).model_dump(by_alias=True), id=i, stored_at="2026-11-27T00:00:00+00:00")
        for i, w in enumerate(windows)
    ]


def test_a_friction_that_falls_is_a_change_the_history_says_and_the_status_watches(document):
    stored = _stored(_runs("normal", 40, range(5, 10)) + _runs("spalling8", 40, range(10)), document)
    prognosis = prognose("rig", stored, document)
    life = prognosis.remaining_life["FDJ"]
    assert life.direction == "above" and life.status == "no degradation detected"
    away = [n for n in prognosis.notes if n.code == "moving_away"]
    assert [n.parameter for n in away] == ["FDJ"] and "FDJ falls by" in away[0].text
    assert "thresholds.fdj_below_nm" in away[0].text
    assert (
        prognosis.life_status("FDJ") == "no degradation detected towards the level above; moving away from it: a change"
    )
    status, _, reason = status_of(stored[-1], prognosis, document, len(stored))
    assert status == "watch" and "FDJ moves away" in reason


def test_a_level_below_makes_the_fall_a_crossing(document):
    """With a lower level in the document, between the healthy runs and the spalled ones, the fall crosses it."""
    thresholds = document.thresholds.model_copy(update={"fdj_below_nm": 0.55})
    lower = document.model_copy(update={"thresholds": thresholds})
    stored = _stored(_runs("normal", 40, range(5, 10)) + _runs("spalling8", 40, range(10)), lower)
    prognosis = prognose("rig", stored, lower)
    life = prognosis.remaining_life["FDJ"]
    assert (life.direction, life.status) == ("below", "already crossed")
    assert not [n for n in prognosis.notes if n.code == "moving_away"]
    assert status_of(stored[-1], prognosis, lower, len(stored))[0] == "due"


def test_healthy_runs_at_two_loads_move_nowhere(document):
    stored = _stored(_runs("normal", 40, range(5, 10)) + _runs("normal", 20, range(5, 10)), document)
    prognosis = prognose("rig", stored, document)
    assert prognosis.remaining_life["FDJ"].status == "no degradation detected"
    assert not [n for n in prognosis.notes if n.code == "moving_away"]
    assert prognosis.life_status("FDJ") == "no degradation detected"
    assert status_of(stored[-1], prognosis, document, len(stored))[0] == "healthy"
