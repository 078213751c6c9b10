"""Stage 1, residuals: each window's equation error on its own measured states.

Comparing a measured window with a re-simulated one mixes trajectory mismatch into the
residual as soon as an effect is large (the simulation no longer follows the same path). Here,
as in the Eq. 5.1 solution, the measured residual torque is regressed on functions of the *measured*
states, sample by sample, over the sliding samples:

    t = sgn(ω)·(T_R − C_M·ω) = FDJ + k_aid·a + k_opp·o + Σ effect columns + noise,

with a and o the smoothed aiding and opposing |T_ext|, the hinge moment read as the estimators
read it (``ema.kinds.rotary.physics.features.as_read``), k_aid and k_opp tied by Eq. 3.4
(``Equations.tied``). A second channel carries the backlash: the motor angle (integrated measured
speed) minus the elevator angle, d = θ_m/n − θ_u, sits at c ± BLK/2 depending on which side of the
dead band the motor pushes. Simulated windows go through this very function, so the noise floor
(``ema.kinds.rotary.noise_floor``) sees what the measured window sees.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from functools import cached_property

import numpy as np

from ema.calibration.limits import FOLDS
from ema.estimate.least_squares import coefficients
from ema.estimate.profile import ETA_O_SEARCH
from ema.kinds.rotary.physics.features import as_read
from ema.kinds.rotary.physics.friction import SolveSettings, regressors
from ema.kinds.rotary.simulator.residual import smooth_derivative, smoothed
from ema.model.params import DriveConstants, load_factors

FOLD_BLOCK_S = 0.02  # held-out folds are interleaved 20 ms blocks: each fold sees every regime of the window
VARIABLES = ("speed_radps", "position_rad", "time_s", "load_nm", "current_a", "direction")


@dataclass(frozen=True)
class Equations:
    """The sliding samples of one or more windows, stacked: target, base columns, variables."""

    y: np.ndarray  # (m,) t = sgn(ω)(T_R − C_M ω) [N·m]
    base: np.ndarray  # (m, 3): 1, a, o
    # VARIABLES, "current_unsigned_a", "acceleration_radps2" (signed by the direction), "motor_angle_rad" and
    # "engaged" (``engaged``), each (m,), from the measured states
    variables: dict[str, np.ndarray]
    cogging: dict[float, np.ndarray]  # order p -> (m, 2): sgn·(sin, cos)(p·θ_m), as logged and smoothed
    kinematic: np.ndarray  # (m,) d = θ_m/n − θ_u [rad]
    folds: np.ndarray  # (m,) held-out fold of each sample
    window: np.ndarray  # (m,) which window each sample comes from
    gear_ratio: float  # the actuator's n: Eq. 3.4 ties η_A to η_O with it

    @property
    def m(self) -> int:
        return len(self.y)

    @cached_property
    def tied(self) -> tuple[np.ndarray, np.ndarray]:
        """(design (m, 2), fixed (m,)): the base with η_A tied to η_O by Eq. 3.4, as the estimators tie it:
        t ≈ FDJ + k_opp·(o + r·a) + q·a, the aiding factor k_aid = q + r·k_opp linearized where this window's
        free solution sits (over η_O 0.5–0.95 and n ≥ 150, r stays within 2 % of 1). The tie is what a gain of the
        current's reading breaks: it scales the aiding and the opposing load's share alike, where Eq. 3.4 makes
        them differ by the transmission's loss; free columns a and o would absorb it into FDJ and η_O."""
        free = coefficients(self.base, self.y)
        eta_o = float(np.clip(1.0 / (1.0 + max(0.5 * (free[1] + free[2]), 0.0)), *ETA_O_SEARCH))
        step = 1e-4
        (aid_low, opp_low), (aid_high, opp_high) = (
            load_factors(x, self.gear_ratio) for x in (eta_o - step, eta_o + step)
        )
        slope = (aid_high - aid_low) / (opp_high - opp_low)
        k_aid, k_opp = load_factors(eta_o, self.gear_ratio)
        aiding, opposing = self.base[:, 1], self.base[:, 2]
        design = np.column_stack([self.base[:, 0], opposing + slope * aiding])
        return design, (k_aid - slope * k_opp) * aiding


def motor_angle_rad(speed_radps: np.ndarray, position_deg: np.ndarray, rate_hz: float, gear: float) -> np.ndarray:
    """θ_m at each interval centre: n·θ_u(0) plus the integral of the interval-mean speed."""
    step = 1.0 / rate_hz
    return gear * np.radians(position_deg[0]) + step * (np.cumsum(speed_radps) - 0.5 * speed_radps)


