"""One bad window, one slow client or one lost disk never breaks the service for everyone (in-process)."""

import os
import stat
import time
import urllib.parse

import pytest
from fastapi.testclient import TestClient

from ema.estimate.documents import parameter
from ema.history.open import open_history
from ema.history.refusals import StorageError
from ema.kinds.rotary.pipeline import estimate_window
from ema.kinds.rotary.synthetic import synthetic_window
from ema.model.actuator import THESIS
from ema.model.params import HealthParams
from ema.service.main import create_app
from tests.service.conftest import LOCAL, SMALL, settings_for, settled


@pytest.fixture(scope="module")
def base():
    return estimate_window(synthetic_window(HealthParams.single(), seed=1, duration_s=0.1), SMALL, actuator=THESIS)


def _copy(base, actuator_id: str, window_id: str, hours: float, fdj: float = 0.05):
    estimates = base.estimates.model_copy(update={"FDJ": parameter(fdj, 3e-4, 0.05, unit="N·m")})
    window = base.window.model_copy(update={"flight_hours": hours, "content_sha256": f"{actuator_id}#{window_id}"})
    return base.model_copy(
        update={"actuator_id": actuator_id, "window_id": window_id, "estimates": estimates, "window": window}
    )


def test_times_a_trend_cannot_use_are_refused_at_intake(client, document):
    for field, value in [("flight_hours", 1e150), ("flight_hours", -1.0), ("recorded_at", "1900-01-01T00:00:00Z")]:
        answer = client.post("/v1/estimate", json={**document, "window_id": f"bad-{field}", field: value})
        assert answer.status_code == 422 and answer.json()["detail"][0]["loc"] == ["body", field], answer.text


@pytest.mark.filterwarnings("ignore::RuntimeWarning")  # hours of 1e150 overflow the trend's fit: the point
def test_one_actuators_failed_prognosis_is_its_own_row_not_the_fleets_500(tmp_path, base):
    settings = settings_for(tmp_path)
    store = open_history(settings.database)
    for i, hours in enumerate([0.0, 1e150, 2e150, 3e150, 4e150]):  # stored past the intake's bounds
        store.add(_copy(base, "broken/elevator", f"w{i}", hours))
    for i in range(5):
        store.add(_copy(base, "fine/elevator", f"w{i}", 20.0 * i))
    store.close()
    with TestClient(create_app(settings), base_url=LOCAL) as client:
        settled(client)
        page = client.get("/ui")
        assert page.status_code == 200 and "fine/elevator" in page.text and "prognosis failed" in page.text
        listed = {line["actuator_id"]: line["status"] for line in client.get("/v1/actuators").json()}
        assert listed["broken/elevator"] == "prognosis failed" and listed["fine/elevator"] != "prognosis failed"
        prognosis = client.get("/v1/actuators/broken/elevator/prognosis")
        assert prognosis.status_code == 200 and prognosis.json()["notes"][0]["code"] == "prognosis_failed"


def test_a_stored_window_is_withdrawn_and_the_record_of_it_kept(client, document):
    assert client.post("/v1/estimate", json=document).status_code == 200
    path = f"/v1/actuators/{document['actuator_id']}/estimates/{urllib.parse.quote(document['window_id'])}"
    gone = client.delete(path, params={"reason": "logged on the wrong actuator"})
    assert gone.status_code == 200 and gone.json()["reason"] == "logged on the wrong actuator"
    assert client.delete(path).status_code == 404
    history = client.get(f"/v1/actuators/{document['actuator_id']}/estimates").json()
    assert history["estimates"] == [] and [w["window_id"] for w in history["withdrawn"]] == [document["window_id"]]
    again = client.post("/v1/estimate", json=document)  # a retry, a replay: the window stays withdrawn
    assert again.status_code == 410 and again.json()["withdrawal"]["reason"] == "logged on the wrong actuator"
    history = client.get(f"/v1/actuators/{document['actuator_id']}/estimates").json()
    assert history["estimates"] == [] and len(history["withdrawn"]) == 1


