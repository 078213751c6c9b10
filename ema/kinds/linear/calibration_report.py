"""``ema calibrate`` for a linear actuator: learn its drive from healthy runs, or say what faulted runs changed.

Learning (the document lacks c or a nominal health; ``ema.kinds.linear.drive_calibration.calibrate_drive``): the
report's ``drive`` holds what was learned, the residual of the runs' current before (the document's model) and
after, and a leave-one-run-out check; ``completed`` is the document with it. Comparing (a calibrated
document): each run read with it (``ema.estimate.quasistatic.slow_window``), FDJ (and η_O where the runs' loads
differ) set against the nominal in ``changes``, and the current along the stroke against the healthy
profile, named ``position_friction`` only beyond ``NAME_Z``.
"""

from __future__ import annotations

import time
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from ema.calibration.documents import (
    Candidate,
    DriveLearned,
    HeldOut,
    Learned,
    LinearCalibration,
    Step,
)
from ema.calibration.plot import ResidualPlot, Series
from ema.estimate.documents import DIMENSIONLESS
from ema.kinds.linear.changes import baseline, compared
from ema.kinds.linear.drive_calibration import CalibratedDrive, Run, calibrate_drive, read_run
from ema.model.actuator import LinearActuator, Nominal
from ema.model.params import load_factors
from ema.model.window import LinearWindow

ANCHOR = (
    "the current at zero torque and FDJ: at constant speed one number (I0 + c·FDJ); read against the runs' "
    "mean current at rest, I0"
)


def calibrate_linear(
    windows: Sequence[LinearWindow], actuator: LinearActuator
) -> tuple[LinearCalibration, LinearActuator | None, ResidualPlot]:
    """The report, the completed document where the runs taught the drive (None when comparing), and its figure."""
    started = time.perf_counter()
    runs = [read_run(w, actuator) for w in windows]
    screw = actuator.screw
    assert screw is not None
    if screw.current_per_nm_a is None or actuator.nominal is None:
        calibrated = calibrate_drive(runs, actuator)
        return _learned(runs, calibrated, actuator, started), completed(actuator, calibrated), _drive_plot(calibrated)
    return compared(windows, runs, actuator), None, _stroke_plot(runs, actuator)


def _drive_plot(calibrated: CalibratedDrive) -> ResidualPlot:
    """Each stretch's current about the document's model and about the drive learned, against its load."""
    return ResidualPlot(
        title="calibration: the drive learned",
        x_label="load torque at the motor, + towards increasing position [N·m]",
        y_label="current about the model [A]",
        series=[
            Series("before", calibrated.stretch_load_nm.tolist(), calibrated.stretch_residual_before_a.tolist()),
            Series("after", calibrated.stretch_load_nm.tolist(), calibrated.stretch_residual_after_a.tolist()),
        ],
    )


def _stroke_plot(runs: list[Run], actuator: LinearActuator) -> ResidualPlot:
    """The current along each stroke, less its mean: the healthy runs' (the document's) and these runs'."""
    healthy, _ = baseline(actuator)
    mean = np.nanmean([run.profile for run in runs], axis=0)
    bins = mean.shape[1]
    along = ((np.arange(bins) + 0.5) / bins).tolist()
    series = [Series(f"these runs, {way}", along, mean[row].tolist()) for row, way in enumerate(("up", "down"))]
    if np.isfinite(healthy).all() and healthy.shape == mean.shape:
        series += [Series(f"healthy, {way}", along, healthy[row].tolist()) for row, way in enumerate(("up", "down"))]
    return ResidualPlot(
        title="calibration: the current along the stroke",
        x_label="share of the stroke",
        y_label="current less its stroke's mean [A]",
        series=series,
    )


