"""The HTTP contract through TestClient: answers, stored history, errors naming fields."""

import json
import time

import pytest
from fastapi.testclient import TestClient

from ema.service.main import create_app
from tests.foreign.windows import Effects, draw, of_the_same_flight
from tests.service.conftest import KEY, LOCAL, SMALL, settings_for


def test_healthz_says_warm_and_storage_ok(client):
    health = client.get("/healthz").json()
    assert health["status"] == "ok" and health["warm"] is True and health["storage"] == "ok"


def test_estimate_answers_the_contract_and_is_stored(client, document):
    response = client.post("/v1/estimate", json=document)
    assert response.status_code == 200, response.text
    result = response.json()
    assert result["schema"] == "ema-estimate/1" and result["replay"] is False
    assert set(result["estimates"]) >= {"FDJ", "eta_O", "eta_A", "FSJ"}
    assert result["estimates"]["FDJ"]["std"] > 0
    assert set(result["timings_s"]) >= {"simulate", "train", "predict", "total"}
    assert result["dataset"]["n_simulations"] == SMALL.n_simulations
    history = client.get("/v1/actuators/ac-1/elev/estimates").json()
    assert [h["id"] for h in history["estimates"]] == [result["id"]]


def test_a_window_posted_twice_is_stored_once_and_answered_from_the_history(client, document):
    first = client.post("/v1/estimate", json=document).json()
    again = client.post("/v1/estimate", json=document).json()
    assert again["replay"] is True and again["id"] == first["id"]
    assert again["estimates"] == first["estimates"]
    assert len(client.get("/v1/actuators/ac-1/elev/estimates").json()["estimates"]) == 1


def test_a_window_moving_one_way_is_read_with_the_zero_its_flight_stored(client):
    """A 0.1 s gust moving one way, its current 0.2 A off: a cruise window of its flight, stored first, read it."""
    one_way = draw(318, "gust", duration_s=0.1, effects=Effects(current_bias_a=0.2))
    both = of_the_same_flight(one_way, 1318)
    for drawn, flight_id in ((both, "f-1"), (one_way, "f-1")):
        drawn.document.update(actuator_id="ac-9/elev", flight_id=flight_id)
    read = client.post("/v1/estimate", json=both.document).json()["window"]["sensor_zero"]
    torque_nm = read["hinge_nm"] / 500.0 + read["current_a"] * 0.0752  # at the motor shaft: gear, k_T
    assert torque_nm == pytest.approx(0.2 * 0.0752, rel=0.05)
    answered = client.post("/v1/estimate", json=one_way.document).json()
    assert answered["window"]["sensor_zero_from"] == both.document["window_id"]
    assert answered["window"]["current_offset_a"] == read["current_a"]
    other_flight = {**one_way.document, "flight_id": "f-2", "window_id": "other"}
    assert client.post("/v1/estimate", json=other_flight).json()["window"]["sensor_zero_from"] is None


def test_the_actuators_j_m_read_by_one_window_decides_for_another(client):
    """J_M 1.08x: a thesis window tells a heavier rotor from a weaker motor, a doublet cannot alone."""
    doublet = draw(403, "doublet", effects=Effects(inertia_factor=1.08))
    thesis = of_the_same_flight(doublet, 1403, "thesis", 0.5)
    for drawn in (thesis, doublet):
        drawn.document["actuator_id"] = "ac-8/elev"
    read = client.post("/v1/estimate", json=thesis.document).json()["window"]["inertia_read"]
    assert read["factor"] == pytest.approx(1.08, abs=0.003) and read["window_ids"] == [thesis.document["window_id"]]
    answered = client.post("/v1/estimate", json=doublet.document).json()["window"]
    assert answered["inertia_from"] == read["window_ids"]
    assert answered["inertia_factor"] == pytest.approx(1.08, abs=0.005)


