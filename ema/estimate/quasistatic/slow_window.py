"""Window -> ``ema-estimate/1`` for a window logged under 1 kHz: the quasi-static reading (``quasistatic``) as
a document, the stages a high rate needs said to be skipped and why.

Stages here: **prepare** finds the stretches at constant speed and at rest and what the current says of the
torque (``TorqueReading``: the kind's), **physics** follows Eq. 5.1 to the stretches, **report** writes the
document. A window with no stretch long enough at constant speed carries no friction information at this
rate and is refused with that reason.
"""

from __future__ import annotations

import time
from collections.abc import Callable

import numpy as np

from ema.estimate.config import PipelineConfig
from ema.estimate.documents import (
    DIMENSIONLESS,
    STAGES,
    ActuatorRead,
    Check,
    Estimate,
    Estimates,
    Note,
    Timings,
    parameter,
)
from ema.estimate.documents.window_facts import WindowInfo
from ema.estimate.quasistatic.departure import DEPARTURE_Z, departure, inside
from ema.estimate.quasistatic.drive_torque import HealthyRuns, QuasiStaticReading
from ema.estimate.quasistatic.stretches import (
    MIN_STRETCH_S,
    QuasiStaticSolution,
    Stretch,
    TorqueReading,
    solve_stretches,
    stretches,
)
from ema.estimate.report import weakly_determined
from ema.estimate.stats import below_zero
from ema.model.actuator import ActuatorDocument
from ema.model.bounds import HIGH_RATE_HZ
from ema.model.checks import InputError
from ema.model.window import Window

MAX_CHI2 = 4.0  # the stretches about the model, per degree of freedom, beyond which it does not reproduce them
SKIPPED = {
    "simulate": f"the window is logged at under {HIGH_RATE_HZ:g} Hz: its own simulations at 1 µs would be compared "
    "with samples that average over its motor's dynamics",
    "learn": "no simulations to train the network on",
    "assess": "no held-out simulations: the std is the stretches' own noise and the document's repeatability",
    "check": "no simulation of the window at the answer: Eq. 5.1 solved on the stretches is the check",
}
QUASI_STATIC_STAGES = tuple(stage for stage in STAGES if stage not in SKIPPED)  # the stages a low-rate window runs


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
            f"no stretch at constant speed lasts {MIN_STRETCH_S:g} s (the window spans {window.duration_s:.3g} s at "
            f"{window.sample_rate_hz:g} Hz): read quasi-statically, a window shows friction only at constant speed",
        )
    torque, rest_note = reading.torque(actuator, rest)
    seconds["prepare"] = time.perf_counter() - started
    announce("solving Eq. 5.1 on the stretches")
    nominal, healthy = actuator.health, reading.healthy(actuator)
    eta_std = healthy.eta_o_std if healthy is not None else 0.0
    solution = solve_stretches(
        found,
        torque,
        actuator.gear_ratio,
        eta_o_document=(nominal.efficiency, eta_std),
        repeatability=reading.spread(actuator),
    )
    if below_zero({"FDJ": solution.fdj_nm}, {"FDJ": solution.fdj_std_nm}):
        raise InputError(
            "signals.current_a",
            f"the stretches read FDJ {solution.fdj_nm:.4g} ± {solution.fdj_std_nm:.2g} N·m, a friction that drives the "
            "motion: "
            "the current or the load is logged with the other sign (the log map's sign)",
        )
    seconds["physics"] = time.perf_counter() - started - seconds["prepare"]
    announce("writing the report")
    document = _document(window, actuator, solution, found, torque, digest=digest, read_with=read_with, config=config)
    said = (rest_note, *_notes(window, actuator, solution, torque), *departure_notes(actuator, solution, load, healthy))
    notes = [n for n in said if n is not None]
    seconds["report"] = time.perf_counter() - started - seconds["prepare"] - seconds["physics"]
    return document.model_copy(
        update={"notes": [*document.notes, *notes], "timings_s": Timings(**seconds, total=sum(seconds.values()))}
    )


def _estimates(actuator: ActuatorDocument, solution: QuasiStaticSolution) -> Estimates:
    nominal, ranges, friction = actuator.health, actuator.ranges, actuator.facts.friction_unit
    eta_a = float(actuator.eta_a(solution.eta_o))
    slope = float((actuator.eta_a(solution.eta_o + 1e-5) - actuator.eta_a(solution.eta_o - 1e-5)) / 2e-5)
    weak_eta = weakly_determined("eta_O", solution.eta_o_std, ranges)
    eta_o = parameter(solution.eta_o, solution.eta_o_std, nominal.eta_o, weak_eta, unit=DIMENSIONLESS)
    nominal_eta_a = None if nominal.eta_o is None else float(actuator.eta_a(nominal.eta_o))
    eta_a_entry = parameter(eta_a, abs(slope) * solution.eta_o_std, nominal_eta_a, weak_eta, unit=DIMENSIONLESS)
    weak_fdj = weakly_determined("FDJ", solution.fdj_std_nm, ranges)
    fdj = parameter(
        solution.fdj_nm,
        solution.fdj_std_nm,
        nominal.fdj,
        weak_fdj,
        unit=friction,
        repeatability_std=solution.fdj_repeatability_std_nm,
    )
    return Estimates(
        FDJ=fdj,
        eta_O=eta_o if solution.eta_o_read else None,
        eta_A=eta_a_entry if solution.eta_o_read else None,
        FSJ=None,
    )


