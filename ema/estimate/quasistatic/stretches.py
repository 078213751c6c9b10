"""A window logged under 1 kHz, read with what its rate allows: Eq. 5.1 at constant speed.

At constant speed the inertia takes nothing (J·dω/dt = 0), and the motor's torque along the motion is

    τ = FDJ + k·|T_L| − s·T_L,   k = 1/η_O − 1 (opposing: s·T_L < 0) or 1 − η_A (aiding),

with s = sgn(ω) and T_L the load torque at the motor in the positive direction (a hinge moment over the
gear ratio, a screw's force times lead/2π). Each stretch at constant speed gives one mean τ and one
|T_L|. Where the stretches hold loads of several sizes the profile over η_O (η_A tied by Eq. 3.4) reads
FDJ and η_O together; at one load only FDJ + k·|T_L| is in the window, η_O is not read (``eta_O`` null,
note ``eta_o_unread``), and FDJ is read with the document's η_O, its std carrying that η_O's.

What the current says of τ is the kind's (``TorqueReading``): a current-piloted motor's k_T·I, or a
stepper drive's (I − I0)/c, its current at zero torque I0 read at rest in this window (it drifts from
one day to the next; a window that never rests takes the document's, with its day-to-day spread).

Two stds, for two questions. ``repeatability_std`` is what a second window read with the same document would
not share: the run-to-run scatter of one state as ``ema calibrate`` measured it on healthy runs
(``screw.run_to_run_nm``: each run's own noise and the day's drift of the drive's current at zero torque
within it), widened where this window is noisier than those runs were (its stretches' block-estimated noise
beyond ``screw.run_noise_nm``). It is what a trend, a status or a comparison of two windows judges a change
on. ``std`` adds what every window read with the document shares: the learned η_O's std (through the load
term) and c's (every torque scales with it). A document learned before the run-to-run sd was kept has the
runs' excess scatter over every load instead (``screw.repeatability_nm``), and its I0 spread is added apart.

The stages that need a high rate (the window's own simulations, the network, the check against a 1 µs
simulation) are skipped, and the estimate says so (``stages``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ema.estimate.profile import ETA_GRID, profile_std
from ema.estimate.stats import rms
from ema.model.params import eta_a_of, load_factors

BLOCKS = 5  # a stretch's mean and its std from this many blocks (the current is correlated over samples)
STRETCH_SETTLE_S = 0.4  # after a change of speed, the drive settles this long before a stretch is read
REST_SETTLE_S = 1.5  # after the motion stops, the drive's current settles this long before it reads I0
MIN_STRETCH_S = 1.0  # a stretch at constant speed, or at rest, this long at least (after settling)
SPEED_TOLERANCE = 0.02  # constant speed: within this share of the stretch's own speed
MIN_LOAD_SPREAD = 0.2  # |T_L| must vary by this share of its mean for a window to read η_O beside FDJ


@dataclass(frozen=True)
class Stretch:
    """A stretch at constant speed: its motion's sign, its mean current and load torque, with stds."""

    direction: int  # sgn(ω)
    current_a: float
    current_std_a: float
    load_nm: float  # T_L at the motor, positive direction
    samples: int
    first: int  # its first sample (for the report)


@dataclass(frozen=True)
class Rest:
    current_a: float
    current_std_a: float
    samples: int


def block_mean(values: np.ndarray) -> tuple[float, float]:
    """The mean and its std from ``BLOCKS`` block means (honest where samples are correlated)."""
    blocks = np.array_split(values, min(BLOCKS, len(values)))
    means = np.array([b.mean() for b in blocks])
    return float(values.mean()), float(means.std(ddof=1) / np.sqrt(len(means))) if len(means) > 1 else float("inf")


def runs(mask: np.ndarray) -> list[tuple[int, int]]:
    """[start, stop) of each run of True in ``mask``."""
    edges = np.flatnonzero(np.diff(np.concatenate([[0], mask.astype(int), [0]])))
    return list(zip(edges[::2].tolist(), edges[1::2].tolist(), strict=True))