def test_sizes_are_overridable_within_the_services_ceilings(client, document):
    ok = client.post("/v1/estimate?n_simulations=24&hidden_units=5", json=document)
    assert ok.status_code == 200 and ok.json()["dataset"]["n_simulations"] == 24
    too_big = client.post("/v1/estimate?n_simulations=4000", json={**document, "window_id": "w2"})
    assert too_big.status_code == 422
    assert too_big.json()["detail"][0]["loc"] == ["query", "n_simulations"]


def _set(document, path, value):
    target = document
    for key in path[:-1]:
        target = target[key]
    target[path[-1]] = value
    return document


@pytest.mark.parametrize(
    ("path", "value", "loc"),
    [
        (("signals", "current_a"), [0.0] * 10, ["body", "signals", "current_a"]),
        (("signals", "position_deg"), [50.0] * 1000, ["body", "signals", "position_deg"]),
        (("signals", "current_a"), [True] * 1000, ["body", "signals", "current_a"]),
        (("signals", "current_a"), ["1.5"] * 1000, ["body", "signals", "current_a"]),
        (("sample_rate_hz",), "10000", ["body", "sample_rate_hz"]),
        (("sample_rate_hz",), 5.0, ["body", "sample_rate_hz"]),
        (("flight_condition", "altitude_m"), 20_000.0, ["body", "flight_condition", "altitude_m"]),
        (("schema",), "ema-window/9", ["body", "schema"]),
        (("signals", "torque"), [0.0], ["body", "signals", "torque"]),
        (("actuator_id",), "tail\\n1", ["body", "actuator_id"]),
    ],
)
def test_bad_windows_get_422_naming_the_field(client, document, path, value, loc):
    if path == ("actuator_id",):
        value = "tail\n1"
    response = client.post("/v1/estimate", json=_set(document, path, value))
    assert response.status_code == 422
    assert response.json()["detail"][0]["loc"] == loc


def test_a_window_whose_signals_disagree_is_a_422_naming_the_field(client, document):
    document["signals"]["current_a"] = [-v for v in document["signals"]["current_a"]]
    response = client.post("/v1/estimate", json=document)
    assert response.status_code == 422
    assert response.json()["detail"][0]["loc"] == ["body", "signals", "current_a"]
    assert "sign" in response.json()["detail"][0]["msg"]


def test_a_current_in_other_units_is_a_422_naming_it(client, document):
    document["signals"]["current_a"] = [v / 10 for v in document["signals"]["current_a"]]
    response = client.post("/v1/estimate", json=document)
    assert response.status_code == 422
    assert response.json()["detail"][0]["loc"] == ["body", "signals", "current_a"]
    assert "other units" in response.json()["detail"][0]["msg"]


def test_unequal_lengths_nan_not_json_and_empty(client, document):
    document["signals"]["current_a"] = document["signals"]["current_a"][:-1]
    response = client.post("/v1/estimate", json=document)
    assert response.json()["detail"][0]["loc"] == ["body", "signals", "current_a"]
    raw = '{"schema": "ema-window/1", "actuator_id": "a", "window_id": "w", "sample_rate_hz": NaN}'
    response = client.post("/v1/estimate", content=raw, headers={"content-type": "application/json"})
    assert response.status_code == 422
    for body in ("{not json", "", b"\xff\xfe"):
        response = client.post("/v1/estimate", content=body, headers={"content-type": "application/json"})
        assert response.status_code == 422 and response.json()["detail"][0]["loc"] == ["body"]


def test_a_window_longer_than_the_budget_is_refused_at_once(tmp_path, document):
    with TestClient(create_app(settings_for(tmp_path, max_window_s=0.05)), base_url=LOCAL) as client:
        response = client.post("/v1/estimate", json=document)  # 0.1 s
    assert response.status_code == 422
    assert response.json()["detail"][0]["loc"] == ["body", "signals"]
    assert "EMA_MAX_WINDOW_S" in response.json()["detail"][0]["msg"]