def _learned_constants(calibrated: CalibratedDrive) -> list[Learned]:
    """What the healthy runs taught, each with its std and unit: c and I0 always, the nominal FDJ and η_O where
    two load sizes read them, the run-to-run and healthy-set spreads where the runs showed them."""
    learned = [
        Learned(
            name="current_per_nm",
            value=calibrated.current_per_nm_a,
            std=calibrated.current_per_nm_std_a,
            unit="A/(N·m)",
        ),
        Learned(
            name="current_at_zero_torque",
            value=calibrated.current_at_zero_torque_a,
            std=calibrated.current_at_zero_torque_std_a,
            unit="A",
        ),
    ]
    if (
        calibrated.fdj_nm is not None
        and calibrated.fdj_std_nm is not None
        and calibrated.eta_o is not None
        and calibrated.eta_o_std is not None
    ):
        learned += [
            Learned(name="FDJ", value=calibrated.fdj_nm, std=calibrated.fdj_std_nm, unit="N·m"),
            Learned(name="eta_O", value=calibrated.eta_o, std=calibrated.eta_o_std, unit=DIMENSIONLESS),
        ]
    if calibrated.spread is not None:
        learned += [
            Learned(name="run_to_run", value=calibrated.spread.run_to_run_nm, std=0.0, unit="N·m"),
            Learned(name="healthy_set", value=calibrated.spread.set_nm, std=0.0, unit="N·m"),
        ]
    return learned


def _learned(
    runs: list[Run], calibrated: CalibratedDrive, actuator: LinearActuator, started: float
) -> LinearCalibration:
    unread = [ANCHOR] + (
        []
        if calibrated.fdj_nm is not None
        else [
            "FDJ and η_O: the runs hold one load size, so only FDJ + (1/η_O − 1)·|T_L| shows; give runs at a "
            "second load"
        ]
    )
    values = {
        name: getattr(calibrated, name) for name in DriveLearned.model_fields if hasattr(calibrated, name)
    }  # c, I0, FDJ, …
    drive = DriveLearned(
        **values,
        runs=len(runs),
        run_to_run_nm=None if calibrated.spread is None else calibrated.spread.run_to_run_nm,
        healthy_set_nm=None if calibrated.spread is None else calibrated.spread.set_nm,
        not_separable=unread,
    )
    before = {} if actuator.nominal is None else {"FDJ": actuator.nominal.fdj, "eta_O": actuator.nominal.eta_o}
    after = (
        {}
        if calibrated.fdj_nm is None or calibrated.eta_o is None
        else {"FDJ": calibrated.fdj_nm, "eta_O": calibrated.eta_o}
    )
    reason = (
        f"learned from {len(runs)} healthy run(s) at {', '.join(f'{n:.0f} N' for n in calibrated.loads_n)}: c "
        f"{calibrated.current_per_nm_a:.4f} ± {calibrated.current_per_nm_std_a:.4f} A/N·m, "
        f"I0 {calibrated.current_at_zero_torque_a:.3f} A"
    )
    report = _report(
        len(runs),
        calibrated.residual_before_a,
        calibrated.residual_after_a,
        before,
        after,
        steps=[Step(selected=None, reason=reason)],
        held=_leave_one_out(runs, actuator),
        started=started,
    )
    return report.model_copy(update={"drive": drive, "learned": _learned_constants(calibrated)})


def completed(actuator: LinearActuator, calibrated: CalibratedDrive) -> LinearActuator:
    """``actuator`` with what the runs taught (the nominal only where two load sizes read it)."""
    assert actuator.screw is not None
    screw = actuator.screw.model_copy(
        update={
            "current_per_nm_a": calibrated.current_per_nm_a,
            "current_per_nm_std_a": calibrated.current_per_nm_std_a,
            "current_at_zero_torque_a": calibrated.current_at_zero_torque_a,
            "current_at_zero_torque_std_a": calibrated.current_at_zero_torque_std_a,
            "eta_o_std": calibrated.eta_o_std,
            "repeatability_nm": calibrated.repeatability_nm,
            "run_to_run_nm": None if calibrated.spread is None else round(calibrated.spread.run_to_run_nm, 6),
            "run_noise_nm": None if calibrated.spread is None else round(calibrated.spread.run_noise_nm, 6),
            "healthy_set_nm": None if calibrated.spread is None else round(calibrated.spread.set_nm, 6),
            "calibrated_loads_n": calibrated.signed_loads_n,
            "stroke_profile_a": np.nan_to_num(calibrated.profile).round(5).tolist(),
            "stroke_profile_std_a": np.nan_to_num(calibrated.profile_std).round(5).tolist(),
        }
    )
    nominal = actuator.nominal
    if calibrated.fdj_nm is not None and calibrated.eta_o is not None:
        nominal = Nominal(fdj_nm=round(calibrated.fdj_nm, 5), eta_o=round(calibrated.eta_o, 4))
    document = actuator.model_dump(by_alias=True) | {
        "screw": screw.model_dump(),
        "nominal": nominal and nominal.model_dump(),
    }
    return LinearActuator.model_validate(document)


