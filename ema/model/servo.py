"""A servo's part of ``ema-actuator/1``: a linear axis whose drive takes a force command from a known position
controller, logged on the load side (positions in m, forces in N).

The controller, sampled at ``controller_rate_hz``, reads the measured position q, filters it by the FIR
``speed_filter`` and differences it for a speed, and commands

    u = kv·(kp·(q_ref − q) − dq),   saturated at ±``command_limit``,

a force ``drive_gain_n_per_unit``·u on the load, held until the next sample. The load moves by

    M·q̈ = F_drive − F_load − FDJ·sgn(q̇) − C(q̇)·q̇ − F_offset,

C the viscous coefficient (``viscous_down_ns_per_m`` where moving towards decreasing position differs). Where
``travel_per_turn_m`` is given, ``ema calibrate`` also looks for a force that repeats once per turn of the motor
(a screw's, a nut's or a coupling's eccentricity). The
controller's constants are on its own data sheet or in the log (a log map may read them from the file); the
load's (M, C, the offset, the nominal FDJ) are learned by ``ema calibrate`` where the document lacks them.
"""

from __future__ import annotations

from typing import Any

from pydantic import Field, field_validator, model_validator

from ema.model.document import Document, Number

SERVO_EFFECTS = ("viscous_down", "stribeck", "presliding", "position_force", "position_friction", "turn_ripple")
# what calibration may adopt into the model (``ema.kinds.servo.load_effects`` says what each is)
SERVO_CONSTANTS = (
    "drive_gain_n_per_unit",
    "command_limit",
    "position_gain_per_s",
    "speed_gain_per_mps",
    "controller_rate_hz",
)  # what a log may record beside its signals (``ema-window/1`` constants)


