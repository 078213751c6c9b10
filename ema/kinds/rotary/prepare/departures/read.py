"""What a window shows beyond the actuator document's model, read in turn, each on the window the
last corrected: the hinge moment's gain against the aircraft's
(``ema.kinds.rotary.prepare.departures.aircraft_check``), a sensor off zero
(``ema.kinds.rotary.prepare.departures.zero_offset``), the drive's k_T and J_M
(``ema.kinds.rotary.prepare.departures.drive_constants``), the hinge moment's gain its loads show
(``ema.kinds.rotary.prepare.departures.hinge_gain``), the viscous coefficient
(``ema.kinds.rotary.prepare.departures.viscosity``).

A drive constant, seen before it is read, passes in part for an offset, so where one is read the
offset is read again on the corrected window (the logged current is s·I + i₀: corrected, then
zeroed). Where the window's equation error cannot tell γ from ΔJ, both are read to the end and the
window simulated with each: the one whose replay follows the motor speed and current clearly
better, and within twice the noise, is taken (``_told_apart``). Where neither does, both ends
stand: what is read after them moves with the choice, so the stds grow by ``UNDECIDED_SHARE`` of
how far the two ends lie apart. So too where the aircraft only puts the strain gauge's gain in
doubt: the window is read as logged and with the aircraft's ratio divided out first (``_doubted``).
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from functools import cached_property

import numpy as np

from ema.estimate.documents import Note
from ema.estimate.stats import MAX_RATIO, white_noise_std
from ema.kinds.rotary.physics.features import solve_as_read
from ema.kinds.rotary.physics.scenario import CLEAR_MARGIN, following_error, inside, scenario_from_window
from ema.kinds.rotary.prepare.departures.aircraft_check import AircraftCheck, banded, divided_out
from ema.kinds.rotary.prepare.departures.drive_constants import UNDECIDED_SHARE, DriveReading, read_drive_constants
from ema.kinds.rotary.prepare.departures.hinge_gain import HingeGain, read_hinge_gain
from ema.kinds.rotary.prepare.departures.viscosity import Viscosity, read_viscosity
from ema.kinds.rotary.prepare.departures.zero_offset import ZeroOffset, read_zero_offset, zeroed
from ema.model.actuator import RotaryActuator
from ema.model.checks import InputError
from ema.model.noise import SensorNoise
from ema.model.params import DriveConstants
from ema.model.window import RotaryWindow

# A reading agrees with the J_M an actuator's history holds where it lies within this many stds of it.
AGREES_Z = 3.0


@dataclass(frozen=True)
class Known:
    """What other windows of the actuator read that this one may not (``documents.HistoryReadings``)."""

    zero: ZeroOffset | None = None  # the sensor zero of its flight
    inertia_factor: float | None = None  # its J_M over the document's ...
    inertia_std: float = 0.0
    inertia_from: tuple[str, ...] = ()  # ... and the windows that read it


@dataclass(frozen=True)
class Departures:
    window: RotaryWindow  # zeroed, its current on the document's k_T
    drive: DriveReading  # γ and ΔJ, and the drive's constants they were read against
    offset: ZeroOffset = field(default_factory=ZeroOffset)
    viscosity: Viscosity = field(default_factory=Viscosity)
    hinge: HingeGain = field(default_factory=HingeGain)
    aircraft: AircraftCheck = field(default_factory=AircraftCheck)
    inertia_from: tuple[str, ...] = ()  # γ or ΔJ undecided by the window: the windows whose J_M decided

    @property
    def drive_as_read(self) -> DriveConstants:
        """What every reconstruction and solution of the window reads it with: the document's, J_M and C as read."""
        return self.viscosity.drive_as_read(self.drive.drive_as_read)

    @cached_property
    def answer(self) -> dict[str, float]:
        """FDJ and η_O of Eq. 5.1's solution of the window as read (solved once: the tie-break and the stds ask)."""
        solved = solve_as_read(self.window.signals, self.window.sample_rate_hz, self.drive_as_read)
        return {name: float(value) for name, value in solved.values().items()}