def _leave_one_out(runs: list[Run], actuator: LinearActuator) -> HeldOut:
    """Each run's stretches predicted by the drive learned on the others (at two runs or more)."""
    if len(runs) < 3:
        return HeldOut(rss_before=0.0, rss_after=0.0, adopted=True, note="too few runs to hold one out")
    before, after = 0.0, 0.0
    for i, run in enumerate(runs):
        others = calibrate_drive([r for j, r in enumerate(runs) if j != i], actuator)
        if others.fdj_nm is None or others.eta_o is None:
            return HeldOut(rss_before=0.0, rss_after=0.0, adopted=True, note="one load size: no run is predicted")
        rest, eta = others.current_at_zero_torque_a, others.eta_o
        for s in run.stretches:
            opposing = s.direction * s.load_nm < 0
            k = load_factors(eta, actuator.gear_ratio)[1 if opposing else 0]
            torque = others.fdj_nm + k * abs(s.load_nm) - s.direction * s.load_nm
            predicted = rest + others.current_per_nm_a * torque
            before += (s.current_a - rest) ** 2
            after += (s.current_a - predicted) ** 2
    return HeldOut(
        rss_before=before,
        rss_after=after,
        adopted=after < before,
        note=f"each run predicted by the drive learned on the other {len(runs) - 1}: the residual of its "
        f"stretches' current {np.sqrt(before / max(len(runs), 1)):.3f} → {np.sqrt(after / len(runs)):.3f} A",
    )


def _report(
    n: int,
    before_a: float,
    after_a: float,
    before: dict,
    after: dict,
    *,
    steps: list[Step],
    held: HeldOut,
    started: float,
    candidates: list[Candidate] | None = None,
) -> LinearCalibration:
    return LinearCalibration(
        n_windows=n,
        noise_floor=None,
        residual_rms_before={"current_a": before_a},
        residual_rms_after={"current_a": after_a},
        candidates=candidates or [],
        selected_effect=None,
        selected_effects=[],
        selected_parameters=None,
        effects={},
        selection_steps=steps,
        held_out=held,
        estimates_before=before,
        estimates_after=after,
        timings_s={"total": time.perf_counter() - started},
    )


def report_lines(report: Mapping[str, Any]) -> list[str]:
    """The drive its healthy runs taught (``drive``), or what its faulted runs changed (``changes``), for a person."""
    lines = [] if report.get("drive") is None else drive_lines(report["drive"])
    for change in report.get("changes", []):
        lines.append(
            f"{change['parameter']}: {change['said']} ({change['value']:.4g} ± {change['std']:.2g} against "
            f"nominal {change['nominal']:.4g})"
        )
    return lines


def drive_lines(drive: Mapping[str, Any]) -> list[str]:
    """The learned drive: c and I₀ with the runs' spread, the nominal FDJ and η_O, their repeatability."""
    loads = ", ".join(f"{n:.0f} N" for n in drive["loads_n"])
    lines = [
        f"learned from {drive['runs']} healthy run(s) at {loads}:",
        f"  current per N·m (c)     {drive['current_per_nm_a']:.4f} ± {drive['current_per_nm_std_a']:.4f} A/(N·m)",
        f"  current at zero torque  {drive['current_at_zero_torque_a']:.4f} ± "
        f"{drive['current_at_zero_torque_std_a']:.4f} A (the runs' spread)",
    ]
    if drive["fdj_nm"] is not None:
        lines.append(f"  nominal FDJ             {drive['fdj_nm']:.4f} ± {drive['fdj_std_nm']:.4f} N·m")
        lines.append(f"  nominal η_O             {drive['eta_o']:.3f} ± {drive['eta_o_std']:.3f}")
    if drive.get("run_to_run_nm") is not None:
        lines.append(f"  a healthy run's FDJ     scatters by {drive['run_to_run_nm']:.4f} N·m within a set (one load)")
        lines.append(f"  a healthy set's mean    sits within {drive['healthy_set_nm']:.4f} N·m of the nominal")
    else:
        lines.append(f"  repeatability of FDJ    {drive['repeatability_nm']:.4f} N·m beyond each run's own noise")
    return lines + [f"  not separable: {unread}" for unread in drive["not_separable"]]