@pytest.fixture
def no_pipeline(monkeypatch):
    """A pipeline that must not run: the refusal comes before any work."""

    def refused(*_, **__):
        raise AssertionError("the pipeline ran")

    monkeypatch.setattr("ema.kinds.estimate", refused)


def test_a_history_deleted_under_the_service_answers_nothing_it_would_lose(tmp_path, document, no_pipeline):
    settings = settings_for(tmp_path)
    with TestClient(create_app(settings), base_url=LOCAL) as client:
        for suffix in ("", "-wal", "-shm"):
            (tmp_path / f"history.sqlite3{suffix}").unlink(missing_ok=True)
        answer = client.post("/v1/estimate", json=document)
        assert answer.status_code == 503 and "deleted" in answer.json()["detail"]
        health = client.get("/healthz").json()
        assert health["status"] == "degraded" and "deleted" in health["storage"]


def test_a_file_that_is_no_history_is_refused_before_anything_about_it_changes(tmp_path):
    text = tmp_path / "passwd"
    text.write_text("root:x:0:0:root:/root:/bin/bash\n")
    text.chmod(0o644)
    with pytest.raises(StorageError, match="not an SQLite database"):
        open_history(text)
    assert stat.S_IMODE(text.stat().st_mode) == 0o644 and text.read_text().startswith("root:")
    import sqlite3

    other = tmp_path / "other.db"
    with sqlite3.connect(other) as connection:
        connection.execute("CREATE TABLE invoices (id INTEGER)")
    other.chmod(0o644)
    with pytest.raises(StorageError, match="another program's tables"):
        open_history(other)
    assert stat.S_IMODE(other.stat().st_mode) == 0o644


def test_a_read_only_history_is_refused_at_start_and_when_it_becomes_so(tmp_path, document, no_pipeline):
    path = tmp_path / "history.sqlite3"
    open_history(path).close()
    path.chmod(0o400)
    with pytest.raises(StorageError, match="read-only"):
        open_history(path)
    path.chmod(0o600)
    with TestClient(create_app(settings_for(tmp_path)), base_url=LOCAL) as client:
        path.chmod(0o400)
        answer = client.post("/v1/estimate", json=document)
        assert answer.status_code == 503 and "read-only" in answer.json()["detail"]


def test_a_full_disk_refuses_new_work_before_the_pipeline(tmp_path, document, no_pipeline):
    free = os.statvfs(tmp_path).f_bavail * os.statvfs(tmp_path).f_frsize
    with TestClient(create_app(settings_for(tmp_path, min_free_bytes=free * 2)), base_url=LOCAL) as client:
        answer = client.post("/v1/estimate", json=document)
        assert answer.status_code == 503 and "MB free" in answer.json()["detail"]


@pytest.mark.parametrize("bad", ["a\x00b", "tail-1/\u202eleft", "x" * 10_000, " padded"])
def test_a_path_id_follows_the_windows_rule(client, bad):
    answer = client.put(f"/v1/actuators/{urllib.parse.quote(bad)}", json=THESIS.model_dump(by_alias=True))
    assert answer.status_code == 422 and answer.json()["detail"][0]["loc"] == ["path", "actuator_id"]


def test_links_carry_the_id_url_encoded(tmp_path, base):
    settings = settings_for(tmp_path)
    store = open_history(settings.database)
    store.add(_copy(base, "tail-1/elev?x=1#top", "w0", 0.0))
    store.close()
    with TestClient(create_app(settings), base_url=LOCAL) as client:
        settled(client)
        page = client.get("/ui").text
        assert 'href="/ui/actuators/tail-1/elev%3Fx%3D1%23top"' in page
        assert client.get("/ui/actuators/tail-1/elev%3Fx%3D1%23top").status_code == 200


def test_a_compressed_body_is_refused_as_such(client, document):
    answer = client.post(
        "/v1/estimate", content=b"\x1f\x8b...", headers={"content-type": "application/json", "content-encoding": "gzip"}
    )
    assert answer.status_code == 415 and answer.json()["detail"][0]["loc"] == ["header", "content-encoding"]