def stretches(
    speed: np.ndarray, current: np.ndarray, load_nm: np.ndarray, rate: float
) -> tuple[list[Stretch], Rest | None]:
    """The stretches at constant speed (by the commanded or logged ``speed``) and at rest, each after its
    settling (``STRETCH_SETTLE_S``; at rest ``REST_SETTLE_S``: a stepper's current decays for a second after it stops),
    at least ``MIN_STRETCH_S`` long."""
    settle, least = round(STRETCH_SETTLE_S * rate), max(round(MIN_STRETCH_S * rate), BLOCKS)
    rest_settle = round(REST_SETTLE_S * rate)
    top = float(np.max(np.abs(speed))) if len(speed) else 0.0
    moving = np.abs(speed) > 0.05 * top
    change = np.abs(np.diff(speed, prepend=speed[0])) > SPEED_TOLERANCE * max(top, 1e-12)
    found, rest = [], []
    for start, stop in runs(moving & ~change):
        start += settle
        if stop - start >= least:
            mean, std = block_mean(current[start:stop])
            found.append(Stretch(int(np.sign(speed[start])), mean, std, float(load_nm[start:stop].mean()),
                                 stop - start, start))  # fmt: skip
    for start, stop in runs(~moving):
        if stop - (start + rest_settle) >= least:
            rest.append(current[start + rest_settle : stop])
    if not rest:
        return found, None
    held = np.concatenate(rest)
    mean, std = block_mean(held)
    return found, Rest(mean, std, len(held))


@dataclass(frozen=True)
class TorqueReading:
    """What the drive's current says of the motor's torque along the motion: τ = (I·s − offset) / per_nm."""

    per_nm_a: float  # current per N·m (1/k_T for a current-piloted motor, c for a stepper)
    per_nm_std_a: float
    offset_a: float  # current at zero torque (0 for a current-piloted motor)
    offset_std_a: float
    signed: bool  # the current's sign follows the torque's (a phase current), else a magnitude along the motion

    def torque(self, stretch: Stretch) -> tuple[float, float]:
        """τ along the motion and its std from the stretch's own noise (I0's and c's, common to every stretch,
        enter FDJ's std in the solution)."""
        along = stretch.current_a * stretch.direction if self.signed else stretch.current_a
        return (along - self.offset_a) / self.per_nm_a, stretch.current_std_a / self.per_nm_a


@dataclass(frozen=True)
class Repeatability:
    """What the document says of how one state's runs scatter (``ema.kinds.linear.drive_calibration.HealthySpread``)."""

    run_to_run_nm: float | None = None  # the healthy runs' sd within a set (null: not learned)
    run_noise_nm: float = 0.0  # their typical own noise
    excess_nm: float = 0.0  # an older document's: the runs' scatter beyond their noise, over every load


@dataclass(frozen=True)
class QuasiStaticSolution:
    fdj_nm: float
    fdj_std_nm: float
    fdj_repeatability_std_nm: float  # what a second window read with the document would not share
    eta_o: float
    eta_o_std: float
    eta_o_read: bool  # False: held at the document's (one load)
    chi2_per_dof: float  # of the stretches about the model, with their stds (≈ 1 where it explains them)
    per_nm_read_a: float | None  # c (or 1/k_T) as the window reads it from opposing against aiding stretches
    per_nm_read_std_a: float | None