def read_departures(
    window: RotaryWindow,
    actuator: RotaryActuator,
    aircraft: AircraftCheck = AircraftCheck(),
    known: Known = Known(),
) -> Departures:
    """The window corrected for what it shows beyond ``actuator``, and what that was (module docstring);
    its hinge moment's gain divided out first where the ``aircraft`` reads one; what other windows of the
    actuator read (``known``): the sensors' zero of its flight (``zero_offset.read_zero_offset``), its J_M
    where the window cannot tell a heavier rotor from a weaker motor (``_by_history``). Where the aircraft
    only puts the gauge's gain in doubt, its stds grow by ``UNDECIDED_SHARE`` of how far the reading moves
    with the gain divided out first (``_doubted``)."""
    aircraft = divided_out(aircraft)
    read = _read(window, actuator, aircraft, known)
    if not aircraft.in_doubt:
        return read
    try:
        divided = _read(window, actuator, replace(aircraft, factor=aircraft.ratio), known)
    except InputError:
        # the gain explains the window only with a motor no drive has: a refuted story, not a refusal of the
        # window, which the doubt alone never justifies
        return read
    return _doubted(read, divided)


def _doubted(read: Departures, divided: Departures) -> Departures:
    """``read``, its aircraft's spread ``UNDECIDED_SHARE`` of how far the answer of the window read with the
    aircraft's ratio ``divided`` out first lies: what an offset read on the moment as logged took in of the
    gain stays there (dividing the ratio out of the zeroed moment of a 0.1 s window in lbf·ft moved η_O
    0.004, dividing it out first 0.18, to the truth)."""
    mine, theirs = read.answer, divided.answer
    spread = {name: UNDECIDED_SHARE * abs(mine[name] - theirs[name]) for name in mine}
    return replace(read, aircraft=replace(read.aircraft, spread=spread))


def _read(window: RotaryWindow, actuator: RotaryActuator, aircraft: AircraftCheck, known: Known) -> Departures:
    """``read_departures`` with ``aircraft``'s factor as decided."""
    zero, spec = known.zero, actuator.params
    window = aircraft.corrected(window)
    offset = read_zero_offset(window, spec, zero)
    hinge = read_hinge_gain(zeroed(window, offset), spec, leading=True)
    if hinge.gain != 1.0:  # a logged g·H + b: the offset, b/g once the gain is taken off, read again
        window = hinge.corrected(window)
        offset = read_zero_offset(window, spec, zero)
    drive = read_drive_constants(zeroed(window, offset), spec)
    read = _along(window, offset, drive, hinge, aircraft, zero)
    if drive.alternative is None:
        return read
    other = _along(window, offset, drive.alternative, hinge, aircraft, zero)
    told = _told_apart(window, read, other, actuator) or _by_history(read, other, known)
    if told is not None:
        return replace(told, drive=replace(told.drive, alternative=None))
    mine, theirs = read.answer, other.answer
    spread = {name: float(np.hypot(drive.spread[name], UNDECIDED_SHARE * (mine[name] - theirs[name]))) for name in mine}
    return replace(read, drive=replace(drive, spread=spread))


NOISELESS_SPEED = 1e-6  # a speed's white-noise std under this share of its range: logged without noise


