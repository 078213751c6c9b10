"""How late the hinge moment is logged: its filter's trace in the noise, the deflection and Eq. 5.1,
weighed together.

The hinge moment's lag barely shows in Eq. 5.1's equation error (lags of a few ms explain it about as well as none), yet
a strain-gauge filter's delay of 1–4 ms moves FDJ beyond its std. It shows in the noise: the filter that delays the
signal correlates the noise it passes, and ``ema.kinds.rotary.physics.noise_reading`` reads that correlation as a
filter's delay D (``filter_delay_samples``; 0 on white noise). But noise correlated after the signal (an amplifier's
own noise behind its output filter) reads the same, and advancing an unfiltered moment by it would move FDJ as much
the other way; and now and then the read misses a filter. So where the noise shows a filter, the lag is a model
average over three stories (``PRIOR``): the filter delays the moment too (D within ``HINGE_LAG_UNCERTAINTY``), it
filters only the noise (on time), or the moment is late by another amount up to ``MAX_HINGE_LAG_S``. Each lag of
the grid is weighed by
- the deflection: in the aircraft's band the moment follows it at once, so the lag read there
  (``aircraft_band.band_lag_s``, relative to the position's own filter) is the moment's; Student's t
  on its jackknife std, widened by ``BAND_LAG_UNCERTAINTY`` of the lag;
- Eq. 5.1's equation error at that lag (``ema.estimate.stats.rms_log_likelihood_ratio``; weak).
The moment is advanced by the posterior mean lag, and FDJ's and η_O's stds grow by their posterior
spread over the lags (the two stories' gap where neither decides; a slow window's band reads too
little to decide, and there the stds carry both).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ema.estimate.stats import white_noise_std
from ema.kinds.rotary.evidence import JACKKNIFE_BLOCKS, rms_log_likelihood_ratio
from ema.kinds.rotary.physics.friction import SolveSettings
from ema.kinds.rotary.physics.noise_reading import MAX_LAG, noise_of
from ema.kinds.rotary.physics.shifts import shifted_solutions
from ema.kinds.rotary.prepare.departures.aircraft_band import band_lag_s
from ema.kinds.rotary.simulator.hinge import denoised_hinge_nm
from ema.model.params import DriveConstants

MAX_HINGE_LAG_S = 3e-3
# How far the filter's delay as read from the noise may be off the true one, in shares of it: one std.
HINGE_LAG_UNCERTAINTY = 0.15
# How far the deflection's band may read a filtered moment's lag off the filter's delay: one std, in shares of it.
BAND_LAG_UNCERTAINTY = 0.25
PRIOR = {"filter": 0.45, "on_time": 0.45, "other": 0.1}  # where the noise shows a filter
OTHER_LAGS = 40  # grid points over (0, MAX_HINGE_LAG_S]
FILTER_LAGS = np.linspace(-2.0, 2.0, 9)  # D·(1 + HINGE_LAG_UNCERTAINTY·z)
# Eq. 5.1's evidence on the lag is read with a sensor's offset and C free: the window's departures are read
# after its lags, and a thick grease left in explains it best with a clean moment read a few ms late.
DEPARTURES_FREE = SolveSettings(offset=True, viscous=True)


@dataclass(frozen=True)
class HingeLag:
    """The hinge moment's lag [samples] as read (all 0: its noise shows no filter)."""

    filter_delay: float = 0.0  # D: the filter its noise went through delays by this
    late: float = 0.0  # the posterior's weight of "late at all" (1 − that of on time)
    advance: float = 0.0  # the posterior mean lag: the moment is advanced by this
    spread: dict[str, float] = field(default_factory=dict)  # per target, the posterior std over the lags


# A sensor whose white-noise std is under this share of its range logged no noise (a simulator's clean trace): the
# noise a real strain gauge leaves is orders of magnitude above it, even behind its amplifier's filter.
NOISELESS = 1e-4


def filter_delay_samples(noise: np.ndarray, sample_rate_hz: float, max_lag: int, rising_is_noise: bool) -> float:
    """The delay of the filter that leaves ``noise`` as correlated as it is: a filter that leaves the noise T
    times the low-frequency density of white noise delays what passes it (T − 1) / 2 samples, exactly for
    a moving average and a first-order lag (0: white)."""
    _, tau_s = noise_of(noise, sample_rate_hz, max_lag, rising_is_noise)
    if tau_s == 0.0:
        return 0.0
    rho = float(np.exp(-1.0 / (tau_s * sample_rate_hz)))
    return rho / (1.0 - rho)  # (T − 1) / 2, T = (1 + ρ) / (1 − ρ)


