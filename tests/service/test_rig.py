"""The real rig through the service: its learned document stored, its runs posted in the order they were logged,
and the friction rising in its prognosis and on the operator's page."""

from fastapi.testclient import TestClient

from ema.calibration.linear_report import calibrate_linear
from ema.model.window import window_to_dict
from ema.service.main import create_app
from tests.estimate.test_ballscrew import DOCUMENT, runs
from tests.service.conftest import LOCAL, settings_for


def test_runs_posted_in_order_show_the_friction_rising(tmp_path):
    _, learned, _ = calibrate_linear(runs("normal", 20, range(5)) + runs("normal", 40, range(5)), DOCUMENT)
    assert learned is not None
    ordered = runs("normal", 20, range(5, 10)) + runs("lackLubrication1", 20, range(10))
    with TestClient(create_app(settings_for(tmp_path, ui_budget_s=60.0)), base_url=LOCAL) as client:
        actuator_id = ordered[0].actuator_id
        stored = client.put(f"/v1/actuators/{actuator_id}", json=learned.model_dump(mode="json", by_alias=True))
        assert stored.status_code == 200, stored.text
        for window in ordered:
            answer = client.post("/v1/estimate", json=window_to_dict(window))
            assert answer.status_code == 200, answer.text
            assert answer.json()["stages"]["learn"].startswith("skipped")
        prognosis = client.get(f"/v1/actuators/{actuator_id}/prognosis").json()
        trend = prognosis["trends"]["FDJ"]
        assert prognosis["time_unit"] == "windows" and trend["slope_per_unit"] > 2 * trend["slope_std"]
        page = client.get(f"/ui/actuators/{actuator_id}")
        assert page.status_code == 200 and page.text.count("<svg") == 1  # FDJ alone: η_O is not read at one load
