"""Two actuators of the spec's architecture unlike the thesis's, for tests only, and their ema-actuator/1
documents as a user would write them (the drive's constants; the nominal health; no airframe)."""

from __future__ import annotations

from dataclasses import asdict

from tests.foreign.physics import THESIS, Drive, Health

HEAVIER = Drive(
    position_gain_per_s=6e4,
    speed_gain_nms=0.08,
    resistance_ohm=1.1,
    inductance_h=6e-4,
    torque_constant_nm_per_a=0.12,
    max_motor_torque_nm=2.7,
    supply_voltage_v=48.0,
    max_current_a=22.5,
    gear_ratio=320.0,
    inertia_kgm2=6e-5,
    viscous_nms=8e-5,
    backlash_rad=4e-3,
    end_stop_deg=25.0,
)
SMALLER = Drive(
    position_gain_per_s=1.5e5,
    speed_gain_nms=0.03,
    resistance_ohm=3.2,
    inductance_h=9e-4,
    torque_constant_nm_per_a=0.05,
    max_motor_torque_nm=0.9,
    supply_voltage_v=48.0,
    max_current_a=18.0,
    gear_ratio=800.0,
    inertia_kgm2=1.2e-5,
    viscous_nms=2.5e-5,
    backlash_rad=6e-3,
    end_stop_deg=30.0,
)
NOMINAL = {
    "thesis": Health(fdj_nm=0.05, fsj_nm=0.10, eta_o=0.85),
    "heavier": Health(fdj_nm=0.08, fsj_nm=0.16, eta_o=0.85),
    "smaller": Health(fdj_nm=0.03, fsj_nm=0.06, eta_o=0.85),
}
DRIVES = {"thesis": THESIS, "heavier": HEAVIER, "smaller": SMALLER}


def document(name: str) -> dict:
    """The ema-actuator/1 document of ``name``: its drive and nominal health, nothing optional."""
    nominal = NOMINAL[name]
    return {
        "schema": "ema-actuator/1",
        "name": f"foreign {name} actuator",
        "drive": asdict(DRIVES[name]),
        "nominal": {"fdj_nm": nominal.fdj_nm, "fsj_nm": nominal.fsj_nm, "eta_o": nominal.eta_o},
    }
