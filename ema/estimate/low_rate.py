"""Window -> ``ema-estimate/1`` for a window logged under 1 kHz: the quasi-static reading (``quasistatic``) as
a document, the stages a high rate needs said to be skipped and why.

Stages here: **prepare** finds the stretches at constant speed and at rest and what the current says of the
torque (``TorqueReading``: the kind's), **physics** fits Eq. 5.1 to the stretches, **report** writes the
document. A window with no stretch long enough at constant speed carries no friction information at this
rate and is refused with that reason.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from ema.estimate.config import PipelineConfig
from ema.estimate.documents import (
    DIMENSIONLESS,
    STAGES,
    ActuatorRead,
    Estimate,
    Estimates,
    FitCheck,
    Note,
    Timings,
    parameter,
)
from ema.estimate.documents.window import WindowInfo
from ema.estimate.quasistatic import (
    MIN_STRETCH_S,
    QuasiStaticFit,
    Rest,
    Stretch,
    TorqueReading,
    fit_stretches,
    logged_motion,
    set_point_motion,
    stretches,
)
from ema.estimate.report import weakly_determined
from ema.model.actuator import ActuatorDocument
from ema.model.checks import InputError
from ema.model.window import HIGH_RATE_HZ, Window

MAX_CHI2 = 4.0  # the stretches about the model, per degree of freedom, beyond which it does not reproduce them
SKIPPED = {
    "simulate": f"the window is logged at under {HIGH_RATE_HZ:g} Hz: its own simulations at 1 µs would be compared "
    "with samples that average over its motor's dynamics",
    "learn": "no simulations to train the network on",
    "assess": "no held-out simulations: the std is the stretches' own noise and the document's repeatability",
    "check": "no simulation of the window at the answer: the stretches' fit to Eq. 5.1 is the check",
}
QUASI_STATIC = tuple(stage for stage in STAGES if stage not in SKIPPED)  # the stages a low-rate window runs


REST_DEPARTURE = 4.0  # a window's current at rest this many day-to-day spreads off the document's: said


def motor_torque(actuator: ActuatorDocument, rest: Rest | None) -> tuple[TorqueReading, Note | None]:
    """A current-piloted motor's torque: k_T·I, signed."""
    return TorqueReading(1.0 / actuator.params.torque_constant_nm_per_a, 0.0, 0.0, 0.0, signed=True), None


def stepper_torque(actuator: ActuatorDocument, rest: Rest | None) -> tuple[TorqueReading, Note | None]:
    """A stepper drive's torque along the motion, (I − I0)/c, and a note where the window's current at rest
    departs from the document's current at zero torque.

    Its current at zero torque is the document's, learned over healthy runs, its std their spread: a window's own
    reading at rest scatters by more than its noise from one stop to the next (where the motor comes to rest
    within a step) and tells nothing of its current while it moves, so it only checks the document (a drive
    whose zero-torque current moved: recalibrate)."""
    screw = actuator.screw
    if screw is None or screw.current_per_nm_a is None or screw.current_at_zero_torque_a is None:
        raise InputError(
            "actuator.screw.current_per_nm_a",
            "is not known yet: a stepper's current per N·m and its "
            "current at zero torque are on no data sheet; run ema calibrate on healthy runs at two loads "
            "(--out-actuator) and read with that document",
        )
    spread = screw.current_at_zero_torque_std_a or 0.0
    reading = TorqueReading(
        screw.current_per_nm_a, screw.current_per_nm_std_a or 0.0, screw.current_at_zero_torque_a, spread, signed=False
    )
    if rest is None or abs(rest.current_a - screw.current_at_zero_torque_a) <= REST_DEPARTURE * max(spread, 1e-9):
        return reading, None
    note = Note(
        code="current_at_zero_torque",
        parameter="current_a",
        text=(
            f"at rest the drive draws {rest.current_a:.3f} A, {REST_DEPARTURE:g} or more of its day-to-day spreads "
            f"from the {screw.current_at_zero_torque_a:.3f} ± {spread:.3f} A the document learned: its zero-torque "
            "current may have moved (another day, another drive setting); FDJ counts it as friction until ema "
            "calibrate is rerun on healthy runs"
        ),
    )
    return reading, note


