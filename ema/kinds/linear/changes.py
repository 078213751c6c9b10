"""``ema calibrate`` on a stepper's runs against its calibrated document: what changed, in physical terms.

Each run is read with the document (``ema.estimate.quasistatic``). Per load the runs were logged at, their
mean FDJ is set against the nominal (``ema.estimate.quasistatic.departure``): a departure either way beyond what
healthy sets allow (a friction that falls is one too: a screw losing its preload), with the load outside the
healthy runs' loads said to be extrapolated, and how large a change it could not show. Where the runs span two
load sizes, η_O is read over all of them and set against the nominal likewise. Along the stroke, the current
is set against the healthy runs' own profile (``ema.kinds.linear.drive_calibration.profile_change``): a friction that
changes along the stroke is named only beyond ``NAME_Z`` of one run's scatter. Each change carries its
machine-readable verdict (``departed``) beside its sentence.
"""

from __future__ import annotations

import time
from collections.abc import Sequence

import numpy as np

from ema.calibration.documents import Candidate, Change, HeldOut, LinearCalibration, Step
from ema.calibration.limits import NAME_Z
from ema.estimate.config import PipelineConfig
from ema.estimate.documents import DIMENSIONLESS, ActuatorRead, Estimate
from ema.estimate.quasistatic.departure import DEPARTURE_Z, Departure, departure, inside
from ema.estimate.quasistatic.slow_window import estimate_low_rate
from ema.estimate.quasistatic.stretches import solve_stretches
from ema.kinds.linear.drive_calibration import Run, profile_change, run_load_n
from ema.kinds.linear.stepper_reading import FELL, ROSE, STEPPER_READING
from ema.model.actuator import LinearActuator
from ema.model.window import LinearWindow


def fdj_changes(runs: list[Run], results: list[Estimate], actuator: LinearActuator) -> list[Change]:
    """Per load the runs were logged at: their mean FDJ against the nominal, departed either way or not."""
    screw, nominal = actuator.screw, actuator.health.fdj
    assert screw is not None  # the linear kind's own section
    loads = np.array([run_load_n(run, actuator.gear_ratio) for run in runs])
    changes = []
    for load in sorted({round(float(x), 0) for x in loads}):
        chosen = [r.estimates.FDJ for r, x in zip(results, loads, strict=True) if abs(x - load) <= 0.1 * abs(load)]
        values = np.array([e.value for e in chosen])
        repeatable = np.array([e.repeatability_std or e.std or 0.0 for e in chosen])
        shared = np.sqrt(np.maximum(np.array([e.std or 0.0 for e in chosen]) ** 2 - repeatable**2, 0.0))
        scatter = float(np.std(values, ddof=1)) if len(values) > 1 else 0.0
        seen = departure(
            float(np.mean(values)),
            nominal,
            repeatability_std=max(float(np.median(repeatable)), scatter),
            shared_std=float(np.median(shared)),
            healthy_set=screw.healthy_set_nm or float(np.median(repeatable)),
            runs=len(values),
            extrapolated=not inside(load, screw.calibrated_loads_n),
        )
        changes.append(_fdj_change(seen, load, nominal, len(values)))
    return changes


def _fdj_change(seen: Departure, load: float, nominal: float, runs: int) -> Change:
    where = f"at {load:.0f} N"
    if seen.departed:
        said = (
            f"FDJ {where} {'fell' if seen.change < 0 else 'rose'} by {abs(seen.change):.3f} N·m over {runs} run(s), "
            f"{seen.z:+.1f} times what healthy sets allow: {FELL if seen.change < 0 else ROSE}"
        )
    else:
        said = f"FDJ {where} moved {seen.change:+.3f} N·m, {seen.z:+.1f} times what healthy sets allow: within them"
    if seen.extrapolated:
        said += (
            f"; this load lies outside those the healthy runs were learned at, where the nominal is extrapolated: "
            f"a change within ±{DEPARTURE_Z * seen.allowed:.3f} N·m is not shown here"
        )
    return Change(
        parameter="FDJ",
        load_n=load,
        nominal=nominal,
        value=nominal + seen.change,
        std=seen.allowed,
        z=seen.z,
        departed=seen.departed,
        unit="N·m",
        said=said,
    )