def test_the_fleet_page_is_served_from_kept_lines_a_page_at_a_time(tmp_path, base, monkeypatch):
    """600 actuators of 2 windows: the keeper computes every line once, in the background, one at a time; a page
    never computes one; the lines are paged. (The probe's timings: ``benchmarks.robustness_probe``.)"""
    import ema.service.view as view

    settings = settings_for(tmp_path)
    store = open_history(settings.database)
    for a in range(600):
        for w in range(2):
            store.add(_copy(base, f"tail-{a // 4}/ema-{a % 4}", f"w{w}", 10.0 * w))
    store.close()
    computed = []
    original = view.refreshed
    monkeypatch.setattr(
        view, "refreshed", lambda store, stale, *rest: computed.append(len(stale)) or original(store, stale, *rest)
    )
    with TestClient(create_app(settings), base_url=LOCAL) as client:
        settled(client)
        first = client.get("/ui")
        again = client.get("/ui", params={"page": 3})
        tail = client.get("/ui", params={"tail": "tail-7/", "status": "not enough history"})
    assert computed == [1] * 600
    assert first.status_code == again.status_code == 200 and "600 actuator(s)" in first.text
    assert 'class="pending"' not in again.text and "page 3 of 12" in again.text
    assert "4 actuator(s)" in tail.text and "tail-7/ema-3" in tail.text


def test_pages_read_the_history_once_a_while_and_after_a_store(tmp_path, base, monkeypatch):
    """Viewers reloading share one reading of the fleet's lines: read again once it is ``VIEW_MAX_AGE_S`` old or
    this service stored something, never once a page."""
    import ema.service.view as view

    store = open_history(tmp_path / "h.sqlite3")
    store.add(_copy(base, "tail-1/elevator", "w0", 0.0))
    reads = []
    monkeypatch.setattr(view, "fleet_lines", lambda store: reads.append(1) or view.Lines([], []))
    fleet = view.FleetView(store)
    for _ in range(20):
        fleet.lines()
    assert len(reads) == 1
    fleet.out_of_date()
    fleet.lines()
    assert len(reads) == 2
    monkeypatch.setattr(view, "VIEW_MAX_AGE_S", 0.0)
    fleet.lines()
    assert len(reads) == 3
    store.close()


def test_a_route_shaped_actuator_id_is_refused_before_it_can_be_stored(client, document):
    put = client.put("/v1/actuators/sh/estimates", json=THESIS.model_dump(by_alias=True))
    assert put.status_code == 422 and put.json()["detail"][0]["loc"] == ["path", "actuator_id"]
    posted = client.post("/v1/estimate", json={**document, "actuator_id": "sh/prognosis"})
    assert posted.status_code == 422 and posted.json()["detail"][0]["loc"] == ["body", "actuator_id"]


def _lines_settle(store, within_s: float) -> bool:
    from ema.service.view import kept_lines

    deadline = time.monotonic() + within_s
    while kept_lines(store)[1] and time.monotonic() < deadline:
        time.sleep(0.02)
    return not kept_lines(store)[1]


def test_a_line_kept_by_other_rules_is_brought_up_to_date(tmp_path, base, monkeypatch):
    """After an upgrade that changes how a line is computed, a kept line is out of date as if a window had come: the
    fleet view never shows a status the actuator's own page (computed now) contradicts."""
    import ema.service.view as view
    from ema.service.jobs import JobRunner

    store = open_history(tmp_path / "h.sqlite3")
    store.add(_copy(base, "tail-1/elevator", "w0", 0.0))
    keeper = view.LineKeeper(store, JobRunner(max_queue=1, queue_timeout_s=1.0), view.FleetView(store))
    keeper.start()
    try:
        assert _lines_settle(store, within_s=10.0)
        monkeypatch.setattr(view, "rules", lambda: "another ema")
        assert [line[0] for line in view.kept_lines(store)[1]] == ["tail-1/elevator"]
        keeper.poke()
        assert _lines_settle(store, within_s=10.0)
        assert store.summaries()["tail-1/elevator"][0].endswith(":another ema")
    finally:
        keeper.stop()
        store.close()


