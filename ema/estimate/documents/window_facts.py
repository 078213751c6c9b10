"""What an estimate says of its window (``ema-estimate/1``'s ``window``): what every kind's says, and what a rotary
window's reading adds, with what its windows lend each other (a flight's sensor zero, the actuator's J_M:
``ema.kinds.rotary.other_windows``). Part of the one definition of the estimate document (``ema.estimate.documents``).
"""

from __future__ import annotations

from typing import Self

from pydantic import Field, TypeAdapter

from ema.model.document import Document
from ema.model.window import Window


class SensorZero(Document):
    """The sensors' zero as a rotary window moving both ways read it (``ema.kinds.rotary.prepare.departures
    .zero_offset``): what a window of the same flight that moves one way, and so cannot read it, is read with."""

    window_id: str = Field(description="the window that read it")
    hinge_nm: float = Field(description="taken off the logged hinge moment")
    current_a: float = Field(description="taken off the logged current")
    torque_std_nm: float = Field(ge=0, description="its std, as a constant torque at the motor shaft")


class InertiaReading(Document):
    """J_M as windows of an actuator read it where each told a heavier rotor from a weaker motor itself
    (``ema.kinds.rotary.prepare.departures.drive_constants``): a window that cannot is read with it (J_M stays with
    the build)."""

    factor: float = Field(description="the inertia at the motor shaft over the document's J_M")
    std: float = Field(ge=0, description="its std")
    window_ids: list[str] = Field(description="the windows that read it")


class HistoryReadings(Document):
    """What a rotary actuator's other windows lend one of its windows that it may not read itself: the sensor zero of
    its flight (``flight_id``) and the actuator's J_M (``Rotary.borrowing``: the service, the fleet and ``ema estimate
    --history`` read it from what the windows lent, ``ema.kinds.rotary.other_windows``)."""

    sensor_zero: SensorZero | None = None
    inertia: InertiaReading | None = None


class WindowInfo(Document):
    """What every kind's estimate says of its window: its content, length and rates, its times and flight, what the
    reading used of it. A rotary window's reading adds what its prepare stage did (``RotaryWindowInfo``)."""

    content_sha256: str | None = Field(
        default=None,
        description="SHA-256 of the window as posted, but its actuator_id and window_id (ema.model.window): another "
        "body under the same key is another window",
    )
    n_samples: int
    duration_s: float
    sample_rate_hz: float
    processed_rate_hz: float = Field(description="after averaging adjacent samples (exact for interval means)")
    command_clipped_fraction: float = Field(description="share of command samples past the end stops, saturating")
    sliding_fraction: float = Field(description="share of samples the friction solution could use")
    recorded_at: str | None = None
    flight_hours: float | None = None
    flight_id: str | None = None

    @classmethod
    def logged(cls, window: Window, digest: str, **read: object) -> Self:
        """The window's own facts (its rate, length, times and flight) and what reading it did (``read``: the
        processed rate, the sliding share, and whatever else a kind's reading reports)."""
        return cls.model_validate(
            {
                "content_sha256": digest,
                "n_samples": window.n_samples,
                "duration_s": window.duration_s,
                "sample_rate_hz": window.sample_rate_hz,
                "recorded_at": window.recorded_at,
                "flight_hours": window.flight_hours,
                "flight_id": window.flight_id,
                **read,
            }
        )


class RotaryWindowInfo(WindowInfo):
    """What a rotary window's reading did to it beside what every kind's says: its sensors' repairs, clocks and
    departures from the document (the prepare stage), the sensors' zero and J_M it read for its actuator's other
    windows, and the strain gauge's gain against the aircraft."""

    glitches_repaired: dict[str, int] = Field(
        default_factory=dict,
        description="per sensor, samples of glitches (short runs far off both flanks, which agree), "
        "replaced by the line between the flanks",
    )
    stale_samples: dict[str, int] = Field(
        default_factory=dict,
        description="per sensor, samples of runs that repeated one value exactly where a working sensor shows its "
        "noise (it stopped updating, or a logging gap was filled in): a run up to the 2 ms reconstruction kernel "
        "bridged by the line between its flanks, a longer one cut out with the window read from read_span",
    )
    read_span: list[int] | None = Field(
        default=None,
        description="[first, one past the last] logged sample read, where stale runs cut the window (null: all)",
    )
    current_lag_s: float = Field(
        default=0.0, description="how late the current is logged behind the speed (negative: the speed), undone"
    )
    hinge_lag_s: float = Field(default=0.0, description="how late the hinge moment is logged (its filter), undone")
    hinge_offset_nm: float = Field(default=0.0, description="taken off the logged hinge moment (a sensor off zero)")
    current_offset_a: float = Field(default=0.0, description="taken off the logged current (a sensor off zero)")
    torque_scale: float = Field(
        default=1.0,
        description="the motor's torque per spec k_T·I as read (k_T warm or cold, a current sensor's gain); "
        "the current was multiplied by it before every estimator",
    )
    inertia_factor: float = Field(
        default=1.0,
        description="the inertia at the motor shaft over the document's J_M as read; "
        "the current carries the difference",
    )
    viscous_factor: float = Field(
        default=1.0,
        description="the viscous coefficient every estimator used over the document's C_M (read where it departs)",
    )
    hinge_gain: float = Field(
        default=1.0,
        description="the logged hinge moment over the load it shows (a strain gauge calibrated off, other units); "
        "the moment was divided by it before every estimator",
    )
    hinge_aircraft_ratio: float | None = Field(
        default=None,
        description="the logged hinge moment's part that follows the deflection over the aircraft model's "
        "q̄·S_e·c_e·C_hδ at the flight condition (1 where gauge and model agree; null: too little fast motion)",
    )
    hinge_aircraft_ratio_std: float | None = Field(default=None, description="the std of hinge_aircraft_ratio")
    kinematic_gain: float | None = Field(
        default=None,
        description="the position's travel over the speed's integral / gear ratio through the dead band (1 in a "
        "consistent log; 0.9-1.1 accepted; null: too little motion to tell)",
    )
    sensor_zero: SensorZero | None = Field(
        default=None,
        description="the sensors' zero as this window read it, for the windows of its flight that move one way "
        "(null: it moves one way itself, took its flight's instead (sensor_zero_from), or was read with the document's "
        "model alone)",
    )
    sensor_zero_from: str | None = Field(
        default=None, description="the window of its flight whose sensor_zero it was read with (null: its own)"
    )
    inertia_read: InertiaReading | None = Field(
        default=None,
        description="J_M as this window read it, where it told a heavier rotor from a weaker motor itself (null: "
        "it read none, or could not tell)",
    )
    inertia_undecided: bool = Field(
        default=False,
        description="it could not tell a heavier rotor from a weaker motor, nor did a J_M read by other windows of "
        "the actuator decide: its stds carry both readings",
    )
    inertia_from: list[str] | None = Field(
        default=None,
        description="it could not tell a heavier rotor from a weaker motor: the windows whose J_M (history) decided",
    )


def window_info_from(value: object) -> WindowInfo:
    """An estimate's ``window`` part (a dict, as JSON gives it) as its class: a rotary window's prepare stage's
    facts read as ``RotaryWindowInfo``, every other window's as ``WindowInfo``."""
    return _WINDOW_INFO.validate_python(value)


_WINDOW_INFO: TypeAdapter[WindowInfo] = TypeAdapter(WindowInfo | RotaryWindowInfo)  # type: ignore[arg-type]