def test_oversize_body_is_413_naming_the_body(tmp_path, document):
    with TestClient(create_app(settings_for(tmp_path, max_body_bytes=10_000)), base_url=LOCAL) as client:
        response = client.post("/v1/estimate", json=document)
    assert response.status_code == 413
    assert response.json()["detail"][0]["loc"] == ["body"]


def test_api_key_protects_v1_but_not_healthz(tmp_path):
    with TestClient(create_app(settings_for(tmp_path, api_key=KEY)), base_url="http://ema.example") as client:
        assert client.get("/healthz").status_code == 200
        assert client.get("/v1/actuators/x/estimates").status_code == 401
        assert client.get("/v1/actuators/x/estimates", headers={"x-api-key": "wrong"}).status_code == 401
        assert (
            client.get("/v1/actuators/x/estimates", headers={"x-api-key": KEY}).status_code == 404
        )  # past the key: nothing stored for x


def test_without_a_key_only_loopback_hosts_are_answered(tmp_path):
    with TestClient(create_app(settings_for(tmp_path)), base_url="http://evil.example") as client:
        response = client.get("/v1/actuators/x/estimates")
    assert response.status_code == 400 and response.json()["detail"][0]["loc"] == ["header", "host"]


def test_history_survives_a_restart(tmp_path, document):
    settings = settings_for(tmp_path)
    with TestClient(create_app(settings), base_url=LOCAL) as client:
        first = client.post("/v1/estimate", json=document).json()
        second = client.post("/v1/estimate", json={**document, "window_id": "w2"}).json()
    with TestClient(create_app(settings), base_url=LOCAL) as client:
        history = client.get("/v1/actuators/ac-1/elev/estimates").json()
        prognosis = client.get("/v1/actuators/ac-1/elev/prognosis").json()
    assert [h["id"] for h in history["estimates"]] == [first["id"], second["id"]]  # oldest first
    assert prognosis["trends"]["FDJ"]["n"] == 2
    assert prognosis["remaining_life"]["FDJ"]["status"] == "too few windows"
    assert "inertia" in prognosis  # a rotary actuator's prognosis answers its own part (RotaryPrognosis), null or not


def test_the_first_prognosis_of_a_new_actuator_is_a_level_with_no_slope(client, document):
    """One window, or windows at one time, hold no slope: a 200 that says so, never a 500 (0/0 stored as NaN)."""
    assert client.post("/v1/estimate", json={**document, "flight_hours": 12.0}).status_code == 200
    first = client.get("/v1/actuators/ac-1/elev/prognosis")
    assert first.status_code == 200, first.text
    trend = first.json()["trends"]["FDJ"]
    assert trend["n"] == 1 and trend["slope_std"] is None
    assert first.json()["remaining_life"]["FDJ"]["status"] == "too few windows"
    assert client.post("/v1/estimate", json={**document, "window_id": "w2", "flight_hours": 12.0}).status_code == 200
    second = client.get("/v1/actuators/ac-1/elev/prognosis")
    assert second.status_code == 200 and second.json()["trends"]["eta_O"]["slope_std"] is None


def test_another_body_under_a_stored_window_id_is_a_409_naming_both(client, document):
    first = client.post("/v1/estimate", json=document).json()
    current = [v + 0.01 for v in document["signals"]["current_a"]]
    other = {**document, "signals": {**document["signals"], "current_a": current}}
    response = client.post("/v1/estimate", json=other)
    assert response.status_code == 409
    detail = response.json()["detail"][0]
    assert detail["loc"] == ["body", "window_id"] and document["window_id"] in detail["msg"]
    assert first["window"]["content_sha256"][:12] in detail["msg"]
    assert client.post("/v1/estimate", json=document).json()["replay"] is True  # the same body: still a replay


