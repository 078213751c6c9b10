"""One contract for every history: SQLite and PostgreSQL pass the same tests (``setting`` runs each on both)."""

import concurrent.futures
import contextlib
import json

import pytest

from ema.estimate.documents.window_facts import SensorZero
from ema.history.open import open_history
from ema.history.refusals import ConflictError, StorageError
from ema.model.actuator import THESIS


def _lent(history, actuator_id, flight_id):
    """What the stored windows lend a window of the thesis's actuator of ``flight_id``, as its kind reads them."""
    from ema.kinds import other_windows_lent

    return other_windows_lent(THESIS, history.lent_to(actuator_id, flight_id))


def _as(result, actuator_id: str, window_id: str, **window):
    info = result.window.model_copy(update={"content_sha256": f"{actuator_id}#{window_id}", **window})
    return result.model_copy(update={"actuator_id": actuator_id, "window_id": window_id, "window": info})


def test_one_row_per_window_and_the_repeat_is_a_replay(history, result):
    first, again = history.add(result), history.add(result)
    assert not first.replay and again.replay and again.id == first.id
    current, legacy = history.history(result.actuator_id)
    assert [s.id for s in current] == [first.id] and legacy == []


def test_another_window_under_a_stored_key_is_a_conflict(history, result):
    history.add(result)
    other = result.model_copy(update={"window": result.window.model_copy(update={"content_sha256": "f" * 64})})
    with pytest.raises(ConflictError, match=result.window_id):
        history.add(other)
    with pytest.raises(ConflictError):
        history.get(result.actuator_id, result.window_id, "f" * 64)
    assert history.get(result.actuator_id, result.window_id, result.window.content_sha256).replay


def test_the_same_window_stored_at_once_from_many_threads_is_one_row(history, result):
    with concurrent.futures.ThreadPoolExecutor(8) as pool:
        stored = list(pool.map(lambda _: history.add(result), range(8)))
    assert len({s.id for s in stored}) == 1 and sum(not s.replay for s in stored) == 1
    assert len(history.history(result.actuator_id)[0]) == 1


def test_document_versions_never_collide_and_sixteen_writers_all_land(history):
    documents = [THESIS.model_copy(update={"name": f"variant {i}"}) for i in range(64)]
    with concurrent.futures.ThreadPoolExecutor(16) as pool:
        versions = [s.version for s in pool.map(lambda d: history.put_actuator("a/1", d), documents)]
    assert sorted(versions) == list(range(1, 65))
    assert history.put_actuator("a/1", history.get_actuator("a/1").document).version == 64  # the same: no new one


def test_a_withdrawn_window_leaves_the_history_and_its_record_stays(history, result):
    history.add(result)
    gone = history.withdraw(result.actuator_id, result.window_id, "wrong actuator")
    assert gone is not None and gone.reason == "wrong actuator"
    assert history.history(result.actuator_id)[0] == [] and history.withdraw(result.actuator_id, "x", "") is None
    assert [w.window_id for w in history.withdrawals(result.actuator_id)] == [result.window_id]
    assert result.actuator_id in history.actuator_ids()


def test_a_withdrawn_window_stays_withdrawn(history, result):
    from ema.history.refusals import WithdrawnError

    history.add(result)
    history.withdraw(result.actuator_id, result.window_id, "bad sensor")
    for again in (lambda: history.add(result), lambda: history.get(result.actuator_id, result.window_id)):
        with pytest.raises(WithdrawnError) as refused:
            again()
        assert refused.value.withdrawal.reason == "bad sensor" and "withdrawn" in str(refused.value)
    assert history.history(result.actuator_id)[0] == []


