"""Calibration of a linear actuator's drive on its own runs: what the document lacks, learned; what changed, said.

A stepper's drive has no data-sheet current per N·m. At constant speed its current is I = I0 + c·τ, τ the
motor's torque along the motion (``ema.estimate.quasistatic.stretches``), I0 the current at zero torque, which the
drive also draws to hold the motor at rest. At constant speed I0 and c·FDJ are one number: no run tells
them apart, and the runs' mean current at rest anchors I0 (FDJ is read against it; the report says so).
Over runs at two loads or more:

    I − I0 = c·FDJ + c·(k·|T_L| − s·T_L),   k = 1/η_O − 1 opposing, 1 − η_A aiding,

is linear in c and c·FDJ at each η_O, so a profile over η_O reads all three. Opposing against aiding
stretches give c whatever FDJ; the loads' sizes separate FDJ from η_O; one load size leaves them one
number (FDJ + k·|T_L|), said so, and no nominal is written. Each run's FDJ scatters about the nominal
by more than its own noise: that excess is the runs' repeatability, written into the document and into
every later estimate's std.

**Learn** (the document lacks c or a nominal health): ``calibrate_drive`` writes the completed document.
**Compare** (a calibrated document): the runs are read with it, their FDJ (and η_O where their loads
differ) set against the nominal, and the current along the stroke against the healthy runs' own
profile (``screw.stroke_profile_a``): a friction that changes along the stroke (a local defect) is named
only where the runs' mean stands ``NAME_Z`` of one run's scatter (the larger of theirs and the healthy
runs', ``screw.stroke_profile_std_a``) above that profile; where nothing does, the report says what 25 Hz
cannot show. One run's scatter, not the standard error of the runs' mean: runs of one set share their
day and their load, and healthy sets logged apart differ by several standard errors of their means.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ema.estimate.least_squares import weighted
from ema.estimate.profile import ETA_GRID, profile_std
from ema.estimate.quasistatic.stretches import Stretch, stretches
from ema.estimate.stats import below_zero, between_runs_std, rms
from ema.kinds.linear.stepper_reading import set_point_motion
from ema.model.actuator import LinearActuator
from ema.model.checks import InputError
from ema.model.params import load_factors
from ema.model.window import LinearWindow

PROFILE_BINS = 8  # the current along each stroke, in this many bins, against the healthy runs'


@dataclass(frozen=True)
class Run:
    """One run as its stretches show it: each stretch's current over the run's own current at rest."""

    window_id: str
    stretches: list[Stretch]
    rest_a: float
    rest_std_a: float
    profile: np.ndarray  # (2, PROFILE_BINS): current along each direction's stroke, less its stroke's mean


def read_run(window: LinearWindow, actuator: LinearActuator) -> Run:
    """A run's stretches and rest; InputError naming the window where it has no stretch or never rests."""
    speed, load = set_point_motion(window, actuator.gear_ratio)
    found, rest = stretches(speed, window.signals["current_a"], load, window.sample_rate_hz)
    if not found or rest is None:
        why = "no stretch at constant speed" if not found else "no rest (the current at zero torque is read there)"
        raise InputError(f"window {window.window_id}", f"{why}: a calibration run moves at constant speed and rests")
    return Run(window.window_id, found, rest.current_a, rest.current_std_a, stroke_profile(window, found))


def stroke_profile(window: LinearWindow, found: list[Stretch]) -> np.ndarray:
    """(2, PROFILE_BINS): the current along each direction's first stretch (0: positive, 1: negative), binned by
    position and less that stretch's mean; NaN where a direction has none."""
    current, out = window.signals["current_a"], np.full((2, PROFILE_BINS), np.nan)
    for row, direction in enumerate((1, -1)):
        stretch = next((s for s in found if s.direction == direction), None)
        if stretch is None:
            continue
        values = current[stretch.first : stretch.first + stretch.samples]
        bins = np.array_split(values, PROFILE_BINS)
        out[row] = [b.mean() - values.mean() for b in bins]
    return out


@dataclass(frozen=True)
class HealthySpread:
    """How healthy runs read with the learned document scatter: what a comparison of windows, or of a set with
    the nominal, must allow (``ema.estimate.quasistatic.stretches``)."""

    run_to_run_nm: float  # the sd of one run's FDJ within a set (one load, one session), pooled over the sets
    run_noise_nm: float  # the typical std of one run's own noise (the median over the runs)
    set_nm: float  # how far a healthy set's mean sits off the nominal: the sets' RMS, never below run_to_run_nm


