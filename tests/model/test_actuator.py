"""The ema-actuator/1 document: validated naming the field, the thesis's the default, what stages read of it."""

import json
import re
from pathlib import Path

import pytest

from ema.model.actuator import THESIS, actuator_from_dict, read_actuator
from ema.model.checks import InputError
from ema.model.params import DEFAULT_RANGES, DriveConstants, eta_a_from_eta_o

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "actuator.json"


def test_the_thesis_actuator_ships_as_the_example_and_is_table_3_1():
    assert read_actuator(EXAMPLE) == THESIS
    assert THESIS.params == DriveConstants()
    for name in ("fdj_nm", "fsj_nm", "eta_o"):  # the healthy range: Table 3.1's, ±20 % of nominal
        assert getattr(THESIS.ranges, name) == pytest.approx(getattr(DEFAULT_RANGES, name))
    assert THESIS.threshold("FDJ") == (0.075, "above") and THESIS.threshold("eta_O") == (0.70, "below")


def test_the_documents_drive_names_every_constant_the_simulator_takes_but_its_step():
    """The document's Drive and the simulator's DriveConstants declare the same constants: one added to the
    simulator and not to the document would be read at its default from every document, silently."""
    from dataclasses import fields

    from ema.model.drive import Drive

    assert set(Drive.model_fields) == {f.name for f in fields(DriveConstants)} - {"step_s"}


def test_eq_3_4_and_the_thresholds_follow_the_documents_gear_ratio_and_nominal():
    document = json.loads(EXAMPLE.read_text())
    document["drive"]["gear_ratio"] = 320.0
    document["nominal"] = {"fdj_nm": 0.08, "fsj_nm": 0.16, "eta_o": 0.9}
    del document["thresholds"]
    heavier = actuator_from_dict(document)
    assert heavier.eta_a(0.9) == pytest.approx(eta_a_from_eta_o(0.9, 320.0))
    assert heavier.eta_a(0.9) != pytest.approx(eta_a_from_eta_o(0.9, 500.0), rel=1e-6)
    assert heavier.threshold("FDJ") == (pytest.approx(0.12), "above")  # 1.5x its own nominal
    assert heavier.threshold("eta_A")[0] == pytest.approx(eta_a_from_eta_o(0.70, 320.0))
    assert heavier.ranges.fdj_nm == pytest.approx((0.064, 0.096)) and heavier.ranges.eta_o[1] == pytest.approx(0.98)


@pytest.mark.parametrize(
    ("change", "field"),
    [
        (("drive", "gear_ratio", 0.5), "drive.gear_ratio"),
        (("drive", "torque_constant_nm_per_a", -0.1), "drive.torque_constant_nm_per_a"),
        (("drive", "inductance_h", 1e-8), "drive.inductance_h"),  # R/L beyond what a 1 µs step integrates
        (("drive", "end_stop_deg", "30"), "drive.end_stop_deg"),  # strict: a string is not a number
        (("nominal", "fsj_nm", 0.01), "nominal.fsj_nm"),  # static below dynamic friction
        (("nominal", "eta_o", 1.2), "nominal.eta_o"),
        (("thresholds", "fdj_above_nm", 0.04), "thresholds.fdj_above_nm"),  # not past the nominal
        (("drive", "unknown_constant", 1.0), "drive.unknown_constant"),
    ],
)
def test_an_impossible_value_is_refused_naming_the_field(change, field):
    document = json.loads(EXAMPLE.read_text())
    part, name, value = change
    document[part][name] = value
    with pytest.raises(InputError) as refused:
        actuator_from_dict(document)
    assert refused.value.field == field


def test_a_document_without_its_airframe_is_valid_and_checks_no_aircraft():
    document = json.loads(EXAMPLE.read_text())
    del document["airframe"]
    assert actuator_from_dict(document).hinge is None and THESIS.hinge is not None
    with pytest.raises(InputError) as refused:
        actuator_from_dict({**document, "schema": "ema-actuator/2"})
    assert refused.value.field == "schema"