@dataclass(frozen=True)
class QuasiStaticReading:
    """What a kind reads a slow window by: its motion and load (``ema.estimate.quasistatic``), and what its
    drive's current says of the torque."""

    motion: Callable[[Window, float], tuple[np.ndarray, np.ndarray]]
    torque: Callable[[ActuatorDocument, Rest | None], tuple[TorqueReading, Note | None]]


MOTOR_READING = QuasiStaticReading(motion=logged_motion, torque=motor_torque)  # the logged speed, k_T·I
STEPPER_READING = QuasiStaticReading(motion=set_point_motion, torque=stepper_torque)  # the set point, (I − I0)/c


def estimate_low_rate(
    window: Window,
    config: PipelineConfig,
    *,
    reading: QuasiStaticReading,
    actuator: ActuatorDocument,
    read_with: ActuatorRead,
    on_stage: Callable[[str], None] | None = None,
) -> Estimate:
    """The ``ema-estimate/1`` result of a window logged under ``HIGH_RATE_HZ`` (module docstring)."""
    announce, seconds = on_stage or (lambda _: None), dict.fromkeys(STAGES, 0.0)
    started = time.perf_counter()
    announce("finding the stretches at constant speed and at rest")
    digest = window.content_sha256()
    speed, load = reading.motion(window, actuator.gear_ratio)
    found, rest = stretches(speed, window.signals["current_a"], load, window.sample_rate_hz)
    if not found:
        raise InputError(
            "signals",
            f"no stretch at constant speed lasts {MIN_STRETCH_S:g} s: at "
            f"{window.sample_rate_hz:g} Hz a window shows friction only at constant speed",
        )
    torque, rest_note = reading.torque(actuator, rest)
    seconds["prepare"] = time.perf_counter() - started
    announce("fitting Eq. 5.1 to the stretches")
    nominal = actuator.health
    screw = actuator.screw
    eta_std = (screw.eta_o_std if screw is not None else None) or 0.0
    repeat = (screw.repeatability_nm if screw is not None else None) or 0.0
    fit = fit_stretches(
        found, torque, actuator.gear_ratio, eta_o_document=(nominal.efficiency, eta_std), repeatability_nm=repeat
    )
    seconds["physics"] = time.perf_counter() - started - seconds["prepare"]
    announce("writing the report")
    document = _document(window, actuator, fit, found, torque, digest=digest, read_with=read_with, config=config)
    notes = [n for n in (rest_note, *_notes(window, actuator, fit, torque)) if n is not None]
    seconds["report"] = time.perf_counter() - started - seconds["prepare"] - seconds["physics"]
    return document.model_copy(
        update={"notes": [*document.notes, *notes], "timings_s": Timings(**seconds, total=sum(seconds.values()))}
    )


def _estimates(actuator: ActuatorDocument, fit: QuasiStaticFit) -> Estimates:
    nominal, ranges, friction = actuator.health, actuator.ranges, actuator.facts.friction_unit
    eta_a = float(actuator.eta_a(fit.eta_o))
    slope = float((actuator.eta_a(fit.eta_o + 1e-5) - actuator.eta_a(fit.eta_o - 1e-5)) / 2e-5)
    weak_eta = weakly_determined("eta_O", fit.eta_o_std, ranges)
    eta_o = parameter(fit.eta_o, fit.eta_o_std, nominal.eta_o, weak_eta, unit=DIMENSIONLESS)
    nominal_eta_a = None if nominal.eta_o is None else float(actuator.eta_a(nominal.eta_o))
    eta_a_entry = parameter(eta_a, abs(slope) * fit.eta_o_std, nominal_eta_a, weak_eta, unit=DIMENSIONLESS)
    weak_fdj = weakly_determined("FDJ", fit.fdj_std_nm, ranges)
    return Estimates(
        FDJ=parameter(fit.fdj_nm, fit.fdj_std_nm, nominal.fdj, weak_fdj, unit=friction),
        eta_O=eta_o if fit.eta_o_read else None,
        eta_A=eta_a_entry if fit.eta_o_read else None,
        FSJ=None,
    )