def _document(
    window: Window,
    actuator: ActuatorDocument,
    solution: QuasiStaticSolution,
    found: list[Stretch],
    reading: TorqueReading,
    *,
    digest: str,
    read_with: ActuatorRead,
    config: PipelineConfig,
) -> Estimate:
    used = sum(s.samples for s in found)
    ratio = float(np.sqrt(solution.chi2_per_dof))
    rate = window.sample_rate_hz
    return Estimate(
        actuator_id=window.actuator_id,
        window_id=window.window_id,
        actuator=read_with,
        estimates=_estimates(actuator, solution),
        fsj_note=Note(
            code="fsj_no_break_away",
            text=(
                f"logged at {rate:g} Hz, the window shows no break-away to read FSJ from (a quasi-static break-away "
                f"needs 1 ms samples)"
            ),
        ),
        irreversible=solution.eta_o_read and float(actuator.eta_a(solution.eta_o)) < 0,
        notes=[],
        timings_s=Timings(total=0.0),
        stages={stage: f"skipped: {SKIPPED[stage]}" if stage in SKIPPED else "run" for stage in STAGES},
        dataset=None,
        learned=None,
        methods={},
        check=Check(
            reproduced=solution.chi2_per_dof <= MAX_CHI2,
            equation_error_ratio=ratio,
            output_error_ratio={"current_a": ratio},
            uncertainty_inflation=1.0,
        ),
        window=WindowInfo.logged(
            window,
            digest,
            processed_rate_hz=rate,
            command_clipped_fraction=0.0,
            sliding_fraction=used / window.n_samples,
        ),
        config=config,
    )


def departure_notes(
    actuator: ActuatorDocument, solution: QuasiStaticSolution, load_nm: np.ndarray, healthy: HealthyRuns | None
) -> list[Note]:
    """Where the window's FDJ departs from the nominal beyond what healthy runs allow (``departure``), either way,
    and where its load (``load_nm`` at the motor) lies outside those the healthy runs were learned at: said."""
    if healthy is None or healthy.healthy_set_nm is None:
        return []
    load = float(np.mean(load_nm)) * actuator.gear_ratio
    shared = float(np.sqrt(max(solution.fdj_std_nm**2 - solution.fdj_repeatability_std_nm**2, 0.0)))
    seen = departure(
        solution.fdj_nm,
        actuator.health.fdj,
        repeatability_std=solution.fdj_repeatability_std_nm,
        shared_std=shared,
        healthy_set=healthy.healthy_set_nm,
        extrapolated=not inside(load, healthy.loads_n),
    )
    notes = []
    if seen.extrapolated:
        learned = ", ".join(f"{n:.0f}" for n in healthy.loads_n or [])
        notes.append(
            Note(
                code="load_extrapolated",
                parameter="FDJ",
                text=f"the window's load, {load:.0f} N, lies outside those the healthy runs were learned at "
                f"({learned} N): the nominal is extrapolated here, and a change of FDJ within "
                f"±{DEPARTURE_Z * seen.allowed:.3f} N·m is not shown",
            )
        )
    if seen.departed:
        way = healthy.fell if seen.change < 0 else healthy.rose
        notes.append(
            Note(
                code="fdj_departed",
                parameter="FDJ",
                text=f"FDJ reads {seen.change:+.3f} N·m off the nominal, {seen.z:+.1f} times what healthy readings "
                f"allow: {way}",
            )
        )
    return notes


def _notes(
    window: Window, actuator: ActuatorDocument, solution: QuasiStaticSolution, reading: TorqueReading
) -> list[Note]:
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
    if not solution.eta_o_read:
        notes.append(
            Note(
                code="eta_o_unread",
                parameter="eta_O",
                text=(
                    "the window's load keeps one size: Eq. 5.1 shows FDJ + (1/η_O − 1)·|T_L| only, so η_O is not read "
                    "and FDJ "
                    f"is read with the document's η_O, {solution.eta_o:.3f} ± {solution.eta_o_std:.3f} "
                    "(its std in FDJ's); "
                    f"windows at "
                    "two loads read both (ema calibrate)"
                ),
            )
        )
    if solution.per_nm_read_a is not None and solution.per_nm_read_std_a is not None:
        z = (solution.per_nm_read_a - reading.per_nm_a) / max(solution.per_nm_read_std_a, 1e-12)
        if abs(z) > 4.0:
            notes.append(
                Note(
                    code="current_per_nm",
                    parameter="current_a",
                    text=(
                        f"opposing and aiding stretches put the current per N·m at {solution.per_nm_read_a:.3f} ± "
                        f"{solution.per_nm_read_std_a:.3f} A, {z:+.1f} stds from the document's "
                        f"{reading.per_nm_a:.3f}: the "
                        f"drive "
                        "or its current sensor departs from the document (recalibrate)"
                    ),
                )
            )
    return notes