@pytest.mark.parametrize(
    "path", [EXAMPLE, EXAMPLE.parent / "emps" / "actuator.json", EXAMPLE.parent / "ballscrew-rig" / "actuator.json"]
)
def test_each_kinds_document_is_its_own_class_and_round_trips(path):
    """A document is read as its kind's class (its section typed), and written back reads the same."""
    from ema.model.actuator import LinearActuator, RotaryActuator, ServoActuator, actuator_from_json

    document = read_actuator(path)
    classes = {"rotary": RotaryActuator, "linear": LinearActuator, "servo": ServoActuator}
    assert type(document) is classes[document.kind] and document.section is getattr(document, document.facts.section)
    assert actuator_from_json(document.model_dump_json(by_alias=True)) == document
    assert {"drive", "screw", "servo"} & set(document.model_dump()) == {document.facts.section}


def test_a_document_as_first_written_still_reads_and_another_kinds_section_is_refused():
    """Documents stored before the kinds' classes carry every section, null but their own, and a rotary one may
    omit its kind: both still read. A section of another kind is refused naming it, and so is an unknown kind."""
    document = json.loads(EXAMPLE.read_text())
    document.pop("kind", None)
    assert actuator_from_dict({**document, "screw": None, "servo": None}) == THESIS
    with pytest.raises(InputError, match="a rotary actuator has no screw") as refused:
        actuator_from_dict({**document, "screw": {"lead_mm": 5.0}})
    assert refused.value.field == "screw"
    with pytest.raises(InputError, match="is one of rotary, linear, servo") as refused:
        actuator_from_dict({**document, "kind": "hydraulic"})
    assert refused.value.field == "kind"
    with pytest.raises(InputError, match="gives its drive") as refused:
        actuator_from_dict({key: value for key, value in document.items() if key != "drive"})
    assert refused.value.field == "drive"


def test_the_rotarys_own_fields_are_its_own_and_a_null_one_in_another_kinds_document_reads_as_absent():
    """The airframe and the sensors' noise are a rotary document's; another kind's document written with them null
    (as every document once was) still reads, and one that gives them is refused naming the field."""
    servo = json.loads((EXAMPLE.parent / "emps" / "actuator.json").read_text())
    read = actuator_from_dict({**servo, "airframe": None, "sensor_noise": None})
    assert read == actuator_from_dict(servo) and "airframe" not in read.model_dump()
    with pytest.raises(InputError, match="Extra inputs") as refused:
        actuator_from_dict({**servo, "sensor_noise": THESIS.model_dump()["drive"]})
    assert refused.value.field == "sensor_noise"
    with pytest.raises(InputError, match="Extra inputs") as refused:  # a null field no kind has: a typo, named
        actuator_from_dict({**servo, "airfram": None})
    assert refused.value.field == "airfram"
    assert THESIS.load_model_tolerance == THESIS.airframe.tolerance and read.load_model_tolerance == 0.1
    nominal = {"fdj_n": 20.0, "eta_o": None}  # FSJ is the rotary's: null as once written, else refused
    assert actuator_from_dict({**servo, "nominal": {**nominal, "fsj_nm": None}}).nominal.fsj is None
    with pytest.raises(InputError, match="Extra inputs") as refused:
        actuator_from_dict({**servo, "nominal": {**nominal, "fsj_nm": 0.1}})
    assert refused.value.field == "nominal.fsj_nm"
    assert THESIS.nominal.fsj == THESIS.nominal.fsj_nm == 0.1


def test_a_servos_force_once_per_turn_repeats_at_its_documents_turn():
    servo = {"command_limit": 10.0, "travel_per_turn_m": 2.5e-3, "effects": {"turn_ripple": 2.5e-3}}
    document = {"schema": "ema-actuator/1", "name": "a servo", "kind": "servo", "servo": servo}
    assert actuator_from_dict(document).servo.effects == {"turn_ripple": 2.5e-3}
    said = "servo.effects.turn_ripple repeats every 0.005 m where servo.travel_per_turn_m is 0.0025 m"
    with pytest.raises(InputError, match=re.escape(said)):
        actuator_from_dict({**document, "servo": {**servo, "effects": {"turn_ripple": 5e-3}}})