def test_writes_are_json_only_and_never_from_another_origin(client, document):
    body = json.dumps(document)
    plain = client.post("/v1/estimate", content=body, headers={"content-type": "text/plain"})
    assert plain.status_code == 415 and plain.json()["detail"][0]["loc"] == ["header", "content-type"]
    foreign = client.post("/v1/estimate", json=document, headers={"origin": "http://evil.example"})
    assert foreign.status_code == 403 and foreign.json()["detail"][0]["loc"] == ["header", "origin"]
    hidden = client.post("/v1/estimate", content=body, headers={"content-type": "text/plain", "origin": "null"})
    assert hidden.status_code == 403
    assert client.get("/v1/actuators/ac-1/elev/estimates").status_code == 404  # nothing was stored
    own = client.post("/v1/estimate", json=document, headers={"origin": LOCAL})
    assert own.status_code == 200


def test_one_budget_covers_a_whole_calibration(client, document):
    """Four 10 s windows are each within the window budget, and far past one calibration's."""
    long = {**document, "sample_rate_hz": 1000.0}
    long["signals"] = {name: values * 10 for name, values in document["signals"].items()}  # 10 000 samples: 10 s
    started = time.perf_counter()
    response = client.post("/v1/calibrate", json={"windows": [long] * 4})
    assert response.status_code == 422 and time.perf_counter() - started < 5
    detail = response.json()["detail"][0]
    assert detail["loc"] == ["body", "windows"] and "EMA_MAX_CALIBRATE_S" in detail["msg"]


def test_calibrate_answers_the_report(client, document):
    response = client.post("/v1/calibrate", json={"windows": [document], "truth": {"FDJ": 0.055, "eta_O": 0.8}})
    assert response.status_code == 200, response.text
    report = response.json()
    assert report["schema"] == "ema-calibration/1"
    assert {"residual_rms_before", "candidates", "selected_effect", "error_before"} <= set(report)


def test_calibrate_bad_input_is_named(client, document):
    assert client.post("/v1/calibrate", json={"windows": []}).json()["detail"][0]["loc"] == ["body", "windows"]
    response = client.post("/v1/calibrate", json={"windows": [document], "truth": {"FDJ": -1, "eta_O": 0.8}})
    assert response.status_code == 422
    assert response.json()["detail"][0]["loc"] == ["body", "truth", "FDJ"]


def test_the_openapi_document_states_bodies_errors_and_bounds(client):
    spec = client.get("/openapi.json").json()
    post = spec["paths"]["/v1/estimate"]["post"]
    assert post["requestBody"]["content"]["application/json"]["schema"]["$ref"].endswith("/WindowDocument")
    assert {"401", "413", "422", "503"} <= set(post["responses"])
    rate = spec["components"]["schemas"]["WindowDocument"]["properties"]["sample_rate_hz"]
    assert rate["minimum"] == 10.0 and rate["maximum"] == 100000.0  # under 1 kHz: read quasi-statically
    seed = next(p for p in post["parameters"] if p["name"] == "seed")
    assert seed["schema"]["anyOf"][0]["maximum"] == 2**32 - 1
    assert client.get("/docs").status_code == 200 and "cdn" not in client.get("/docs").text


@pytest.mark.slow
def test_a_ground_station_fans_out_to_ray(tmp_path, document):
    settings = settings_for(tmp_path, backend="ray", ray_jobs=2)
    with TestClient(create_app(settings), base_url=LOCAL) as client:
        first = client.post("/v1/estimate", json=document)
        second = client.post("/v1/estimate", json={**document, "window_id": "w2"})
        hold = {**document, "window_id": "hold", "signals": {k: [0.0] * 1000 for k in document["signals"]}}
        refused = client.post("/v1/estimate", json=hold)
    assert first.status_code == second.status_code == 200
    # all zeros: no sensor logged anything (ema.kinds.rotary.prepare.consistency), named before any motion is looked for
    assert refused.status_code == 422 and refused.json()["detail"][0]["loc"] == ["body", "signals", "position_deg"]


