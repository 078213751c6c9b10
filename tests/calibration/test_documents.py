"""ema-calibration/1 is one kind's report, joined on ``kind``: each kind's class holds its own parts and no
other's, and a report written before reports named their kind (every part in each, empty) still reads as its
kind's, as the history holds such reports."""

import json
from pathlib import Path

import pytest

from ema.calibration.documents import (
    CALIBRATION_REPORT,
    CalibrationReport,
    Change,
    HeldOut,
    LinearCalibration,
    NoiseFloor,
    RotaryCalibration,
    ServoCalibration,
)
from ema.model.checks import InputError, validated
from ema.model.kinds import KIND_NAMES


def _shared() -> dict:
    """What every kind's report holds, at values no loop would need to have produced."""
    return {
        "n_windows": 2,
        "noise_floor": NoiseFloor(copies=4, equation_error_ratio=1.1).model_dump(),
        "residual_rms_before": {"residual_torque": 0.02},
        "residual_rms_after": {"residual_torque": 0.01},
        "candidates": [],
        "selected_effect": None,
        "selected_effects": [],
        "selected_parameters": None,
        "effects": {},
        "selection_steps": [],
        "unexplained": None,
        "held_out": HeldOut(rss_before=2.0, rss_after=1.0, adopted=True, note="better").model_dump(),
        "estimates_before": {"FDJ": 0.05},
        "estimates_after": {"FDJ": 0.051},
        "timings_s": {"total": 1.0},
    }


CHANGE = Change(parameter="FDJ", nominal=0.6, value=0.8, std=0.02, z=10.0, departed=True, said="rose").model_dump()
EMPS_DOCUMENT = Path(__file__).resolve().parents[2] / "examples" / "emps" / "actuator.json"
AS_FIRST_WRITTEN = {"schema": "ema-calibration/1", "drive": None, "changes": [], "as_simulated": []}


@pytest.mark.parametrize(
    ("parts", "cls"),
    [
        ({}, RotaryCalibration),
        ({"changes": [CHANGE]}, LinearCalibration),
        ({"as_simulated": [{"name": "mass", "value": 95.0, "std": 0.2, "unit": "kg"}]}, ServoCalibration),
        ({"completed_actuator": {"schema": "ema-actuator/1", "name": "axis", "kind": "servo"}}, ServoCalibration),
    ],
)
def test_a_report_written_before_kinds_were_named_reads_as_its_kinds(parts, cls):
    written = {**AS_FIRST_WRITTEN, **_shared(), **parts}
    if "completed_actuator" in parts:  # a servo's document needs its section to read: borrow the bundled one's
        written["completed_actuator"] = json.loads(EMPS_DOCUMENT.read_text())
    report = CALIBRATION_REPORT.validate_json(json.dumps(written))
    assert type(report) is cls
    again = report.model_dump(by_alias=True)
    assert again["kind"] == report.kind and CALIBRATION_REPORT.validate_python(again) == report
    others = {"drive", "changes", "as_simulated"} - set(cls.model_fields)
    assert not others & set(report.model_dump())  # written without another kind's parts


def test_another_kinds_part_is_refused_naming_it():
    with pytest.raises(InputError) as refused:
        validated(CALIBRATION_REPORT, {**_shared(), "kind": "rotary", "changes": [CHANGE]}, "report", tags=KIND_NAMES)
    assert refused.value.field == "changes" and "rotary" in refused.value.message
    with pytest.raises(InputError) as unknown:
        validated(CALIBRATION_REPORT, {**_shared(), "kind": "hydraulic"}, "report", tags=KIND_NAMES)
    assert unknown.value.field == "kind"


def test_the_shared_class_holds_no_report_alone():
    with pytest.raises(TypeError, match="no document alone"):
        CalibrationReport.model_validate(_shared())


def test_the_schema_is_one_of_each_kinds_report():
    from ema.calibration.documents import calibration_schema
    from ema.model.kinds import KINDS

    schema = calibration_schema()
    members = [schema["$defs"][ref["$ref"].rpartition("/")[2]] for ref in schema["oneOf"]]
    assert {member["properties"]["kind"]["const"] for member in members} == set(KINDS)