def _told_apart(
    window: RotaryWindow, scale: Departures, inertia: Departures, actuator: RotaryActuator
) -> Departures | None:
    """The reading whose simulation follows the window's motor speed and current clearly better
    (``CLEAR_MARGIN``), or None: γ as a torque constant or as a current sensor's gain, whichever
    follows better, against ΔJ; each at its own answer, with the viscous coefficient it read. Only
    where the better one follows within twice the noise: a replay that drifts from the drive (after a
    pilot's step, or where the loop saturates) drifts by tens of noise stds whichever constant it
    carries, and its preference is noise."""
    signals = window.signals
    noise = SensorNoise(
        motor_speed_radps=white_noise_std(signals["motor_speed_radps"]), current_a=white_noise_std(signals["current_a"])
    )
    if noise.motor_speed_radps < NOISELESS_SPEED * float(np.max(np.abs(signals["motor_speed_radps"])) or 1.0):
        return None  # a speed logged without noise: no replay follows it "within twice the noise" (saves three)

    def error(read: Departures, effect: str, **parameters: float) -> float:
        effects = read.viscosity.effects().with_effect(effect, **parameters)
        scenario = scenario_from_window(window, actuator.params, actuator.hinge, effects)
        health = inside(read.answer["FDJ"], read.answer["eta_O"], actuator.health.fdj)
        return following_error(scenario, window, health, noise)

    factor = scale.drive.torque_factor
    errors = (
        min(error(scale, "torque_constant", gain=factor), error(scale, "current_sensor_gain", gain=1.0 / factor)),
        error(inertia, "inertia", factor=inertia.drive.inertia_factor),
    )
    if min(errors) > 2 * MAX_RATIO:  # neither follows the drive within twice the noise on speed and current
        return None
    if errors[1] * (1.0 + CLEAR_MARGIN) < errors[0]:
        return inertia
    return scale if errors[0] * (1.0 + CLEAR_MARGIN) < errors[1] else None


def _by_history(scale: Departures, inertia: Departures, known: Known) -> Departures | None:
    """Of γ's reading and ΔJ's, which the window cannot tell apart, the one whose J_M agrees with the
    actuator's (``known``, read by windows that could: ``AGREES_Z``) where the other does not; else None.
    J_M stays with the build, k_T moves with the magnets' temperature."""
    factor = known.inertia_factor
    if factor is None:
        return None

    def z(read: Departures) -> float:
        drive = read.drive
        std = drive.stds.get("inertia_kgm2", 0.0) / drive.spec.inertia_kgm2
        return abs(drive.inertia_factor - factor) / float(np.hypot(std, known.inertia_std))

    agree = [read for read in (scale, inertia) if z(read) <= AGREES_Z]
    return replace(agree[0], inertia_from=known.inertia_from) if len(agree) == 1 else None


def _along(
    window: RotaryWindow,
    offset: ZeroOffset,
    drive: DriveReading,
    hinge: HingeGain,
    aircraft: AircraftCheck,
    zero: ZeroOffset | None,
) -> Departures:
    """The offset read first (again on the corrected window where a drive constant was read), then the
    hinge moment's gain unless it led (on the zeroed moment: a logged g·H + b), the band of the
    aircraft's where that was divided out and the window reads none, then C."""
    if drive.stds:
        window = drive.corrected(window)
        offset = read_zero_offset(window, drive.drive_as_read, zero)
    window = zeroed(window, offset)
    if hinge.gain == 1.0:
        hinge = read_hinge_gain(window, drive.drive_as_read)
        window = hinge.corrected(window)
    aircraft = banded(aircraft, window, hinge.gain, drive.drive_as_read)
    return Departures(window, drive, offset, read_viscosity(window, drive.drive_as_read), hinge, aircraft)


def history_note(read: Departures) -> list[Note]:
    """Where the actuator's J_M decided between γ and ΔJ, for the result's notes."""
    if not read.inertia_from:
        return []
    windows = ", ".join(read.inertia_from[:3]) + (
        f" and {len(read.inertia_from) - 3} more" if len(read.inertia_from) > 3 else ""
    )
    chosen = "a heavier rotor" if read.drive.inertia_kgm2 else "the motor's torque per k_T·I"
    return [
        Note(
            code="inertia_from_history",
            text=(
                "the window alone could not tell a heavier rotor from a weaker motor; the actuator's J_M as windows "
                "that "
                f"could read it ({windows}) decided for {chosen}"
            ),
        )
    ]