def solve_stretches(
    found: list[Stretch],
    reading: TorqueReading,
    gear_ratio: float,
    *,
    eta_o_document: tuple[float, float],
    repeatability: Repeatability = Repeatability(),
) -> QuasiStaticSolution:
    """FDJ (and η_O where the loads differ enough) from ``found`` stretches: y = τ + s·T_L = FDJ + k·|T_L|."""
    torques = np.array([reading.torque(s) for s in found])
    tau, tau_std = torques[:, 0], torques[:, 1]
    load = np.array([s.load_nm for s in found])
    direction = np.array([s.direction for s in found])
    y, size, opposing = tau + direction * load, np.abs(load), direction * load < 0
    weight = 1.0 / np.maximum(tau_std, 1e-12) ** 2
    spread = float(np.ptp(size)) / max(float(np.mean(size)), 1e-12) if len(size) else 0.0

    def fdj_at(eta: float) -> tuple[float, float]:
        k_aid, k_opp = load_factors(eta, gear_ratio)
        rest = y - np.where(opposing, k_opp, k_aid) * size
        fdj = float(np.sum(weight * rest) / np.sum(weight))
        return fdj, float(np.sum(weight * (rest - fdj) ** 2))

    read = spread >= MIN_LOAD_SPREAD and len(found) >= 3
    if read:
        chi2 = np.array([fdj_at(eta)[1] for eta in ETA_GRID])
        best = int(np.argmin(chi2))
        eta, eta_std = float(ETA_GRID[best]), profile_std(ETA_GRID, chi2)
    else:
        eta, eta_std = eta_o_document
    fdj, chi2_min = fdj_at(eta)
    dof = max(len(found) - 1 - int(read), 1)
    slope = float(np.mean(np.where(opposing, 1.0 / eta**2, -_eta_a_slope(eta, gear_ratio)) * size))  # ∂FDJ/∂η_O
    within = float(1.0 / np.sqrt(np.sum(weight)))
    scale = float(np.mean(np.abs(tau))) * _rel(reading)  # every torque scales with c: FDJ's share of it
    repeatable, shared = _repeatable_and_shared(within, repeatability, reading)
    fdj_std = float(np.sqrt(repeatable**2 + (slope * eta_std) ** 2 + scale**2 + shared**2))
    per_nm = _per_nm_read(found, reading, eta, gear_ratio)
    return QuasiStaticSolution(fdj, fdj_std, repeatable, eta, eta_std, read, chi2_min / dof, *per_nm)


def _repeatable_and_shared(within: float, repeatability: Repeatability, reading: TorqueReading) -> tuple[float, float]:
    """(the repeatability std, what else an older document leaves every window sharing) of FDJ (module docstring)."""
    if repeatability.run_to_run_nm is not None:
        noisier = max(within**2 - repeatability.run_noise_nm**2, 0.0)
        return float(np.sqrt(repeatability.run_to_run_nm**2 + noisier)), 0.0
    offset = reading.offset_std_a / reading.per_nm_a  # I0's spread moves every torque, so FDJ, alike
    return float(np.hypot(within, repeatability.excess_nm)), offset


def _rel(reading: TorqueReading) -> float:
    """c's relative std: every torque, and so FDJ, scales with it."""
    return reading.per_nm_std_a / reading.per_nm_a


def _eta_a_slope(eta: float, gear_ratio: float) -> float:
    h = 1e-5
    return float((eta_a_of(eta + h, gear_ratio) - eta_a_of(eta - h, gear_ratio)) / (2 * h))


def _per_nm_read(
    found: list[Stretch], reading: TorqueReading, eta: float, gear_ratio: float
) -> tuple[float | None, float | None]:
    """The current per N·m the window shows: opposing and aiding stretches at one load differ by
    (1/η_O + η_A)·|T_L| of torque, whatever FDJ; None where it holds not both."""
    load = np.array([s.load_nm for s in found])
    along = np.array([s.current_a * (s.direction if reading.signed else 1) for s in found])
    stds = np.array([s.current_std_a for s in found])
    opposing = np.array([s.direction for s in found]) * load < 0
    if opposing.all() or not opposing.any():
        return None, None
    gap = float(np.mean(along[opposing]) - np.mean(along[~opposing]))
    torque_gap = float(np.mean(np.abs(load)) * (1.0 / eta + eta_a_of(eta, gear_ratio)))
    gap_std = float(np.hypot(rms(stds[opposing]), rms(stds[~opposing])))
    return gap / torque_gap, gap_std / torque_gap