def test_the_sensor_zero_lent_is_the_most_precise_of_the_actuators_flight(history, result):
    for actuator_id, window_id, flight_id, std in [
        ("a", "w1", "f", 3e-4),
        ("a", "w2", "f", 1e-4),
        ("a", "w3", "f", None),
        ("a", "w4", "g", 1e-5),
        ("b", "w5", "f", 1e-6),
        ("a", "w6", None, 1e-6),
    ]:
        zero = None if std is None else SensorZero(window_id=window_id, hinge_nm=0.0, current_a=std, torque_std_nm=std)
        history.add(_as(result, actuator_id, window_id, flight_id=flight_id, sensor_zero=zero))
    assert _lent(history, "a", "f").sensor_zero.window_id == "w2"
    assert _lent(history, "a", "g").sensor_zero.window_id == "w4"
    assert _lent(history, "a", "h").sensor_zero is None and _lent(history, "c", "f").sensor_zero is None


def test_the_views_lookups_answer_every_actuator_at_once(history, result):
    for actuator_id in ("a", "b"):
        for i in range(3):
            history.add(_as(result, actuator_id, f"w{i}"))
    history.put_actuator("b", THESIS)
    versions = history.versions()
    assert versions["a"][0] == 3 and versions["b"][0] == 3 and versions["b"][2] == 1 and versions["a"][2] == 0
    latest = history.latest(["a", "b", "c"])
    assert sorted(latest) == ["a", "b"] and latest["a"].window_id == "w2"
    assert list(history.latest_documents(["a", "b"])) == ["b"]
    history.put_summary("a", "3:3:0", 4, None, "{}")
    history.put_summary("a", "3:4:0", 3, 1.5, "{}")
    assert history.summaries() == {"a": ("3:4:0", "{}")}


def test_a_setting_that_is_neither_path_nor_address_is_refused_naming_it(tmp_path):
    with pytest.raises(StorageError, match="mysql:// is no database"):
        open_history("mysql://ema@localhost/ema")
    assert not (tmp_path / "mysql:").exists()


def test_a_history_is_healthy_until_its_storage_goes(history):
    assert history.healthy() == (True, "ok")


def test_another_programs_estimates_table_is_refused_naming_the_database_never_altered(setting):
    import sqlalchemy as sa

    url = setting if "://" in setting else f"sqlite:///{setting}"
    engine = sa.create_engine(url.replace("postgresql://", "postgresql+psycopg://"))
    with engine.begin() as connection:
        connection.exec_driver_sql("CREATE TABLE estimates (id INTEGER PRIMARY KEY, price REAL)")
    with pytest.raises(StorageError) as refused:
        open_history(setting)
    assert "not an ema history" in refused.value.reason
    with engine.connect() as connection:  # the other program's table is as it was
        assert {c["name"] for c in sa.inspect(connection).get_columns("estimates")} == {"id", "price"}
    engine.dispose()


def test_what_was_stored_is_all_there_after_the_history_is_opened_again(setting, result):
    """Nothing a user stored is lost: windows (as stored, oldest first), documents and their versions, withdrawals
    and the kept fleet lines come back from another opening of the same database."""
    store = open_history(setting)
    stored = [store.add(_as(result, "tail-1", f"w{i}", recorded_at=f"2026-01-0{i + 1}T00:00:00Z")) for i in range(3)]
    store.put_actuator("tail-1", THESIS)
    second = store.put_actuator("tail-1", THESIS.model_copy(update={"name": "overhauled"}))
    store.withdraw("tail-1", "w1", "logged on the wrong aircraft")
    store.put_summary("tail-1", "2:3:2", 1, 40.0, '{"status": "healthy"}')
    store.close()
    again = open_history(setting)
    try:
        current, legacy = again.history("tail-1")
        assert [s.window_id for s in current] == ["w0", "w2"] and legacy == []
        assert [s.model_dump(exclude={"replay"}) for s in current] == [
            s.model_dump(exclude={"replay"}) for s in (stored[0], stored[2])
        ]
        assert again.get_actuator("tail-1") == second and second.version == 2
        assert [w.reason for w in again.withdrawals("tail-1")] == ["logged on the wrong aircraft"]
        assert again.summaries()["tail-1"] == ("2:3:2", '{"status": "healthy"}')
        assert again.versions()["tail-1"][0] == 2  # windows now held
    finally:
        again.close()


