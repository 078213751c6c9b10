"""The operator's pages through TestClient: what they list, in what order, and that they need the key."""

import base64

import pytest
from fastapi.testclient import TestClient

from ema.history.open import open_history
from ema.kinds.rotary.pipeline import estimate_window
from ema.kinds.rotary.synthetic import synthetic_window
from ema.model.actuator import THESIS
from ema.model.params import HealthParams
from ema.service.main import create_app
from tests.service.conftest import KEY, LOCAL, SMALL, settings_for, settled
from tests.service.fleet import FLEET, store_fleet


@pytest.fixture(scope="module")
def base():
    return estimate_window(synthetic_window(HealthParams.single(), seed=1, duration_s=0.1), SMALL, actuator=THESIS)


@pytest.fixture
def fleet_settings(tmp_path, base):
    settings = settings_for(tmp_path)
    store = open_history(settings.database)
    store_fleet(store, base)
    store.close()
    return settings


def test_the_fleet_page_lists_every_actuator_most_urgent_first(fleet_settings):
    with TestClient(create_app(fleet_settings), base_url=LOCAL) as client:
        settled(client)
        page = client.get("/ui")
    assert page.status_code == 200 and page.headers["content-type"].startswith("text/html")
    order = sorted(FLEET, key=page.text.index)
    assert order[0] == "tail-3/elevator-left" and order[-1] == "tail-1/elevator-left"  # crossed first, steady last
    assert page.text.count('class="due"') >= 1 and 'class="healthy"' in page.text
    assert "no degradation detected" in page.text and "http" not in page.text.replace(LOCAL, "")


def test_an_actuator_page_plots_each_parameter_with_its_outlook(fleet_settings):
    with TestClient(create_app(fleet_settings), base_url=LOCAL) as client:
        page = client.get("/ui/actuators/tail-1/elevator-right")
    assert page.status_code == 200 and page.text.count("<svg") == 3  # FDJ, η_O, η_A
    assert page.text.count('class="estimate"') == 60 and 'class="forecast"' in page.text
    assert 'class="threshold"' in page.text and 'class="rul"' in page.text and "backtest" in page.text


def test_an_actuator_page_answers_while_every_job_place_is_taken(fleet_settings):
    """The view costs the estimates nothing: its pages never take a job's place, so with every place held (as five
    concurrent estimates hold them) a page still answers, and no page makes an estimate wait or be refused."""
    with TestClient(create_app(fleet_settings), base_url=LOCAL) as client:
        runner = client.app.state.runner
        held = [runner.admit() for _ in range(runner.slots + runner.max_queue)]
        try:
            assert client.post("/v1/estimate", json={}).status_code == 503  # every place taken: estimates wait
            for _ in range(5):  # five viewers, reloading
                assert client.get("/ui/actuators/tail-1/elevator-right").status_code == 200
            assert runner.admitted == len(held)  # no page took a place
        finally:
            for ticket in held:
                ticket.__exit__(None, None, None)


def test_an_actuator_nothing_is_stored_of_is_a_404_page_not_an_empty_history(fleet_settings):
    """A mistyped id must not read as an actuator with no windows (the API answers it 404 as well)."""
    with TestClient(create_app(fleet_settings), base_url=LOCAL) as client:
        page = client.get("/ui/actuators/tail-1/elevator-rigth")
        api = client.get("/v1/actuators/tail-1/elevator-rigth/prognosis")
    assert page.status_code == 404 == api.status_code and page.headers["content-type"].startswith("text/html")
    assert "No window or document is stored" in page.text and 'href="/ui"' in page.text and "<svg" not in page.text


def test_with_a_key_the_pages_ask_for_it_as_a_password(tmp_path, base):
    settings = settings_for(tmp_path, api_key=KEY)
    with TestClient(create_app(settings), base_url="http://ema.example") as client:
        refused = client.get("/ui")
        assert refused.status_code == 401 and refused.headers["www-authenticate"].startswith("Basic")
        basic = base64.b64encode(f"operator:{KEY}".encode()).decode()
        assert client.get("/ui", headers={"authorization": f"Basic {basic}"}).status_code == 200
        wrong = base64.b64encode(b"operator:wrong").decode()
        assert client.get("/ui", headers={"authorization": f"Basic {wrong}"}).status_code == 401
        assert client.post("/ui", json={}, headers={"authorization": f"Basic {basic}"}).status_code == 405  # read only


def test_each_fleet_row_shows_its_own_friction_unit_and_no_empty_limits():
    """A servo's friction is a force on the load, a rotary's a torque at the motor: one column, each row's unit;
    a row with neither nominal nor threshold shows none, not an empty bracket."""
    from ema.prognosis.documents import ActuatorSummary, Threshold
    from ema.service.pages import fleet_page

    def line(actuator_id: str, status: str, **values) -> ActuatorSummary:
        return ActuatorSummary(actuator_id=actuator_id, status=status, reason="", windows=6, document="d", **values)

    rotary = line(
        "tail-1/elevator",
        "healthy",
        estimates={"FDJ": 0.0512, "eta_O": 0.85},
        stds={"FDJ": 0.001, "eta_O": 0.01},
        units={"FDJ": "N·m", "eta_O": "1"},
        nominal={"FDJ": 0.05},
        thresholds={"FDJ": Threshold(level=0.075, direction="above")},
    )
    servo = line("emps/axis", "not enough history", estimates={"FDJ": 20.79}, stds={"FDJ": 0.27}, units={"FDJ": "N"})
    page = fleet_page([rotary, servo], page=1, pages=1, total=2, pending=[], status=None, tail=None)
    assert "<th>FDJ</th>" in page and "0.0512 ± 0.001 N·m <small>(nominal 0.05, fails &gt; 0.075)</small>" in page
    assert "<td>20.79 ± 0.27 N</td>" in page and "()" not in page and "0.85 ± 0.01</td>" in page


def test_a_reload_of_an_unchanged_fleet_page_is_answered_not_modified(fleet_settings):
    with TestClient(create_app(fleet_settings), base_url=LOCAL) as client:
        settled(client)
        first = client.get("/ui")
        again = client.get("/ui", headers={"If-None-Match": first.headers["etag"]})
        other = client.get("/ui", headers={"If-None-Match": '"another page"'})
    assert first.status_code == 200 and first.headers["cache-control"] == "no-cache"
    assert again.status_code == 304 and again.content == b"" and again.headers["etag"] == first.headers["etag"]
    assert other.status_code == 200 and other.text == first.text
    assert 'http-equiv="refresh"' not in first.text  # nothing pending: the page stays as it is


def test_the_fleet_page_reloads_itself_while_a_line_is_pending_and_not_after():
    from ema.service.pages import fleet_page

    common = {"page": 1, "pages": 1, "total": 0, "status": None, "tail": None}
    assert 'http-equiv="refresh"' in fleet_page([], pending=["tail-9/x"], **common)
    assert 'http-equiv="refresh"' not in fleet_page([], pending=[], **common)