def test_the_keeper_yields_every_line_to_a_job_and_to_a_pause_after_it(tmp_path, base):
    """The fleet's lines are the keeper's work, done only once no job has run or waited for a moment
    (docs/service.md): a client posting one window after another has the cores between its posts."""
    from ema.service.jobs import JobRunner
    from ema.service.view import KEEPER_QUIET_S, FleetView, LineKeeper, kept_lines

    store = open_history(tmp_path / "h.sqlite3")
    store.add(_copy(base, "tail-1/elevator", "w0", 0.0))
    runner = JobRunner(max_queue=1, queue_timeout_s=1.0)
    runner.admitted = 1  # a job holds its place
    keeper = LineKeeper(store, runner, FleetView(store))
    keeper.start()
    try:
        time.sleep(0.5)
        assert kept_lines(store)[1] != []  # nothing computed beside the job
        runner.admitted, runner.last_busy = 0, time.monotonic()  # the job ended just now
        assert not _lines_settle(store, within_s=KEEPER_QUIET_S * 0.6)  # still nothing: a next post may come
        assert _lines_settle(store, within_s=5.0)
    finally:
        keeper.stop()
        store.close()


def test_a_stream_without_a_pause_still_gets_its_lines(tmp_path, base, monkeypatch):
    from ema.service import view
    from ema.service.jobs import JobRunner

    monkeypatch.setattr(view, "KEEPER_MAX_WAIT_S", 0.3)
    store = open_history(tmp_path / "h.sqlite3")
    store.add(_copy(base, "tail-1/elevator", "w0", 0.0))
    runner = JobRunner(max_queue=1, queue_timeout_s=1.0)
    runner.admitted = 1  # jobs, one after another, for ever
    keeper = view.LineKeeper(store, runner, view.FleetView(store))
    keeper.start()
    try:
        assert _lines_settle(store, within_s=5.0)
    finally:
        keeper.stop()
        store.close()


def test_a_full_queue_says_what_holds_its_places():
    from ema.service.jobs import JobRunner, OverloadedError

    runner = JobRunner(max_queue=4, queue_timeout_s=1.0)
    runner.admitted = 5
    with pytest.raises(OverloadedError) as full:
        runner.admit()
    assert "all 5 places are taken: 0 job(s) running, 5 waiting for a slot or storing an answer" in str(full.value)


def test_a_line_that_cannot_be_computed_is_its_own_and_the_others_still_come(tmp_path, base, monkeypatch):
    """One actuator's line failing (its numbers, its document) is said on that line; the keeper's pass goes on to
    the next actuator rather than stopping there for ever."""
    from ema.service import view
    from ema.service.jobs import JobRunner

    store = open_history(tmp_path / "h.sqlite3")
    for name in ("tail-1/elevator", "tail-2/elevator"):
        store.add(_copy(base, name, "w0", 0.0))
    original = view.summary

    def summary(prognosis, *rest):
        if prognosis.actuator_id == "tail-1/elevator":
            raise ValueError("a number out of its range")
        return original(prognosis, *rest)

    monkeypatch.setattr(view, "summary", summary)
    keeper = view.LineKeeper(store, JobRunner(max_queue=1, queue_timeout_s=1.0), view.FleetView(store))
    keeper.start()
    try:
        assert _lines_settle(store, within_s=10.0)
        lines = {line.actuator_id: line for line in view.kept_lines(store)[0].values()}
    finally:
        keeper.stop()
        store.close()
    assert (
        lines["tail-1/elevator"].status == "prognosis failed" and "out of its range" in lines["tail-1/elevator"].reason
    )
    assert lines["tail-2/elevator"].status == "not enough history"
