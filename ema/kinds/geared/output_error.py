"""A geared servo's health read by output error: the window's own set point simulated in closed loop
(``ema.kinds.geared.loop``) at the document's constants, FDJ, η_O and η_A solved so that the simulated position
follows the logged one (robust least squares, as Rhoban's BAM fits its models).

**One run says little of its health where its loop is stiff** (at a high gain the friction moves the position
by a few encoder steps), and what the model misses there would read as friction: a run is read as an update of its
document's nominal. The nominal joins the solve as one more observation, its spread half the way to the failure
levels (``prior_spread``), against the residual's noise per independent sample (a first solve of the run alone
reads it); the stds are the posterior's, (JᵀJ/σ² + Σ_prior⁻¹)⁻¹. A run that holds its health reads it; one that
does not stays near the nominal, and its std says so.

Why not Eq. 5.1 on the logged duty, as the other kinds read their drive's force: the duty this servo reports is a
register read once per 10 ms, a sample behind the position it answers and smoothed by the firmware. Solved on it,
Eq. 5.1 reads a negative viscous friction (the back-EMF it lags) and trades η_O against the motor's constant. The
position the loop produced has no such lag: its error is what the health moved.

σ², the residual's variance per independent sample, is widened by its correlation over time (the residual of a
closed-loop run is a slow curve, not white noise: ``1 + 2·Σρ_k``, Bartlett-weighted to the lag where ρ first falls
below 0). The report adds the document's repeatability, what the healthy runs of this servo scatter by beyond it.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from functools import partial

import numpy as np
from scipy.optimize import least_squares

from ema.kinds.geared.log_reading import HEALTH, GearedPrepared
from ema.kinds.geared.loop import Run, simulate_lanes

LOSS_SCALE_RAD = 0.02  # soft-L1: a position error past this counts linearly (a slip, a knock), not squared
BOUNDS = {"fdj_nm": (1e-6, 100.0), "k_opp": (1e-3, 9.0), "k_aid": (1e-3, 2.0)}  # η_O 0.1-0.999, η_A −1-0.999
DIFF_STEP = 1e-3  # relative finite-difference step: the stick-slip map is flat below it
MAX_EVALUATIONS = 200


@dataclass(frozen=True)
class HealthReading:
    values: dict[str, float]  # HEALTH: FDJ [N·m], η_O, η_A
    stds: dict[str, float]
    error_rad: np.ndarray  # (N,) logged less simulated position at the answer

    @property
    def mean_abs_error_rad(self) -> float:
        return float(np.mean(np.abs(self.error_rad)))


def health_of(x: np.ndarray) -> dict[str, float]:
    """(FDJ, k_opp, k_aid) as the health: FDJ, η_O = 1/(1 + k_opp), η_A = 1 − k_aid."""
    return {"fdj_nm": float(x[0]), "eta_o": 1.0 / (1.0 + float(x[1])), "eta_a": 1.0 - float(x[2])}


def solved_of(health: dict[str, float]) -> np.ndarray:
    """The health as the solver's unknowns (FDJ, k_opp, k_aid), inside their bounds."""
    x = np.array([health["fdj_nm"], 1.0 / health["eta_o"] - 1.0, 1.0 - health["eta_a"]])
    low, high = np.array(list(BOUNDS.values())).T
    return np.clip(x, low, high)


def correlation_inflation(residual: np.ndarray) -> float:
    """1 + 2·Σ (1 − k/K)·ρ_k over the lags k < K where the residual's autocorrelation ρ first falls below 0: how
    many times fewer independent samples a correlated residual holds."""
    centred = residual - residual.mean()
    variance = float(centred @ centred)
    if variance <= 0:
        return 1.0
    n = len(centred)
    spectrum = np.fft.rfft(centred, 2 * n)
    rho = np.fft.irfft(spectrum * np.conj(spectrum))[: n // 2] / variance
    below = np.flatnonzero(rho[1:] <= 0)
    lags = int(below[0]) + 1 if len(below) else len(rho)
    weights = 1.0 - np.arange(1, lags) / lags
    return max(1.0, 1.0 + 2.0 * float(weights @ rho[1:lags]))


def _residual(prepared: GearedPrepared, run: Run, logged: np.ndarray) -> Callable[[np.ndarray], np.ndarray]:
    def residual(x: np.ndarray) -> np.ndarray:
        lane = prepared.lane(health_of(x))
        return logged - simulate_lanes(run, lane[None, :]).position_rad[0]

    return residual


def read_health(
    prepared: GearedPrepared, logged: np.ndarray | None = None, start: dict[str, float] | None = None
) -> HealthReading:
    """The health that simulates ``logged`` (the window's position; a held-out simulation's) best given the document's
    nominal, with its posterior stds (module docstring), solved from ``start`` (the nominal where none)."""
    logged = prepared.position_rad if logged is None else logged
    residual = _residual(prepared, prepared.run, logged)
    low, high = np.array(list(BOUNDS.values())).T
    x0 = solved_of(prepared.nominal if start is None else start)
    solve = partial(least_squares, bounds=(low, high), diff_step=DIFF_STEP, x_scale="jac", max_nfev=MAX_EVALUATIONS)
    first = solve(residual, x0, loss="soft_l1", f_scale=LOSS_SCALE_RAD)  # the run alone: how far its residual goes
    error = residual(first.x)
    noise = np.sqrt(float(error @ error) / len(error) * correlation_inflation(error))  # one independent sample's
    centre, spread = solved_of(prepared.nominal), prior_spread(prepared)

    def posterior(x: np.ndarray) -> np.ndarray:
        return np.concatenate([residual(x), noise * (x - centre) / spread])

    solution = solve(posterior, first.x)
    jacobian = solution.jac[: len(logged)]
    covariance = np.linalg.pinv(jacobian.T @ jacobian / noise**2 + np.diag(1.0 / spread**2))
    return HealthReading(health_of(solution.x), _stds(covariance, solution.x), residual(solution.x))


def prior_spread(prepared: GearedPrepared) -> np.ndarray:
    """How far the health may lie from the document's nominal before a run says so (FDJ, k_opp, k_aid): half the way
    to the document's failure levels (FDJ's upper one, η_O's lower one; η_A as η_O), so a run may read a servo at
    the end of its life within 2 std of its prior."""
    nominal, levels = prepared.nominal, prepared.failure_levels
    eta_o = nominal["eta_o"]
    eta_std = max((eta_o - levels["eta_o"]) / 2.0, 1e-3)
    k_opp_std = eta_std / (eta_o * eta_o)
    return np.array([max((levels["fdj_nm"] - nominal["fdj_nm"]) / 2.0, 1e-6), k_opp_std, eta_std])


def _stds(covariance: np.ndarray, x: np.ndarray) -> dict[str, float]:
    """The health's stds from the covariance of (FDJ, k_opp, k_aid), carried to η."""
    std = np.sqrt(np.clip(np.diag(covariance), 0.0, None))
    eta_o = 1.0 / (1.0 + x[1])
    return {"fdj_nm": float(std[0]), "eta_o": float(eta_o * eta_o * std[1]), "eta_a": float(std[2])}


__all__ = ["HEALTH", "HealthReading", "read_health"]
