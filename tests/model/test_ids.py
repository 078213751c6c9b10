"""An actuator id never resolves to another's: a path segment ``.``, ``..`` or an empty one is refused, in a window
and in the service's path alike."""

import pytest
from fastapi.testclient import TestClient

from ema.model.bounds import route_collision
from ema.model.checks import InputError
from ema.model.window import window_from_dict
from ema.service.main import create_app
from tests.service.conftest import LOCAL, settings_for
from tests.service.conftest import window_document as window_document  # the service's fixture, a rotary window


@pytest.mark.parametrize("actuator_id", ["a/../b", "../b", "a/./b", "a//b", "a/", "tail-7/.."])
def test_relative_segments_are_refused(actuator_id, window_document, tmp_path):
    assert route_collision(actuator_id) is not None
    with pytest.raises(InputError, match="segment"):
        window_from_dict({**window_document, "actuator_id": actuator_id})
    with TestClient(create_app(settings_for(tmp_path)), base_url=LOCAL) as client:
        assert client.get(f"/v1/actuators/{actuator_id}/estimates").status_code in (404, 422)


@pytest.mark.parametrize("actuator_id", ["tail-123/elevator-left", "a.b/c..d", "rig.1"])
def test_names_with_dots_stand(actuator_id):
    assert route_collision(actuator_id) is None
