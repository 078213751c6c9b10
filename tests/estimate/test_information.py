"""A dead sensor never becomes an answer: a channel that carries nothing is refused before it is read, and an answer
outside its document's bounds is never a reading. Every case on data we did not write for it: the EMPS log mapped
carelessly, a foreign rotary window, a foreign geared servo's recorder log."""

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from ema import kinds
from ema.cli.logs import read_one
from ema.estimate.config import PipelineConfig
from ema.estimate.information import dead_channel
from ema.model.actuator import read_actuator
from ema.model.checks import InputError
from ema.model.logmap import logmap_from_dict, read_logmap
from ema.model.window import Window, window_from_dict
from tests.foreign.windows import draw

EMPS = Path(__file__).resolve().parents[2] / "examples" / "emps"


@pytest.fixture(scope="module")
def emps() -> Window:
    return read_one(EMPS / "DATA_EMPS.mat", read_logmap(EMPS / "log-map.json"))


def mapped(**changes: dict) -> Window:
    document = read_logmap(EMPS / "log-map.json").model_dump(mode="json", by_alias=True, exclude_none=True)
    for role, change in changes.items():
        document[role] = {**document[role], **change}
    return read_one(EMPS / "DATA_EMPS.mat", logmap_from_dict(document))


def read(window: Window) -> None:
    kinds.estimate(window, PipelineConfig(), actuator=read_actuator(EMPS / "actuator.json"))


@pytest.mark.parametrize(
    ("change", "said"),
    [
        (lambda f: np.zeros_like(f), "0 throughout"),
        (lambda f: np.full_like(f, 3.7), "3.7 throughout"),
        (lambda f: np.where(np.arange(len(f)) < 0.95 * len(f), 1.25, f), "frozen"),
        (lambda f: np.where(f > 0, 0.5, -0.5), "two values"),
    ],
)
def test_a_dead_stuck_or_one_step_force_is_refused_naming_the_channel(emps, change, said):
    window = replace(emps, signals={**emps.signals, "drive_force_n": change(emps.signals["drive_force_n"])})
    with pytest.raises(InputError, match=said) as refused:
        read(window)
    assert refused.value.field == "signals.drive_force_n"


def test_a_force_mapped_with_a_scale_of_0_is_refused(emps):
    with pytest.raises(InputError, match="scale of 0") as refused:
        read(mapped(force={"scale": 0}))
    assert refused.value.field == "signals.drive_force_n"


def test_a_force_scaled_out_of_any_physical_range_is_refused_naming_the_bound():
    with pytest.raises(InputError, match="allows ≥ 1e-06") as refused:
        read(mapped(force={"scale": 35.15e-9}))
    assert refused.value.field == "estimates.fdj_n"


def test_positions_declared_in_micrometres_read_a_mass_past_the_documents_bound():
    with pytest.raises(InputError, match="allows ≤ 1e\\+06") as refused:
        read(mapped(position={"unit": "um"}, set_point={"unit": "um"}))
    assert refused.value.field == "estimates.mass_kg"


def test_the_set_point_mapped_as_the_position_is_named_a_mapping_mistake():
    with pytest.raises(InputError, match="maps one variable to both") as refused:
        read(mapped(position={"column": "qg"}))
    assert refused.value.field == "signals.position_m"


def test_a_rotary_windows_dead_current_is_refused_and_a_calibration_names_the_window():
    window = window_from_dict(draw(seed=5).document)
    dead = replace(window, signals={**window.signals, "current_a": np.zeros(window.n_samples)})
    with pytest.raises(InputError) as refused:
        kinds.estimate(dead, PipelineConfig(), actuator=read_actuator(Path("examples/actuator.json")))
    assert refused.value.field == "signals.current_a"
    request = kinds.CalibrationRequest(PipelineConfig(), read_actuator(Path("examples/actuator.json")))
    with pytest.raises(InputError) as refused:
        kinds.calibrate([window, dead], request)
    assert refused.value.field == "windows.1.signals.current_a"


def test_a_live_channel_with_rests_is_not_dead():
    rng = np.random.default_rng(0)
    signal = np.concatenate([np.zeros(300), rng.normal(size=400), np.full(300, 2.0)])
    assert dead_channel("drive_force_n", signal) is None