def test_the_latest_window_and_document_of_each_actuator_answer_together(history, result):
    for actuator_id, n in (("a/1", 3), ("b/2", 1)):
        for i in range(n):
            history.add(_as(result, actuator_id, f"w{i}"))
    history.put_actuator("a/1", THESIS)
    latest = history.latest(["a/1", "b/2", "c/3"])
    assert {k: v.window_id for k, v in latest.items()} == {"a/1": "w2", "b/2": "w0"}  # none for an unknown one
    assert set(history.latest_documents(["a/1", "b/2"])) == {"a/1"}
    assert sorted(history.actuator_ids()) == ["a/1", "b/2"]


def test_the_migrations_build_exactly_the_tables_the_code_declares(setting):
    """Alembic's comparison of a new history's tables with ``ema.history.tables``: no column, index or key
    that one has and the other lacks (the migrations are frozen; the declarations must follow them)."""
    import sqlalchemy as sa
    from alembic.migration import MigrationContext

    from ema.history.schema import upgrade
    from ema.history.tables import metadata

    address = setting if "://" in setting else f"sqlite:///{setting}"
    engine = sa.create_engine(address.replace("postgresql://", "postgresql+psycopg://", 1))
    try:
        upgrade(engine)
        with engine.connect() as connection:
            from alembic.autogenerate import compare_metadata

            differences = compare_metadata(MigrationContext.configure(connection), metadata)
    finally:
        engine.dispose()
    assert differences == []


def test_every_change_an_actuator_sees_moves_its_state_and_a_repeat_does_not(history, result):
    """The fleet view recomputes a line when its actuator's state moves (``ema.service.view``): a window stored
    or withdrawn, a new document. A replayed window or the same document again is no change."""
    steps = [
        (lambda: history.add(_as(result, "a", "w0")), True),
        (lambda: history.add(_as(result, "a", "w0")), False),  # a replay
        (lambda: history.add(_as(result, "a", "w1")), True),
        (lambda: history.put_actuator("a", THESIS), True),
        (lambda: history.put_actuator("a", THESIS), False),  # the same document: no new version
        (lambda: history.withdraw("a", "w0", "logged on another actuator"), True),
        (lambda: history.put_actuator("a", THESIS.model_copy(update={"name": "re-rigged"})), True),
    ]
    before = None
    for step, moves in steps:
        step()
        now = history.versions()["a"]
        assert (now != before) == moves, (now, before)
        before = now
    assert before[2] == 2  # the document's version


def _rig_windows_and_document():
    """The rig's healthy runs at two loads, and its bundled document."""
    from pathlib import Path

    from ema.model.actuator import read_actuator
    from ema.model.logmap import read_logmap, read_mapped
    from ema.model.window import window_from_dict

    rig = Path(__file__).resolve().parents[2] / "examples" / "ballscrew-rig"
    paths = sorted((rig / "runs").glob("normal_load[24]0_run*.csv"))
    windows = [window_from_dict(read_mapped(p, read_logmap(rig / "log-map.json"))) for p in paths]
    return windows, read_actuator(rig / "actuator.json")


def test_calibrations_come_back_whole_latest_first(history):
    from ema.kinds.linear.calibration_report import calibrate_linear

    windows, document = _rig_windows_and_document()
    reports = [calibrate_linear(windows[:n] + windows[-n:], document)[0] for n in (2, 3)]
    for report in reports:
        history.add_calibration("rig", report)
    stored = history.calibrations("rig")
    assert [r for _, r in stored] == reports[::-1] and history.calibrations("other") == []
    assert all(when for when, _ in stored)