def eta_change(runs: list[Run], actuator: LinearActuator) -> Change | None:
    """η_O over every run where their loads differ enough to read it, against the nominal; None where not."""
    torque, _ = STEPPER_READING.torque(actuator, None)
    screw, health = actuator.screw, actuator.health
    assert screw is not None  # the linear kind's own section
    eta_std = screw.eta_o_std or 0.0
    found = [s for run in runs for s in run.stretches]
    calibrated = solve_stretches(found, torque, actuator.gear_ratio, eta_o_document=(health.efficiency, eta_std))
    if not calibrated.eta_o_read:
        return None
    allowed = float(np.hypot(calibrated.eta_o_std, eta_std))
    z = (calibrated.eta_o - health.efficiency) / max(allowed, 1e-12)
    departed = abs(z) > DEPARTURE_Z
    said = (
        f"η_O reads {calibrated.eta_o:.3f} ± {calibrated.eta_o_std:.3f} over the runs' loads, {z:+.1f} times its "
        "uncertainty off "
        f"the nominal {health.efficiency:.3f}: "
        + (
            "the transmission's efficiency under load changed (a lubricant, a preload)"
            if departed
            else "within its uncertainty"
        )
    )
    return Change(
        parameter="eta_O",
        nominal=health.efficiency,
        value=calibrated.eta_o,
        std=allowed,
        z=z,
        departed=departed,
        unit=DIMENSIONLESS,
        said=said,
    )


def stroke_step(runs: list[Run], actuator: LinearActuator) -> tuple[Step, Candidate]:
    """The current along the stroke against the healthy runs' profile: a step naming a local change or not (not
    compared at a load outside those the profile was learned at: its shape is the load's too)."""
    healthy = baseline(actuator)
    learned = actuator.screw.calibrated_loads_n if actuator.screw is not None else None
    loads = {round(run_load_n(run, actuator.gear_ratio)) for run in runs}
    outside = sorted(load for load in loads if not inside(load, learned))
    if outside:
        healthy = (np.full_like(healthy[0], np.nan), np.full_like(healthy[1], np.nan))
    profile_z, departure_a = profile_change(runs, *healthy)
    named = profile_z >= NAME_Z
    candidate = Candidate(
        effect="position_friction",
        follows="position_mm",
        named=True,
        parameters={f"bin_{i}": float(v) for i, v in enumerate(np.nan_to_num(departure_a).ravel())},
        rms_reduction=0.0,
        held_out_drop=0.0,
        score=profile_z,
        plausible=True,
    )
    reason = (
        f"the current along the stroke departs from the healthy runs' by {profile_z:.1f} run-to-run stds: a "
        "friction that changes along the stroke (a local defect)"
        if named
        else f"nothing beyond FDJ stands above the runs' noise along the stroke (z = {profile_z:.1f} < {NAME_Z:g}): a "
        "local defect such as a spall may well be invisible in a current logged at 25 Hz"
        if np.isfinite(healthy[1]).any()
        else f"the stroke is not compared at {', '.join(f'{n} N' for n in outside)}: the healthy profile was learned "
        "at other loads, and its shape is the load's as much as the screw's"
        if outside
        else "the stroke is not compared: the document holds no healthy profile along it with its run-to-run spread "
        "(learn the drive again with ema calibrate on healthy runs)"
    )
    return Step(selected="position_friction" if named else None, reason=reason), candidate


def baseline(actuator: LinearActuator) -> tuple[np.ndarray, np.ndarray]:
    """The healthy runs' profile along the stroke and its run-to-run std; NaN where the document lacks either (one
    learned before the std was kept: the runs' own scatter alone would take a load's profile for a defect)."""
    screw = actuator.screw
    if screw is None or not screw.stroke_profile_a or not screw.stroke_profile_std_a:
        return np.full((2, 1), np.nan), np.full((2, 1), np.nan)
    return np.array(screw.stroke_profile_a, dtype=float), np.array(screw.stroke_profile_std_a, dtype=float)


def compared(windows: Sequence[LinearWindow], runs: list[Run], actuator: LinearActuator) -> LinearCalibration:
    """The runs against the calibrated document (module docstring)."""
    started = time.perf_counter()
    read_with = ActuatorRead(name=actuator.name)
    results = [
        estimate_low_rate(w, PipelineConfig(), reading=STEPPER_READING, actuator=actuator, read_with=read_with)
        for w in windows
    ]
    changes = [*fdj_changes(runs, results, actuator), *([c] if (c := eta_change(runs, actuator)) else [])]
    step, candidate = stroke_step(runs, actuator)
    named = step.selected is not None
    fdj = float(np.mean([r.estimates.FDJ.value for r in results]))
    return LinearCalibration(
        n_windows=len(runs),
        noise_floor=None,
        residual_rms_before={"current_a": 0.0},
        residual_rms_after={"current_a": 0.0},
        candidates=[candidate],
        selected_effect="position_friction" if named else None,
        selected_effects=["position_friction"] if named else [],
        selected_parameters=None,
        effects={},
        selection_steps=[step],
        held_out=HeldOut(rss_before=0.0, rss_after=0.0, adopted=False, note="runs read with the document"),
        estimates_before={"FDJ": actuator.health.fdj},
        estimates_after={"FDJ": fdj},
        changes=changes,
        timings_s={"total": time.perf_counter() - started},
    )