def cogging_columns(
    angle_rad: np.ndarray, speed_radps: np.ndarray, rate: float, orders: Sequence[float]
) -> dict[float, np.ndarray]:
    """Per order p: (sin, cos)(p·θ_m) as the log records them, then smoothed as T_R is.

    A ripple of p periods per revolution is averaged over each log interval, where θ_m advances
    by ω·Δt: its interval mean is the centre value times sinc(p·ω·Δt/2). The 2 ms reconstruction
    kernel then attenuates it again; applying both here keeps the solved amplitude the true one.
    """
    out = {}
    for p in orders:
        half = 0.5 * p * speed_radps / rate
        attenuation = np.sinc(half / np.pi)  # np.sinc(x) = sin(πx)/(πx)
        phase = p * angle_rad
        out[p] = np.stack(
            [smoothed(np.sin(phase) * attenuation, rate), smoothed(np.cos(phase) * attenuation, rate)], axis=1
        )
    return out


STOP_MARGIN_DEG = 1.0  # within this of an end stop the stop, not the dead band, sets where the elevator is


def engaged(position_deg: np.ndarray, speed_radps: np.ndarray, rate: float, drive: DriveConstants) -> np.ndarray:
    """1 where the motor drives the elevator (it moves with the motor, at least half its speed on the
    motor side), 0 where the motor crosses the dead band after a reversal and the elevator waits, and 0 by an
    end stop, where the stop holds the elevator and the motor's angle says nothing of the band."""
    elevator = drive.gear_ratio * smooth_derivative(np.radians(position_deg), rate)
    free = np.abs(position_deg) < drive.end_stop_deg - STOP_MARGIN_DEG
    return ((elevator * np.sign(speed_radps) > 0.5 * np.abs(speed_radps)) & free).astype(float)


def _one_window(
    signals: Mapping[str, np.ndarray], rate: float, drive: DriveConstants, orders: Sequence[float], index: int
) -> Equations:
    signals = as_read(signals, rate)  # the hinge moment as the estimators read it
    t, a, o, mask = (x[0] for x in regressors(signals, rate, drive, SolveSettings()))
    speed = smoothed(signals["motor_speed_radps"], rate)
    sign = np.sign(speed)
    angle = motor_angle_rad(signals["motor_speed_radps"], signals["position_deg"], rate, drive.gear_ratio)
    block = max(1, round(FOLD_BLOCK_S * rate))
    variables = {
        "speed_radps": np.abs(speed),
        "position_rad": np.radians(smoothed(signals["position_deg"], rate)),
        "time_s": np.arange(len(speed)) / rate,
        "load_nm": smoothed(signals["hinge_moment_nm"], rate) / drive.gear_ratio * sign,  # > 0: aiding
        "current_a": sign * smoothed(signals["current_a"], rate),
        "current_unsigned_a": smoothed(signals["current_a"], rate),
        "acceleration_radps2": sign * smooth_derivative(signals["motor_speed_radps"], rate),  # as T_R reads it
        "direction": sign,
        "motor_angle_rad": angle,
        "engaged": engaged(signals["position_deg"], speed, rate, drive),
    }
    return Equations(
        y=t[mask],
        base=np.stack([np.ones(mask.sum()), a[mask], o[mask]], axis=1),
        variables={k: v[mask] for k, v in variables.items()},
        cogging={p: c[mask] * sign[mask, None] for p, c in cogging_columns(angle, speed, rate, orders).items()},
        kinematic=smoothed(angle / drive.gear_ratio - np.radians(signals["position_deg"]), rate)[mask],
        folds=(np.arange(len(t)) // block % FOLDS)[mask],
        window=np.full(int(mask.sum()), index),
        gear_ratio=drive.gear_ratio,
    )


def equations(
    windows: Sequence[Mapping[str, np.ndarray]],
    rate: float,
    orders: Sequence[float],
    drive: DriveConstants,
) -> Equations:
    """The stacked equation-error problem of ``windows`` (each a dict of signals at ``rate``)."""
    parts = [_one_window(signals, rate, drive, orders, i) for i, signals in enumerate(windows)]
    first = parts[0]
    # Grouped by fold (stable: in time within a fold), so that each fold is a slice of every column.
    order = np.argsort(np.concatenate([p.folds for p in parts]), kind="stable")

    def stack(arrays: list[np.ndarray]) -> np.ndarray:
        return np.ascontiguousarray(np.concatenate(arrays)[order])

    return Equations(
        y=stack([p.y for p in parts]),
        base=stack([p.base for p in parts]),
        variables={k: stack([p.variables[k] for p in parts]) for k in first.variables},
        cogging={q: stack([p.cogging[q] for p in parts]) for q in first.cogging},
        kinematic=stack([p.kinematic for p in parts]),
        folds=stack([p.folds for p in parts]),
        window=stack([p.window for p in parts]),
        gear_ratio=first.gear_ratio,
    )