def test_an_actuators_document_is_stored_versioned_and_read_with_its_windows(client):
    from tests.foreign.actuators import DRIVES, NOMINAL, document
    from tests.foreign.windows import Ground, draw

    path = "/v1/actuators/tail-7/elevator-right"
    assert client.get(path).status_code == 404
    first = client.put(path, json=document("heavier"))
    assert first.status_code == 200 and first.json()["version"] == 1
    assert client.put(path, json=document("heavier")).json()["version"] == 1  # the same document: nothing new
    stored = client.get(path).json()
    assert stored["document"]["drive"]["gear_ratio"] == 320.0 and stored["actuator_id"] == "tail-7/elevator-right"
    bench = draw(21, "sweep", drive=DRIVES["heavier"], nominal=NOMINAL["heavier"], flight=Ground(-150.0, 600.0))
    window = {**bench.document, "actuator_id": "tail-7/elevator-right", "window_id": "bench-1"}
    del window["flight_condition"]  # absent: on the ground
    answer = client.post("/v1/estimate", json=window).json()
    assert answer["actuator"] == {"name": "foreign heavier actuator", "version": 1, "default": False}
    assert abs(answer["estimates"]["FDJ"]["value"] / bench.truth["FDJ"] - 1) < 0.03
    assert "on_ground" in {note["code"] for note in answer["notes"]}
    changed = document("heavier") | {"name": "heavier, reworked"}
    assert client.put(path, json=changed).json()["version"] == 2
    history = client.get(f"{path}/estimates").json()["estimates"]
    assert history[0]["actuator"]["version"] == 1  # a stored estimate keeps the version it was read with


def test_a_window_of_an_actuator_without_a_document_is_read_with_the_default_and_says_so(client, document):
    answer = client.post("/v1/estimate", json=document).json()
    assert answer["actuator"]["default"] and answer["notes"][0]["code"] == "default_actuator"


def test_a_bad_actuator_document_is_a_422_naming_its_field(client):
    from tests.foreign.actuators import document as actuator_document

    bad = actuator_document("smaller")
    bad["nominal"]["fsj_nm"] = 0.001
    response = client.put("/v1/actuators/x", json=bad)
    assert response.status_code == 422 and response.json()["detail"][0]["loc"] == ["body", "nominal", "fsj_nm"]


def test_a_servo_window_without_its_stored_document_is_refused_saying_how_to_store_it(tmp_path):
    """The EMPS log as a window, to an actuator with no document: not read as the default's rotary EMA, and the
    refusal names the path to PUT its document to, for an estimate and for a calibration alike."""
    from pathlib import Path

    from ema.cli.logs import read_one
    from ema.model.logmap import read_logmap
    from ema.model.window import window_to_dict

    emps = Path(__file__).resolve().parents[2] / "examples" / "emps"
    window = window_to_dict(read_one(emps / "DATA_EMPS.mat", read_logmap(emps / "log-map.json")))
    settings = settings_for(tmp_path, max_window_s=30.0, max_calibrate_s=30.0)  # the 24.8 s log within the limits
    with TestClient(create_app(settings), base_url=LOCAL) as client:
        for route, body, field in (
            ("/v1/estimate", window, ["body", "signals"]),
            ("/v1/calibrate", {"windows": [window]}, ["body", "windows", "0", "signals"]),
        ):
            refused = client.post(route, json=body)
            assert refused.status_code == 422 and refused.json()["detail"][0]["loc"] == field
            assert "PUT its document to /v1/actuators/emps/axis" in refused.json()["detail"][0]["msg"]


def test_a_window_with_a_dead_channel_is_refused_and_never_stored(client, document):
    """A dead current sensor (a constant): 422 naming the signal, and nothing of the window is stored, so it
    never enters a trend, a status or a remaining life."""
    dead = {**document, "signals": {**document["signals"], "current_a": [0.0] * len(document["signals"]["current_a"])}}
    refused = client.post("/v1/estimate", json=dead)
    assert refused.status_code == 422 and refused.json()["detail"][0]["loc"] == ["body", "signals", "current_a"]
    assert client.get(f"/v1/actuators/{document['actuator_id']}/estimates").status_code == 404
