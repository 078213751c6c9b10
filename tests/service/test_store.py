"""The history file: idempotent, private, checked at start, migrated from the earlier format."""

import json
import sqlite3
import stat

import pytest

from ema.estimate.documents.window_facts import SensorZero
from ema.history.open import open_history
from ema.history.refusals import StorageError
from ema.kinds.rotary.pipeline import estimate_window
from ema.kinds.rotary.synthetic import synthetic_window
from ema.model.actuator import THESIS
from ema.model.params import HealthParams
from tests.service.conftest import SMALL


def _lent(history, actuator_id, flight_id):
    """What the stored windows lend a window of the thesis's actuator of ``flight_id``, as its kind reads them."""
    from ema.kinds import other_windows_lent

    return other_windows_lent(THESIS, history.lent_to(actuator_id, flight_id))


@pytest.fixture(scope="module")
def result():
    return estimate_window(synthetic_window(HealthParams.single(), seed=1, duration_s=0.1), SMALL, actuator=THESIS)


def test_one_row_per_window_and_the_repeat_is_a_replay(tmp_path, result):
    store = open_history(tmp_path / "h.sqlite3")
    first, again = store.add(result), store.add(result)
    assert not first.replay and again.replay and again.id == first.id
    current, legacy = store.history(result.actuator_id)
    assert [s.id for s in current] == [first.id] and legacy == []


def test_the_file_is_private(tmp_path, result):
    open_history(tmp_path / "h.sqlite3").add(result)
    assert stat.S_IMODE((tmp_path / "h.sqlite3").stat().st_mode) == 0o600


def test_a_file_others_could_read_is_made_private_with_a_warning(tmp_path, result, caplog):
    path = tmp_path / "h.sqlite3"
    open_history(path).close()
    path.chmod(0o644)
    with caplog.at_level("WARNING", logger="ema.history"):
        open_history(path).close()
    assert stat.S_IMODE(path.stat().st_mode) == 0o600 and "made private" in caplog.text


def test_another_window_under_a_stored_key_is_a_conflict_and_an_old_row_a_replay(tmp_path, result):
    from ema.history.refusals import ConflictError

    store = open_history(tmp_path / "h.sqlite3")
    store.add(result)
    other = result.model_copy(update={"window": result.window.model_copy(update={"content_sha256": "f" * 64})})
    with pytest.raises(ConflictError, match=result.window_id):
        store.add(other)
    with pytest.raises(ConflictError):
        store.get(result.actuator_id, result.window_id, "f" * 64)
    assert store.get(result.actuator_id, result.window_id, result.window.content_sha256).replay
    with sqlite3.connect(tmp_path / "h.sqlite3") as old:  # a row stored before digests: taken as the window's
        old.execute("UPDATE estimates SET content_sha256 = NULL")
    assert store.get(result.actuator_id, result.window_id, "f" * 64).replay


def test_a_file_that_is_not_a_database_is_refused_naming_it(tmp_path):
    broken = tmp_path / "broken.sqlite3"
    broken.write_bytes(b"this is not sqlite" * 100)
    with pytest.raises(StorageError) as error:
        open_history(broken)
    assert error.value.path == broken
    assert broken.read_bytes().startswith(b"this is not sqlite")  # refused, never replaced


def test_a_round_one_history_is_migrated_and_nothing_is_lost(tmp_path, result):
    path = tmp_path / "old.sqlite3"
    old = sqlite3.connect(path)
    old.executescript(
        "CREATE TABLE estimates (id INTEGER PRIMARY KEY AUTOINCREMENT, actuator_id TEXT NOT NULL, "
        "window_id TEXT NOT NULL, stored_at TEXT NOT NULL, result TEXT NOT NULL);"
    )
    legacy = {"schema": "ema-estimate/1", "estimates": {"FDJ": {"value": 0.05}}, "window_id": "w"}
    rows = [("a", "w", "2026-11-01T00:00:00+00:00", json.dumps(legacy))] * 2  # round 1 stored duplicates
    rows.append(("a", "w2", "2026-11-02T00:00:00+00:00", result.model_dump_json(by_alias=True)))
    old.executemany("INSERT INTO estimates (actuator_id, window_id, stored_at, result) VALUES (?, ?, ?, ?)", rows)
    old.commit()
    old.close()
    store = open_history(path)
    current, kept = store.history("a")
    assert len(current) == 1 and len(kept) == 1  # one row per window, the old format returned as stored
    assert sqlite3.connect(path).execute("SELECT count(*) FROM estimates_v1").fetchone()[0] == 3


def test_the_sensor_zero_is_the_most_precise_of_the_actuators_flight(tmp_path, result):
    store = open_history(tmp_path / "h.sqlite3")

    def stored(actuator_id: str, window_id: str, flight_id: str | None, std: float | None) -> None:
        zero = None if std is None else SensorZero(window_id=window_id, hinge_nm=0.0, current_a=std, torque_std_nm=std)
        window = result.window.model_copy(update={"flight_id": flight_id, "sensor_zero": zero})
        store.add(result.model_copy(update={"actuator_id": actuator_id, "window_id": window_id, "window": window}))

    for args in [
        ("a", "w1", "f", 3e-4),
        ("a", "w2", "f", 1e-4),
        ("a", "w3", "f", None),
        ("a", "w4", "g", 1e-5),
        ("b", "w5", "f", 1e-6),
        ("a", "w6", None, 1e-6),
    ]:
        stored(*args)
    assert _lent(store, "a", "f").sensor_zero.window_id == "w2"
    assert _lent(store, "a", "g").sensor_zero.window_id == "w4"
    assert _lent(store, "a", "h").sensor_zero is None and _lent(store, "c", "f").sensor_zero is None
    assert _lent(store, "a", None).sensor_zero is None
