"""A geared servo's calibrated document, as the foreign servo's constants would fill it (for tests)."""

from ema.model.actuator import GearedActuator, actuator_from_dict
from tests.foreign.geared import Servo

FOREIGN = Servo()


def calibrated_document(servo: Servo = FOREIGN, **geared: float) -> GearedActuator:
    document = actuator_from_dict(
        {
            "schema": "ema-actuator/1",
            "name": "a foreign geared servo",
            "kind": "geared",
            "nominal": {"fdj_nm": servo.fdj, "eta_o": servo.eta_o, "eta_a": servo.eta_a},
            "geared": {
                "gear_ratio": 300,
                "position_resolution_rad": 0.0015339807878856412,
                "torque_constant_nm_per_a": servo.torque_constant,
                "resistance_ohm": servo.resistance,
                "inertia_kg_m2": servo.inertia,
                "error_gain_per_rad": servo.error_gain,
                "duty_limit": servo.duty_limit,
                "viscous_nm_s_per_rad": servo.viscous,
                "command_delay_s": servo.delay_s,
                **geared,
            },
        }
    )
    assert isinstance(document, GearedActuator)
    return document