def lag_grid(delay: float, sample_rate_hz: float) -> tuple[np.ndarray, np.ndarray]:
    """(lags [samples], the prior's mass on each): on time, any lag up to ``MAX_HINGE_LAG_S``, and the
    filter's delay ``delay`` within its read's uncertainty (a normal's weights)."""
    other = np.linspace(0.0, max(MAX_HINGE_LAG_S * sample_rate_hz, delay), OTHER_LAGS + 1)[1:]
    normal = np.exp(-(FILTER_LAGS**2) / 2)
    lags = np.concatenate([[0.0], other, delay * (1.0 + HINGE_LAG_UNCERTAINTY * FILTER_LAGS)])
    prior = np.concatenate(
        [[PRIOR["on_time"]], np.full(OTHER_LAGS, PRIOR["other"] / OTHER_LAGS), PRIOR["filter"] * normal / normal.sum()]
    )
    return lags, prior


def band_log_likelihood(
    signals: dict[str, np.ndarray], sample_rate_hz: float, lags: np.ndarray, gear_ratio: float
) -> np.ndarray:
    """ln of the density of the lag the deflection reads (``band_lag_s``) were the moment ``lags`` late:
    Student's t (the std is a jackknife's), widened by half of what the position sensor's own filter may
    delay it by and by ``BAND_LAG_UNCERTAINTY`` of the lag; 0 where the band reads none."""
    read, std = band_lag_s(signals, sample_rate_hz, gear_ratio)
    if not np.isfinite(std):
        return np.zeros(len(lags))
    position = filter_delay_samples(signals["position_deg"], sample_rate_hz, MAX_LAG["position_deg"], False) / 2
    scale = np.sqrt((std * sample_rate_hz) ** 2 + position**2 + (BAND_LAG_UNCERTAINTY * lags) ** 2)
    dof = JACKKNIFE_BLOCKS - 1
    return -np.log(scale) - (dof + 1) / 2 * np.log1p(((read * sample_rate_hz + position - lags) / scale) ** 2 / dof)


def hinge_lag(
    signals: dict[str, np.ndarray], sample_rate_hz: float, drive: DriveConstants, in_flight: bool = True
) -> HingeLag:
    """The hinge moment's lag, where its noise shows a filter: the model average of the module docstring (on
    the ground the moment follows no deflection, and the band reads no lag)."""
    hinge = signals["hinge_moment_nm"]
    if white_noise_std(hinge) < NOISELESS * float(np.max(np.abs(hinge)) or 1.0):
        return HingeLag()  # a moment logged without noise shows no filter (what is left is the denoiser's own)
    noise = hinge - denoised_hinge_nm(hinge, signals["position_deg"], sample_rate_hz)
    delay = min(
        filter_delay_samples(noise, sample_rate_hz, MAX_LAG["hinge_moment_nm"], True), MAX_HINGE_LAG_S * sample_rate_hz
    )
    if delay == 0.0:
        return HingeLag()
    lags, prior = lag_grid(delay, sample_rate_hz)
    solutions = shifted_solutions(signals, sample_rate_hz, lags, drive, "hinge_moment_nm")
    rms = shifted_solutions(signals, sample_rate_hz, lags, drive, "hinge_moment_nm", DEPARTURES_FREE).residual_rms_nm
    if not np.all(np.isfinite(rms)):
        return HingeLag(delay)  # too little sliding motion: the physics solution says so next
    used, resolution = float(solutions.n_sliding[0]), float(solutions.resolution_nm[0])
    equation = [rms_log_likelihood_ratio(rms[0], r, used, sample_rate_hz, resolution_nm=resolution) for r in rms]
    band = band_log_likelihood(signals, sample_rate_hz, lags, drive.gear_ratio) if in_flight else 0.0
    log_posterior = np.log(prior) + band + np.array(equation)
    weight = np.exp(log_posterior - log_posterior.max())
    weight /= weight.sum()
    spread = {
        name: float(np.sqrt(weight @ (values - weight @ values) ** 2))
        for name, values in solutions.values(slice(None)).items()
    }
    return HingeLag(delay, float(1.0 - weight[0]), float(weight @ lags), spread)