@dataclass(frozen=True)
class CalibratedDrive:
    """What healthy runs say of the drive and of the actuator new."""

    current_per_nm_a: float
    current_per_nm_std_a: float
    current_at_zero_torque_a: float
    current_at_zero_torque_std_a: float
    fdj_nm: float | None  # None: the runs' loads keep one size, FDJ and η_O are one number
    fdj_std_nm: float | None
    eta_o: float | None
    eta_o_std: float | None
    repeatability_nm: float
    spread: HealthySpread | None  # None: the runs keep one load size (no nominal to compare with)
    residual_before_a: float  # RMS of the stretches' current about the document's model (I0 alone where it has none)
    residual_after_a: float
    loads_n: list[float]
    signed_loads_n: list[float]  # each healthy set's load [N], its sign its direction
    profile: np.ndarray  # (2, PROFILE_BINS): the runs' mean current along each stroke (``Run.profile``)
    profile_std: np.ndarray  # its run-to-run std per bin
    stretch_load_nm: np.ndarray  # (S,) each stretch's load torque at the motor, + pushing towards increasing position
    stretch_residual_before_a: np.ndarray  # (S,) its current about the document's model
    stretch_residual_after_a: np.ndarray  # (S,) about the drive learned


def _design(runs: list[Run], eta: float, actuator: LinearActuator) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(X, y, w): y = I − I0 per stretch (I0 the runs' mean current at rest: the anchor of FDJ), X = [g, 1] with
    g = k·|T_L| − s·T_L at ``eta``, weights 1/σ²."""
    rest = float(np.mean([run.rest_a for run in runs]))
    k_aid, k_opp = load_factors(eta, actuator.gear_ratio)
    rows, y, w = [], [], []
    for run in runs:
        for s in run.stretches:
            opposing = s.direction * s.load_nm < 0
            rows.append([(k_opp if opposing else k_aid) * abs(s.load_nm) - s.direction * s.load_nm, 1.0])
            y.append(s.current_a - rest)
            w.append(1.0 / max(s.current_std_a**2, 1e-12))
    return np.array(rows), np.array(y), np.array(w)


def _refuse_reversed_signs(c: float, c_std: float, rests: np.ndarray) -> None:
    """Raise unless the runs' current rests above zero and grows with the torque the load opposes (neither
    ``below_zero``): a stepper's drive current is a magnitude, so a current at rest below zero is a current logged
    with the other sign, and a current falling where the load opposes the motion is a load (or a motion) so."""
    rest = float(rests.mean())
    rest_std = float(rests.std(ddof=1)) / np.sqrt(len(rests)) if len(rests) > 1 else 0.0  # the mean's std
    if below_zero({"rest": rest}, {"rest": rest_std}):
        raise InputError(
            "signals.current_a",
            f"the healthy runs draw {rest:.4g} A at rest: a stepper's current is a magnitude, so it is logged with "
            "the other sign (the log map's sign)",
        )
    if below_zero({"c": c}, {"c": c_std}):
        raise InputError(
            "signals.load_n",
            f"the healthy runs draw less current where the load opposes the motion (c = {c:.4g} ± {c_std:.2g} "
            "A/(N·m)): the load or the motion is logged with the other sign (the log map's sign)",
        )


def calibrate_drive(runs: list[Run], actuator: LinearActuator) -> CalibratedDrive:
    """c, I0, and (at two load sizes or more) the nominal FDJ and η_O, from healthy ``runs`` (module docstring)."""
    profiles = [weighted(*_design(runs, float(eta), actuator)) for eta in ETA_GRID]
    chi2 = np.array([p[2] for p in profiles])
    best = int(np.argmin(chi2))
    (c, c_fdj), covariance, chi2_min = profiles[best]
    x, y, _ = _design(runs, float(ETA_GRID[best]), actuator)
    dof = max(len(y) - 3, 1)
    birge = max(1.0, float(np.sqrt(chi2_min / dof)))
    sizes = sorted({round(abs(s.load_nm), 6) for run in runs for s in run.stretches})
    separable = len(sizes) > 1 and float(np.ptp(sizes)) > 0.2 * float(np.mean(sizes))
    rests = np.array([run.rest_a for run in runs])
    c_std = float(np.sqrt(covariance[0, 0])) * birge
    _refuse_reversed_signs(c, c_std, rests)
    fdj = c_fdj / c
    eta_std = profile_std(ETA_GRID, chi2, rise=birge**2)
    per_run = [_run_fdj(run, c, float(ETA_GRID[best]), actuator) for run in runs]
    repeat = between_runs_std(np.array([f for f, _ in per_run]), np.array([s for _, s in per_run]))
    anchored = [_run_fdj(run, c, float(ETA_GRID[best]), actuator, float(rests.mean())) for run in runs]
    return CalibratedDrive(
        current_per_nm_a=float(c),
        current_per_nm_std_a=c_std,
        current_at_zero_torque_a=float(rests.mean()),
        current_at_zero_torque_std_a=float(rests.std(ddof=1)) if len(rests) > 1 else float(runs[0].rest_std_a),
        fdj_nm=float(fdj) if separable else None,
        fdj_std_nm=float(np.sqrt(covariance[1, 1]) * birge / c) if separable else None,
        eta_o=float(ETA_GRID[best]) if separable else None,
        eta_o_std=eta_std if separable else None,
        repeatability_nm=repeat,
        spread=healthy_spread(runs, anchored, float(fdj)) if separable else None,
        residual_before_a=rms(y - _predicted_before(runs, actuator)),
        residual_after_a=rms(y - x @ np.array([c, c_fdj])),
        stretch_load_nm=np.array([s.load_nm for run in runs for s in run.stretches]),
        stretch_residual_before_a=y - _predicted_before(runs, actuator),
        stretch_residual_after_a=y - x @ np.array([c, c_fdj]),
        loads_n=[round(size * actuator.gear_ratio, 3) for size in sizes],
        signed_loads_n=signed_loads(runs, actuator.gear_ratio),
        profile=np.nanmean([run.profile for run in runs], axis=0),
        profile_std=np.nanstd([run.profile for run in runs], axis=0, ddof=1)
        if len(runs) > 1
        else np.full((2, PROFILE_BINS), np.nan),
    )


def _run_fdj(
    run: Run, c: float, eta: float, actuator: LinearActuator, rest_a: float | None = None
) -> tuple[float, float]:
    """One run's FDJ (and its std) at ``c`` and ``eta``: the stretches' mean of (I − I0)/c − g, I0 the run's own
    current at rest, or ``rest_a`` (the document's: as an estimate reads the run)."""
    x, y, w = _design([run], eta, actuator)
    if rest_a is not None:
        y = y + run.rest_a - rest_a
    values = y / c - x[:, 0]
    weights = w * c**2
    return float(np.sum(weights * values) / np.sum(weights)), float(1.0 / np.sqrt(np.sum(weights)))


def run_load_n(run: Run, gear_ratio: float) -> float:
    """A run's load [N], its sign its direction (the load holds one size through a run)."""
    return float(np.median([s.load_nm for s in run.stretches])) * gear_ratio


def signed_loads(runs: list[Run], gear_ratio: float) -> list[float]:
    """The distinct loads the runs were logged at [N], signed."""
    loads: list[float] = []
    for load in sorted(run_load_n(run, gear_ratio) for run in runs):
        if not loads or abs(load - loads[-1]) > 0.1 * max(abs(load), abs(loads[-1])):
            loads.append(round(load, 3))
    return loads


def healthy_spread(runs: list[Run], per_run: list[tuple[float, float]], nominal_fdj_nm: float) -> HealthySpread:
    """The runs' FDJ (as an estimate reads each, the document's I0) grouped into sets of one load size: their
    pooled run-to-run sd, their typical own noise, and the sets' RMS off the nominal. A set logged on another day
    may sit off the nominal by as much as one run scatters (the drive's current at zero torque drifts from one
    day to the next), so that spread is never taken below the run-to-run sd."""
    groups: dict[float, list[float]] = {}
    for run, (value, _) in zip(runs, per_run, strict=True):
        size = float(np.median([abs(s.load_nm) for s in run.stretches]))
        key = next((k for k in groups if abs(k - size) <= 0.1 * max(k, size)), size)
        groups.setdefault(key, []).append(value)
    deviations = [np.asarray(v) - np.mean(v) for v in groups.values() if len(v) > 1]
    dof = sum(len(d) - 1 for d in deviations)
    run_to_run = (
        float(np.sqrt(sum(float(d @ d) for d in deviations) / dof)) if dof else float(np.std([v for v, _ in per_run]))
    )
    sets = rms(np.array([np.mean(v) - nominal_fdj_nm for v in groups.values()]))
    noise = float(np.median([std for _, std in per_run]))
    return HealthySpread(run_to_run_nm=run_to_run, run_noise_nm=noise, set_nm=max(sets, run_to_run))


def _predicted_before(runs: list[Run], actuator: LinearActuator) -> np.ndarray:
    """What the document as given predicts of I − I0: its own c and nominal where it has them, else nothing."""
    screw, nominal = actuator.screw, actuator.nominal
    if screw is None or screw.current_per_nm_a is None or nominal is None:
        return np.zeros(sum(len(run.stretches) for run in runs))
    x, _, _ = _design(runs, nominal.efficiency, actuator)
    return screw.current_per_nm_a * (x[:, 0] + nominal.fdj_nm)


def profile_change(runs: list[Run], baseline: np.ndarray, baseline_std: np.ndarray) -> tuple[float, np.ndarray]:
    """z of the runs' current along the stroke against the healthy ``baseline`` profile: the largest bin's
    departure of the runs' mean over one run's scatter there (the larger of the runs' std and the healthy
    runs' ``baseline_std``; module docstring), and that departure per bin."""
    stack = np.array([run.profile for run in runs])
    if len(runs) < 2 or not np.isfinite(baseline).any():
        return 0.0, np.zeros_like(stack[0])
    departure = np.nanmean(stack, axis=0) - baseline
    spread = np.fmax(np.nanstd(stack, axis=0, ddof=1), baseline_std)
    z = np.abs(departure) / np.maximum(spread, 1e-6)
    return float(np.nanmax(z)), departure
