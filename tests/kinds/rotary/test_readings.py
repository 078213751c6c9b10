"""Two readings of one window: an effect is adopted only where its rivals agree with it within the stds."""

from types import SimpleNamespace

import pytest

from ema.kinds.rotary import readings
from ema.kinds.rotary.readings import Contest, settled
from ema.kinds.rotary.selection import Chosen

BEFORE = {"FDJ": 0.050, "eta_O": 0.80}
STDS = {"FDJ": 0.001, "eta_O": 0.01}


def _evidence(name: str) -> SimpleNamespace:
    family = SimpleNamespace(name=name)
    return SimpleNamespace(family=family, grid=None)


@pytest.fixture
def fake_readings(monkeypatch):
    values = {}

    def reading(_measured, terms, _bias):
        return values[terms[-1].family.name]

    monkeypatch.setattr(readings, "reading", reading)
    return values


def test_rivals_that_agree_within_the_stds_let_the_effect_in(fake_readings):
    fake_readings.update(inertia={"FDJ": 0.0520, "eta_O": 0.78}, current_sensor_gain={"FDJ": 0.0521, "eta_O": 0.79})
    pick = _evidence("inertia")
    contests = {"inertia": Contest(pick, [_evidence("current_sensor_gain")])}
    kept, ambiguity = settled(None, [Chosen(pick.family, None)], contests, {}, (BEFORE, STDS))
    assert [c.family.name for c in kept] == ["inertia"] and ambiguity is None


def test_rivals_that_read_the_window_elsewhere_keep_the_base_with_stds_holding_both(fake_readings):
    fake_readings.update(inertia={"FDJ": 0.058, "eta_O": 0.79}, current_sensor_gain={"FDJ": 0.046, "eta_O": 0.81})
    pick = _evidence("inertia")
    contests = {"inertia": Contest(pick, [_evidence("current_sensor_gain")])}
    kept, ambiguity = settled(None, [Chosen(pick.family, None)], contests, {}, (BEFORE, STDS))
    assert kept == [] and ambiguity is not None
    assert ambiguity.effects == ["inertia", "current_sensor_gain"] and "end stop" in ambiguity.tell_apart
    for reading in ambiguity.readings.values():  # the base estimate's ±2 std now holds every reading
        assert all(abs(reading[t] - BEFORE[t]) <= 2 * ambiguity.stds_after[t] + 1e-12 for t in BEFORE)