@contextlib.contextmanager
def _migrating(setting):
    """A connection to the history at ``setting`` and an Alembic configuration of ema's migrations on it, committed
    when the block ends."""
    import sqlalchemy as sa
    from alembic.config import Config

    from ema.history.schema import MIGRATIONS

    address = setting if "://" in setting else f"sqlite:///{setting}"
    engine = sa.create_engine(address.replace("postgresql://", "postgresql+psycopg://", 1))
    try:
        with engine.connect() as connection:
            config = Config()
            config.set_main_option("script_location", str(MIGRATIONS))
            config.attributes["connection"] = connection
            yield connection, config
            connection.commit()
    finally:
        engine.dispose()


def test_a_round_three_history_upgraded_keeps_every_window_and_fills_its_lookups(setting, result):
    """A history round 3 left (its tables, windows stored as JSON only) opened by this ema: every window comes back
    as stored, and the lookups round 4 added (a flight's sensor zero) read from their JSON, more than the batch of
    rows the migration fills at once."""
    import sqlalchemy as sa
    from alembic import command

    from ema.history.migrations.versions import r4_lookups_withdrawals_summaries as r4

    n = r4.BATCH + 3
    zero = SensorZero(window_id="last", hinge_nm=0.0, current_a=1e-4, torque_std_nm=1e-4)  # in the second batch
    rows = [_as(result, "a", f"w{i}", flight_id="f", sensor_zero=zero if i == n - 1 else None) for i in range(n)]
    with _migrating(setting) as (connection, config):
        command.upgrade(config, "r3")
        table = sa.table("estimates", *(sa.column(c) for c in ("actuator_id", "window_id", "stored_at", "result")))
        connection.execute(
            table.insert(),
            [{"actuator_id": "a", "window_id": r.window_id, "stored_at": "2026-01-01T00:00:00Z",
              "result": r.model_dump_json(by_alias=True)} for r in rows],
        )  # fmt: skip
    store = open_history(setting)
    try:
        current, legacy = store.history("a")
        assert [s.window_id for s in current] == [r.window_id for r in rows] and legacy == []
        assert _lent(store, "a", "f").sensor_zero.window_id == "last"
    finally:
        store.close()


def test_a_calibration_stored_before_reports_named_their_kind_comes_back_as_its_kinds(history):
    """Reports were first stored with every kind's part in each (null or empty) and no ``kind``: they read as their
    kind's report, nothing lost, with no migration."""
    from ema.calibration.documents import LinearCalibration
    from ema.history.tables import calibrations
    from ema.kinds.linear.calibration_report import calibrate_linear

    windows, document = _rig_windows_and_document()
    report = calibrate_linear(windows, document)[0]
    written = report.model_dump(mode="json", by_alias=True)
    first_shape = {**{k: v for k, v in written.items() if k != "kind"}, "as_simulated": []}
    with history._writing() as connection:  # as an earlier ema wrote it
        row = calibrations.insert().values(actuator_id="rig", stored_at="then", report=json.dumps(first_shape))
        connection.execute(row)
    [(when, read)] = history.calibrations("rig")
    assert when == "then" and isinstance(read, LinearCalibration) and read == report


def test_the_lending_columns_renamed_go_back_and_forth_with_what_they_hold(setting, result):
    """Round 7's migration renames round 4's sensor_zero and inertia_read in place: down to r4 the loans sit in the
    old columns, up again in the new ones, nothing lost either way."""
    import sqlalchemy as sa
    from alembic import command

    zero = SensorZero(window_id="w1", hinge_nm=0.0, current_a=2e-4, torque_std_nm=2e-4)
    store = open_history(setting)
    try:
        store.add(_as(result, "a", "w1", flight_id="f", sensor_zero=zero))
    finally:
        store.close()
    with _migrating(setting) as (connection, config):
        command.downgrade(config, "r4")
        kept = connection.execute(sa.text("SELECT sensor_zero FROM estimates")).scalar_one()
        assert SensorZero.model_validate_json(kept) == zero
        command.upgrade(config, "head")
    store = open_history(setting)
    try:
        assert _lent(store, "a", "f").sensor_zero == zero
    finally:
        store.close()
