"""The logged hinge moment against the aircraft's: the part of it that follows the deflection, which
the flight condition alone gives (analytical redundancy for the strain gauge).

H_e = q̄·S_e·c_e·(C_h0 + C_hα·α_t + C_hδ·δ) (``docs/model.md``, the airframe). Between 10 and
400 Hz (``BAND_S``: each signal's local line over 2.5 ms minus that over 100 ms) the aircraft's own
part hardly moves (α_t's response to δ adds under 1 % there) and the sensors' noise is mostly
averaged away, so the logged moment and the logged deflection stand in the ratio
b = q̄·S_e·c_e·C_hδ in that band. Their least-squares slope over b, the *ratio*, reads the strain
gauge's gain where Eq. 5.1 cannot: there a gain is η_O's twin wherever the load is small
(``ema.kinds.rotary.prepare.departures.hinge_gain``), here it needs only a deflection that moves. What the
position sensor's noise keeps in the band is taken out of the deflection's spread (it would
attenuate the slope); the std is the larger of the white-noise one and a jackknife over
``JACKKNIFE_BLOCKS`` (which sees a filter's correlated noise).

In turn:
1. Where the moment read ``STEP_LAGS_S`` away matches the aircraft's (within the tolerance) and the
   band clearly better (``STEP_UNEXPLAINED``): it was exported out of step, refused naming it and
   the lag.
2. Outside ``GROSS`` by ``GROSS_STDS``: no strain gauge's calibration nor hinge coefficient is that
   far off: refused naming it (a unit, a sign, or the flight condition).
3. Departing from 1 by more than the airframe's tolerance + ``DEPART_STDS`` stds: the model's C_hδ
   is trusted within the tolerance (one further off shows the same ratio in every window of the
   aircraft, ``window.hinge_aircraft_ratio``: a model to calibrate), so the gauge is off by the
   ratio, where the window spans ``DECISIVE_SPANS`` of the band (shorter, it only widens the stds).
   It is divided out first (``divided_out``): a gain seen later passes in part for an offset. Where
   the window's loads then read no gain more precisely (a small load, where the gain is η_O's twin),
   the stds grow by half of what the ends of the ratio's band (the tolerance and its std) move FDJ
   and η_O (``banded``). Beyond the tolerance by ``SUSPECT_STDS`` only, or in a shorter window, the
   gauge is in doubt (``in_doubt``): the moment is read as logged and the stds grow by
   ``UNDECIDED_SHARE`` of what reading the window with the ratio divided out first would move
   (``ema.kinds.rotary.prepare.departures.read``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from typing import Literal

import numpy as np

from ema.estimate.documents import Note
from ema.kinds.rotary.evidence import JACKKNIFE_BLOCKS, jackknife_std
from ema.kinds.rotary.physics.features import solve_as_read
from ema.kinds.rotary.prepare.consistency import STEP_LAGS_S
from ema.kinds.rotary.prepare.departures.aircraft_band import BAND_S, band_noise_variance, band_part
from ema.kinds.rotary.prepare.departures.drive_constants import BESIDE
from ema.kinds.rotary.prepare.departures.hinge_gain import divided_hinge, free_load_solution
from ema.kinds.rotary.simulator.residual import kernel_samples
from ema.model.actuator import Airframe
from ema.model.aircraft import HingeGeometry
from ema.model.checks import InputError
from ema.model.params import DriveConstants
from ema.model.window import RotaryWindow

TOLERANCE = Airframe.model_fields["tolerance"].default  # how far the airframe's C_hδ may be off: the document's default
DEPART_STDS = 2.0  # stds beyond the tolerance by which a ratio departs: the gauge is off by it
SUSPECT_STDS = 1.0  # stds beyond the tolerance by which a ratio puts the gauge in doubt
SOLUTION_STDS = 2.0  # a ratio read at another lag matches within the tolerance and this many stds ...
STEP_UNEXPLAINED = 0.75  # ... and leaves under this share of what lag 0 leaves unexplained
GROSS = (0.5, 2.0)  # no gauge's calibration nor hinge coefficient is off beyond these
GROSS_STDS = 4.0
MAX_NOISE_SHARE = 0.5  # of the deflection's fast spread its sensor noise may make for the slope to be read
DECISIVE_SPANS = 2.0  # a shorter window's band is its deviation from one line: curvature, where α_t
# answers δ, reads as a gain there: it only widens the stds
READABLE_STD = 0.25  # a ratio read less precisely is not reported (a deflection that hardly moves fast)


@dataclass(frozen=True)
class AircraftCheck:
    """The logged moment's part that follows the deflection, over the aircraft's, and what was done."""

    ratio: float = math.nan  # logged over q̄·S_e·c_e·C_hδ (nan: no fast deflection to read it by)
    ratio_std: float = math.inf
    per_rad_nm: float = 0.0  # q̄·S_e·c_e·C_hδ at the window's flight condition
    decisive: bool = False  # the window spans ``DECISIVE_SPANS`` of the band's longer span
    factor: float = 1.0  # the moment divided by this before the window's own gain is read: the ratio, where it departs
    spread: dict[str, float] = field(default_factory=dict)  # per target, the std the two ends add
    skipped: Literal["on_ground", "no_airframe"] | None = None  # why no aircraft model applies
    tolerance: float = (
        TOLERANCE  # how far the airframe's C_hδ may be from the real one (``ema.model.actuator.Airframe``)
    )

    @property
    def readable(self) -> bool:
        return self.ratio_std <= READABLE_STD

    def beyond(self, stds: float) -> bool:
        """Whether the ratio lies beyond the tolerance by ``stds`` of its stds."""
        return bool(abs(self.ratio - 1.0) > self.tolerance + stds * self.ratio_std)

    @property
    def in_doubt(self) -> bool:
        """Beyond the tolerance by ``SUSPECT_STDS`` but not divided out (module docstring, 3)."""
        return self.factor == 1.0 and self.beyond(SUSPECT_STDS)

    def corrected(self, window: RotaryWindow) -> RotaryWindow:
        """``window`` with its hinge moment divided by ``factor``."""
        return divided_hinge(window, self.factor)


def slope(
    hinge_fast: np.ndarray, position_fast: np.ndarray, lag: int = 0, noise_var: float = 0.0, span: int = 1
) -> tuple[float, float, float]:
    """The least-squares slope [N·m/deg] of the moment's fast part on the deflection's, the moment read
    ``lag`` samples later, the deflection's sensor noise (``noise_var`` a sample) taken out of its
    spread (which it would otherwise attenuate the slope by); its std (the larger of white noise's, with
    one independent value in each ``span`` samples the band averages, and the jackknife's) and the
    correlation. NaN where the noise is over ``MAX_NOISE_SHARE`` of the spread."""
    if lag:
        hinge_fast, position_fast = (
            (hinge_fast[lag:], position_fast[:-lag]) if lag > 0 else (hinge_fast[:lag], position_fast[-lag:])
        )
    n = len(position_fast)
    blocks = np.minimum(np.arange(n) * JACKKNIFE_BLOCKS // n, JACKKNIFE_BLOCKS - 1)
    cross, raw = (
        np.bincount(blocks, weights=w, minlength=JACKKNIFE_BLOCKS)
        for w in (hinge_fast * position_fast, position_fast**2)
    )
    spreads = raw - np.bincount(blocks, minlength=JACKKNIFE_BLOCKS) * noise_var
    if not spreads.sum() > (1.0 - MAX_NOISE_SHARE) * raw.sum():
        return math.nan, math.inf, 0.0
    value = float(cross.sum() / spreads.sum())
    residual = hinge_fast - value * position_fast
    white = math.sqrt(float(residual @ residual) / n / spreads.sum() * span)
    with np.errstate(invalid="ignore", divide="ignore"):
        left_out = (cross.sum() - cross) / (spreads.sum() - spreads)
    jackknife = float(jackknife_std(left_out[None])[0])
    correlation = float(cross.sum() / math.sqrt(max(raw.sum() * float(hinge_fast @ hinge_fast), 1e-300)))
    return value, max(white, jackknife) if np.isfinite(jackknife) else math.inf, correlation


def check_against_aircraft(
    window: RotaryWindow, hinge: HingeGeometry | None, tolerance: float = TOLERANCE
) -> AircraftCheck:
    """The ratio of ``window``'s moment to the aircraft's, or an InputError naming the moment where it
    was exported out of step or lies outside ``GROSS`` (module docstring, 1 and 2); ``tolerance``: how far
    the airframe's C_hδ may be off. Skipped on the ground (the logged moment is the load) and without the
    airframe's ``hinge`` model, and said so."""
    condition = window.flight_condition
    if condition is None or hinge is None:
        return AircraftCheck(skipped="on_ground" if condition is None else "no_airframe")
    rate, signals = window.sample_rate_hz, window.signals
    per_deg = hinge.per_deflection_nm_per_rad(condition) * math.pi / 180.0
    bands = (band_part(signals["hinge_moment_nm"], rate), band_part(signals["position_deg"], rate))
    noise_var = band_noise_variance(signals["position_deg"], rate)
    span = kernel_samples(rate, BAND_S[0])
    value, std, correlation = slope(*bands, 0, noise_var, span)
    decisive = window.n_samples / rate >= DECISIVE_SPANS * BAND_S[1]
    read = AircraftCheck(value / per_deg, std / abs(per_deg), per_deg * 180.0 / math.pi, decisive, tolerance=tolerance)
    against = (
        f"its part that follows the deflection is {read.ratio:.3g} ± {read.ratio_std:.2g}x the aircraft's at "
        f"{condition.airspeed_mps:g} m/s, {condition.altitude_m:g} m (q̄·S_e·c_e·C_hδ = {per_deg:.3g} N·m/deg)"
    )
    shifted = lag_against_aircraft(bands, noise_var, per_deg, rate, correlation, span=span, tolerance=tolerance)
    if shifted is not None:
        lag_s, at_lag, unexplained = shifted
        raise InputError(
            "signals.hinge_moment_nm",
            f"is out of step with position_deg: {against}; read {1e3 * lag_s:+g} ms later it is {at_lag.ratio:.3g}x, "
            f"and what the deflection leaves unexplained falls to {100 * unexplained:.0f} % (a strain gauge's filter "
            "delays ~1 ms at most): exported on another clock?",
        )
    low, high = GROSS
    if read.ratio + GROSS_STDS * read.ratio_std < low or read.ratio - GROSS_STDS * read.ratio_std > high:
        raise InputError(
            "signals.hinge_moment_nm",
            f"{against}: no calibration or hinge coefficient is that far off; other units (kN·m is 0.001x, lbf·in "
            "8.85x), another sign, or another flight_condition?",
        )
    return read


def lag_against_aircraft(
    bands: tuple[np.ndarray, np.ndarray],
    noise_var: float,
    per_deg: float,
    rate: float,
    correlation: float,
    *,
    span: int,
    tolerance: float = TOLERANCE,
) -> tuple[float, AircraftCheck, float] | None:
    """The lag of ``STEP_LAGS_S`` [s] the moment read that much later matches the aircraft's at (within the
    tolerance and ``SOLUTION_STDS``) leaving the least of what lag 0 leaves unexplained (1 − correlation²),
    under ``STEP_UNEXPLAINED`` of it; its reading and that share. None where no lag does."""
    found = None
    for lag_s in STEP_LAGS_S:
        lag = round(lag_s * rate)
        if not 0 < abs(lag) < len(bands[0]) // 4:
            continue
        value, std, at_correlation = slope(*bands, lag, noise_var, span)
        at_lag = AircraftCheck(value / per_deg, std / abs(per_deg), tolerance=tolerance)
        unexplained = (1.0 - at_correlation**2) / max(1.0 - correlation**2, 1e-12)
        best = STEP_UNEXPLAINED if found is None else found[2]
        if at_lag.readable and not at_lag.beyond(SOLUTION_STDS) and unexplained < best:
            found = lag / rate, at_lag, unexplained
    return found


def divided_out(read: AircraftCheck) -> AircraftCheck:
    """``read`` with its ratio as the gain to divide the moment by where it departs (module docstring, 3)
    and the window is long enough to tell (``DECISIVE_SPANS``): first of all, as a gain seen later passes
    in part for an offset or a drive constant."""
    return replace(read, factor=read.ratio) if read.decisive and read.beyond(DEPART_STDS) else read


def banded(read: AircraftCheck, window: RotaryWindow, gain: float, drive: DriveConstants) -> AircraftCheck:
    """``read`` with the stds it adds to FDJ and η_O of ``window`` (its ratio divided out already, where
    it departs) where the window's own loads read no ``gain``
    (``ema.kinds.rotary.prepare.departures.hinge_gain``); as it is otherwise. Divided out: half of what the ends of
    the ratio's band move them (the tolerance and the ratio's std, narrowed by what the loads' free solution knows of
    the gain where it agrees within 2 stds). In doubt, the whole reading moves
    (``ema.kinds.rotary.prepare.departures.read``)."""
    if gain != 1.0 or read.factor == 1.0 or not read.beyond(SUSPECT_STDS):
        return read
    band = math.hypot(read.tolerance, read.ratio_std / read.ratio)
    solved = free_load_solution(window, drive, BESIDE)
    if solved is not None:
        own, own_std = float(solved[0][0]), float(jackknife_std(solved[0][None, 1:])[0])
        if np.isfinite(own) and own_std > 0.0 and abs(own - 1.0) <= 2.0 * own_std:
            band = 1.0 / math.hypot(1.0 / band, 1.0 / own_std)
    return replace(read, spread=_moved(window, drive, 1.0 - band, 1.0 + band, 0.5))


def _moved(window: RotaryWindow, drive: DriveConstants, first: float, second: float, share: float) -> dict[str, float]:
    """``share`` of how far FDJ and η_O of Eq. 5.1's solution move between the hinge moment divided by
    ``first`` and by ``second``."""
    ends = [solve_as_read(divided_hinge(window, g).signals, window.sample_rate_hz, drive) for g in (first, second)]
    return {
        "FDJ": share * abs(float(ends[1].fdj_nm[0] - ends[0].fdj_nm[0])),
        "eta_O": share * abs(float(ends[1].eta_o[0] - ends[0].eta_o[0])),
    }


def aircraft_note(read: AircraftCheck) -> list[Note]:
    """The disagreement, or why no aircraft model applied, for the result's notes."""
    if read.skipped == "on_ground":
        text = (
            "logged on the ground (no flight_condition): no aircraft model applies, the logged hinge moment is "
            "the load, and the strain gauge is not checked against an aircraft"
        )
        return [Note(code="on_ground", text=text)]
    if read.skipped == "no_airframe":
        text = (
            "the actuator's document holds no airframe: the hinge moment's gain is not checked against the "
            "aircraft model (its loads in Eq. 5.1 still read it)"
        )
        return [Note(code="aircraft_check_skipped", parameter="hinge_moment_nm", text=text)]
    if read.factor == 1.0 and not read.spread:
        return []
    against = (
        f"the hinge moment's part that follows the deflection is {read.ratio:.3f} ± {read.ratio_std:.3f}x the "
        f"aircraft model's at this flight condition (q̄·S_e·c_e·C_hδ = {read.per_rad_nm:.4g} N·m/rad), beyond the "
        f"model's {100 * read.tolerance:.0f} % tolerance"
    )
    if read.factor == 1.0:
        return [
            Note(
                code="hinge_vs_aircraft_undecided",
                parameter="hinge_moment_nm",
                text=f"{against}, by under {DEPART_STDS:g} stds or in a window under {DECISIVE_SPANS * BAND_S[1]:g} s: "
                f"the "
                "strain gauge's gain may be off (lbf·ft for N·m is 0.74x); read as logged, the stds include what that "
                "gain "
                "would move",
            )
        ]
    return [
        Note(
            code="hinge_vs_aircraft",
            parameter="hinge_moment_nm",
            text=f"{against}: taken as the strain gauge's gain (lbf·ft for N·m is 0.74x) and divided out before "
            f"anything else "
            "is read; where the window's loads read no gain more precisely, the stds include what the tolerance moves "
            "(if "
            "the airframe's hinge coefficients or the flight condition are that far off instead, every window shows "
            "it)",
        )
    ]