class Servo(Document):
    """The drive, its position controller and the load, on the load side."""

    drive_gain_n_per_unit: Number | None = Field(
        None, gt=0, le=1e7, description="force on the load per unit of the controller's command (N/V); null: the log's"
    )
    command_unit: str = Field("V", min_length=1, max_length=16, description="the command's unit, for a person")
    command_limit: Number | None = Field(
        None, gt=0, le=1e6, description="the command's saturation, ± in its unit; null: the log's, else none"
    )
    position_gain_per_s: Number | None = Field(
        None, gt=0, le=1e6, description="kp: position error [m] -> speed reference [m/s]; null: the log's"
    )
    speed_gain_per_mps: Number | None = Field(
        None, gt=0, le=1e9, description="kv: speed error [m/s] -> command [its unit]; null: the log's"
    )
    speed_filter: list[Number] = Field(
        default_factory=lambda: [0.5, 0.5],
        min_length=1,
        max_length=16,
        description="FIR taps on the measured position before its difference is the speed (they sum to 1)",
    )
    controller_rate_hz: Number | None = Field(
        None, ge=10, le=100_000, description="the controller's sample rate; null: the log's own (a controller's log)"
    )
    bandwidth_hz: Number | None = Field(
        None,
        gt=0,
        le=10_000,
        description="the closed position loop's bandwidth, which sets the inverse model's filters (a low-pass at 5x, "
        "decimation to 2x); null: the loop's natural frequency from its gains and the mass",
    )
    position_resolution_m: Number | None = Field(
        None, gt=0, le=1e-2, description="the position sensor's step; null: read from the log"
    )
    travel_per_turn_m: Number | None = Field(
        None,
        gt=0,
        le=10,
        description="the load's travel per turn of the motor (a screw's lead, through any gear between): the period "
        "of a force once per turn; null: not known, and no such force is looked for",
    )
    mass_kg: Number | None = Field(
        None, ge=1e-3, le=1e6, description="M, everything the drive moves (learned; no drive moves less than a gram)"
    )
    mass_std_kg: Number | None = Field(None, ge=0, le=1e6)
    viscous_ns_per_m: Number | None = Field(
        None, ge=0, le=1e7, description="C moving towards increasing position, and both ways where the next is null"
    )
    viscous_std_ns_per_m: Number | None = Field(None, ge=0, le=1e7)
    viscous_down_ns_per_m: Number | None = Field(
        None, ge=0, le=1e7, description="C moving towards decreasing position (null: the same as viscous_ns_per_m)"
    )
    viscous_down_std_ns_per_m: Number | None = Field(None, ge=0, le=1e7)
    force_offset_n: Number | None = Field(
        None, ge=-1e6, le=1e6, description="a constant force against the drive (a slope, a drive's zero) (learned)"
    )
    force_offset_std_n: Number | None = Field(None, ge=0, le=1e6)
    effects: dict[str, Number] = Field(
        default_factory=dict,
        description="the effects ema calibrate adopted into this servo's model, each with its nonlinear constant "
        f"(1 where it has none): any of {', '.join(SERVO_EFFECTS)}",
    )
    effect_constants: dict[str, Number] = Field(
        default_factory=dict,
        description="the adopted effects' solved constants, in the inverse model's names (presliding_n: the friction "
        "short of FDJ right after a reversal [N]; turn_ripple_amplitude_n: the size of the force once per turn, whose "
        "phase each log reads, the motor's angle at the load's zero moving from run to run)",
    )
    repeatability_n: Number | None = Field(
        None, ge=0, le=1e6, description="the run-to-run std of FDJ beyond each run's own noise (learned)"
    )

    @field_validator("speed_filter")
    @classmethod
    def _averaging(cls, taps: list[float]) -> list[float]:
        if abs(sum(taps) - 1.0) > 1e-6:
            raise ValueError(f"the taps sum to {sum(taps):g}: a filter of the position must pass it unscaled (sum 1)")
        return taps

    @field_validator("effects")
    @classmethod
    def _known_effects(cls, effects: dict[str, float]) -> dict[str, float]:
        unknown = sorted(set(effects) - set(SERVO_EFFECTS))
        if unknown:
            raise ValueError(f"{unknown[0]} is not an effect of a servo's model ({', '.join(SERVO_EFFECTS)})")
        if any(value <= 0 for value in effects.values()):
            raise ValueError("an effect's constant is positive (a speed, a travel; 1 where it has none)")
        return effects

    @model_validator(mode="after")
    def _one_turn(self) -> Servo:
        """An adopted force once per turn repeats at the machine's turn, where the document gives it."""
        period, turn = self.effects.get("turn_ripple"), self.travel_per_turn_m
        if period is not None and turn is not None and abs(period - turn) > 1e-9 * turn:
            raise ValueError(
                f"servo.effects.turn_ripple repeats every {period:g} m where servo.travel_per_turn_m is {turn:g} m: a "
                "machine turns one way (calibrate again with the document's turn)"
            )
        return self

    @property
    def gear_ratio(self) -> float:
        """1: the logged force acts on the load itself (no transmission between the log and the load)."""
        return 1.0

    def with_constants(self, constants: dict[str, float], source: str) -> Servo:
        """This section completed by the constants a log recorded (``SERVO_CONSTANTS``); a constant the
        section gives differently is refused naming it (a log read with another machine's document)."""
        from ema.model.checks import InputError, validated

        update: dict[str, Any] = {}
        for name, value in constants.items():
            if name not in SERVO_CONSTANTS:
                raise InputError(f"{source}.{name}", f"is not a servo's constant ({', '.join(SERVO_CONSTANTS)})")
            given = getattr(self, name)
            if given is not None and abs(given - value) > 1e-6 * max(abs(given), abs(value)):
                raise InputError(
                    f"{source}.{name}", f"the log recorded {value:g}, the actuator's document says {given:g}"
                )
            update[name] = value
        return validated(type(self), {**self.model_dump(), **update}, source, prefix=f"{source}.")

    def missing(self) -> list[str]:
        """The controller's constants neither the document nor the log gave."""
        needed = ("drive_gain_n_per_unit", "position_gain_per_s", "speed_gain_per_mps")
        return [name for name in needed if getattr(self, name) is None]
