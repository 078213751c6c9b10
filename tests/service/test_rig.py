"""The real rig through the service: its learned document stored, its runs posted in the order they were logged,
and the friction rising in its prognosis and on the operator's page."""

import pytest
from fastapi.testclient import TestClient

from ema.kinds.linear.calibration_report import calibrate_linear
from ema.kinds.rotary.synthetic import synthetic_window
from ema.model.actuator import read_actuator
from ema.model.logmap import read_logmap, read_mapped
from ema.model.params import HealthParams
from ema.model.window import window_from_dict, window_to_dict
from ema.service.main import create_app
from tests.kinds.linear.test_ballscrew import DOCUMENT, runs
from tests.service.conftest import LOCAL, settings_for


@pytest.fixture(scope="module")
def learned():
    """The drive learned on half the healthy runs at each load; the histories post the other half."""
    _, document, _ = calibrate_linear(runs("normal", 20, range(5)) + runs("normal", 40, range(5)), DOCUMENT)
    assert document is not None
    return document


def _posted(client: TestClient, learned, ordered: list) -> str:
    """The learned document stored, then ``ordered`` posted one after another (each answered); the actuator's id."""
    actuator_id = ordered[0].actuator_id
    stored = client.put(f"/v1/actuators/{actuator_id}", json=learned.model_dump(mode="json", by_alias=True))
    assert stored.status_code == 200, stored.text
    for window in ordered:
        answer = client.post("/v1/estimate", json=window_to_dict(window))
        assert answer.status_code == 200, answer.text
        assert answer.json()["stages"]["learn"].startswith("skipped")
    return actuator_id


def test_runs_posted_in_order_show_the_friction_rising(tmp_path, learned):
    ordered = runs("normal", 20, range(5, 10)) + runs("lackLubrication1", 20, range(10))
    with TestClient(create_app(settings_for(tmp_path)), base_url=LOCAL) as client:
        actuator_id = _posted(client, learned, ordered)
        prognosis = client.get(f"/v1/actuators/{actuator_id}/prognosis").json()
        trend = prognosis["trends"]["FDJ"]
        assert prognosis["time_unit"] == "windows" and trend["slope_per_unit"] > 2 * trend["slope_std"]
        page = client.get(f"/ui/actuators/{actuator_id}")
        assert page.status_code == 200 and page.text.count("<svg") == 1  # FDJ alone: η_O is not read at one load


def test_runs_of_a_spalled_screw_show_the_friction_falling_under_its_heading(tmp_path, learned):
    """The fall is FDJ's: its note stands under FDJ's heading on the page, and the fleet's line watches it."""
    ordered = runs("normal", 40, range(5, 10)) + runs("spalling8", 40, range(10))
    with TestClient(create_app(settings_for(tmp_path)), base_url=LOCAL) as client:
        page = client.get(f"/ui/actuators/{_posted(client, learned, ordered)}").text
    fdj, rest = page.split("<h2>Notes of the latest windows</h2>")
    assert "moving_away" in fdj.split("<h2>FDJ")[1] and "moving_away" not in rest
    assert 'class="watch"' in page and "FDJ moves away from its failure level" in page
    assert 'class="title">FDJ: no degradation detected towards the level above; moving away' in page  # the plot


def test_a_linear_actuator_is_calibrated_through_the_service_as_through_the_cli(tmp_path):
    """Healthy runs teach the stored document's drive; the answer carries the completed document; two 13 s runs
    at 25 Hz simulate nothing, so neither the window limit nor the simulation budget refuses them."""
    healthy = runs("normal", 20, range(3)) + runs("normal", 40, range(1))
    body = {"windows": [window_to_dict(w) for w in healthy]}
    with TestClient(create_app(settings_for(tmp_path, max_window_s=4.0)), base_url=LOCAL) as client:
        actuator_id = healthy[0].actuator_id
        assert client.put(
            f"/v1/actuators/{actuator_id}", json=DOCUMENT.model_dump(mode="json", by_alias=True)
        ).is_success
        answer = client.post("/v1/calibrate", json=body)
        assert answer.status_code == 200, answer.text
        report = answer.json()
        assert report["completed_actuator"]["screw"]["current_per_nm_a"] > 0
        assert {entry["name"] for entry in report["learned"]} >= {"current_per_nm", "FDJ", "eta_O"}


def test_windows_of_another_kind_than_the_document_are_a_422_naming_the_signals(tmp_path):
    linear = {"windows": [window_to_dict(w) for w in runs("normal", 20, range(2))]}
    with TestClient(create_app(settings_for(tmp_path)), base_url=LOCAL) as client:
        unstored = client.post("/v1/calibrate", json=linear)  # no document stored: the default is a rotary one
        assert unstored.status_code == 422, unstored.text
        assert unstored.json()["detail"][0]["loc"] == ["body", "windows", "0", "signals"]
        actuator_id = runs("normal", 20, range(1))[0].actuator_id
        client.put(f"/v1/actuators/{actuator_id}", json=DOCUMENT.model_dump(mode="json", by_alias=True))
        rotary = synthetic_window(HealthParams.single(), seed=2, duration_s=0.1, actuator_id=actuator_id)
        answer = client.post("/v1/calibrate", json={"windows": [window_to_dict(rotary)]})
        assert answer.status_code == 422, answer.text
        assert answer.json()["detail"][0]["loc"] == ["body", "windows", "0", "signals"]


def test_the_service_holds_a_servo_log_to_its_window_limit(tmp_path):
    """A 24.8 s log at 1 kHz: a service's window limit, in seconds of log, holds for a servo as for any kind (over
    it, refused naming the setting); within it, answered."""
    from tests.kinds.servo.test_stages import EMPS

    window = window_from_dict(read_mapped(EMPS / "DATA_EMPS.mat", read_logmap(EMPS / "log-map.json")))
    document = read_actuator(EMPS / "actuator.json").model_dump(mode="json", by_alias=True)
    with TestClient(create_app(settings_for(tmp_path, max_window_s=4.0)), base_url=LOCAL) as client:
        assert client.put(f"/v1/actuators/{window.actuator_id}", json=document).is_success
        refused = client.post("/v1/estimate", json=window_to_dict(window))
        assert refused.status_code == 422 and "EMA_MAX_WINDOW_S" in refused.text
    with TestClient(create_app(settings_for(tmp_path, max_window_s=30.0)), base_url=LOCAL) as client:
        answer = client.post("/v1/estimate", json=window_to_dict(window))
        assert answer.status_code == 200, answer.text
        assert set(answer.json()["stages"].values()) == {"run"} and answer.json()["estimates"]["FDJ"]["unit"] == "N"