def _document(
    window: Window,
    actuator: ActuatorDocument,
    fit: QuasiStaticFit,
    found: list[Stretch],
    reading: TorqueReading,
    *,
    digest: str,
    read_with: ActuatorRead,
    config: PipelineConfig,
) -> Estimate:
    used = sum(s.samples for s in found)
    ratio = float(np.sqrt(fit.chi2_per_dof))
    rate = window.sample_rate_hz
    return Estimate(
        actuator_id=window.actuator_id,
        window_id=window.window_id,
        actuator=read_with,
        estimates=_estimates(actuator, fit),
        fsj_note=Note(
            code="fsj_no_break_away",
            text=(
                f"logged at {rate:g} Hz, the window shows no break-away to read FSJ from (a quasi-static break-away "
                f"needs 1 ms samples)"
            ),
        ),
        irreversible=fit.eta_o_read and float(actuator.eta_a(fit.eta_o)) < 0,
        notes=[],
        timings_s=Timings(total=0.0),
        stages={stage: f"skipped: {SKIPPED[stage]}" if stage in SKIPPED else "run" for stage in STAGES},
        dataset=None,
        training=None,
        methods={},
        fit_check=FitCheck(
            reproduced=fit.chi2_per_dof <= MAX_CHI2,
            equation_error_ratio=ratio,
            output_error_ratio={"current_a": ratio},
            uncertainty_inflation=1.0,
        ),
        window=WindowInfo(
            content_sha256=digest,
            n_samples=window.n_samples,
            duration_s=window.duration_s,
            sample_rate_hz=rate,
            processed_rate_hz=rate,
            command_clipped_fraction=0.0,
            sliding_fraction=used / window.n_samples,
            recorded_at=window.recorded_at,
            flight_hours=window.flight_hours,
            flight_id=window.flight_id,
        ),
        config=config,
    )


def _notes(window: Window, actuator: ActuatorDocument, fit: QuasiStaticFit, reading: TorqueReading) -> list[Note]:
    notes = [
        Note(
            code="low_rate",
            text=(
                f"logged at {window.sample_rate_hz:g} Hz (under {HIGH_RATE_HZ:g}): read quasi-statically, Eq. 5.1 on "
                f"the "
                "stretches at constant speed; the window's own simulations, the network and the check against a 1 µs "
                "simulation are skipped (stages)"
            ),
        )
    ]
    if not fit.eta_o_read:
        notes.append(
            Note(
                code="eta_o_unread",
                parameter="eta_O",
                text=(
                    "the window's load keeps one size: Eq. 5.1 shows FDJ + (1/η_O − 1)·|T_L| only, so η_O is not read "
                    "and FDJ "
                    f"is read with the document's η_O, {fit.eta_o:.3f} ± {fit.eta_o_std:.3f} (its std in FDJ's); "
                    f"windows at "
                    "two loads read both (ema calibrate)"
                ),
            )
        )
    if fit.per_nm_read_a is not None and fit.per_nm_read_std_a is not None:
        z = (fit.per_nm_read_a - reading.per_nm_a) / max(fit.per_nm_read_std_a, 1e-12)
        if abs(z) > 4.0:
            notes.append(
                Note(
                    code="current_per_nm",
                    parameter="current_a",
                    text=(
                        f"opposing and aiding stretches put the current per N·m at {fit.per_nm_read_a:.3f} ± "
                        f"{fit.per_nm_read_std_a:.3f} A, {z:+.1f} stds from the document's {reading.per_nm_a:.3f}: the "
                        f"drive "
                        "or its current sensor departs from the document (recalibrate)"
                    ),
                )
            )
    return notes
