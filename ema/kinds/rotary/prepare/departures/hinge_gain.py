"""The hinge moment's gain a window shows, read where it departs from 1: a strain-gauge bridge
calibrated off, or a log in lbf·ft taken for N·m.

Eq. 5.1 reads the load as t = FDJ + k_aid·a + k_opp·o, with k_aid = 1 − η_A and k_opp = 1/η_O − 1
over the aiding and opposing |T_ext| (``ema.kinds.rotary.physics.friction``), η_A tied to η_O by Eq. 3.4. A
hinge moment logged g times the true one puts (g − 1)·H/n into T_R and g into a and o, so the window
holds c_aid = 1 − η_A/g and c_opp = 1/(g·η_O) − 1 instead. Solved freely (both are linear), they
give η_A·η_O = (1 − c_aid)/(1 + c_opp), whence η_O by Eq. 3.4 (a quadratic), and
g = 1/((1 + c_opp)·η_O). Read with g = 1, a gain is η_O's twin in the constrained solution.

So g is read where the free solution explains the window ``DECISIVE_Z`` stds better (the likelihood ratio
of the two equation errors, as for the offset) and lies in ``GAIN_PLAUSIBLE``; the hinge moment is then
divided by it before every estimator, and FDJ's and η_O's stds grow by what g's jackknife std moves
them (``spread``).

A k_T or J_M off (``ema.kinds.rotary.prepare.departures.drive_constants``) and g each take a part of the
other, whichever is read first. So g is read before them only where it explains the window
decisively better than γ or ΔJ alone (``leading``, as ΔJ must beat γ), and after them otherwise.
Every solution of g sits beside a sensor offset and a change of C, and leads on the window the offset
stage zeroed: a hinge moment off zero bends |H − b| as a gain would, and C·|ω| grows with the load's
speeds.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from ema.estimate.documents import Note
from ema.estimate.least_squares import coefficients
from ema.estimate.stats import DECISIVE_Z, rms
from ema.kinds.rotary.evidence import JACKKNIFE_BLOCKS, jackknife_std, rms_log_likelihood_ratio
from ema.kinds.rotary.physics.features import as_read, solve_as_read
from ema.kinds.rotary.physics.friction import MIN_SLIDING_KERNELS, SolveSettings, nuisance_columns, regressors
from ema.kinds.rotary.prepare.departures.drive_constants import BESIDE, FIELDS
from ema.kinds.rotary.simulator.residual import DERIVATIVE_SPAN_S, kernel_samples
from ema.model.params import DriveConstants
from ema.model.window import RotaryWindow

GAIN_PLAUSIBLE = (0.7, 1.35)  # lbf·ft for N·m is 0.74; outside, no sensor's: not taken
GAIN_MIN_CHANGE = 0.01  # a gain nearer 1 than this changes nothing worth a note
GAIN_DECISIVE = 12.0  # ln LR by which g must beat γ and ΔJ to be read before them (as ΔJ must beat γ)


@dataclass(frozen=True)
class HingeGain:
    """The hinge moment's gain read on a window (1: as logged), and what its std adds."""

    gain: float = 1.0  # logged over true
    gain_std: float = 0.0
    spread: dict[str, float] = field(default_factory=dict)  # per target, the std g's uncertainty adds

    def corrected(self, window: RotaryWindow) -> RotaryWindow:
        """``window`` with its hinge moment divided by the gain."""
        return divided_hinge(window, self.gain)


def divided_hinge(window: RotaryWindow, gain: float) -> RotaryWindow:
    """``window`` with its hinge moment divided by ``gain`` (itself where the gain is 1)."""
    if gain == 1.0:
        return window
    return replace(window, signals=dict(window.signals, hinge_moment_nm=window.signals["hinge_moment_nm"] / gain))


def eta_o_from_product(product: np.ndarray, gear: float) -> np.ndarray:
    """η_O with η_A(η_O)·η_O = ``product`` (Eq. 3.4, τ = n): the positive root of
    2n²η² + (n − n² − p(n² − 1))·η − p(n + 1) = 0 (NaN where there is none)."""
    n, p = gear, np.asarray(product, dtype=np.float64)
    b = n - n**2 - p * (n**2 - 1)
    discriminant = b**2 + 8 * n**2 * p * (n + 1)
    with np.errstate(invalid="ignore"):
        return (-b + np.sqrt(discriminant)) / (4 * n**2)


def free_load_solution(
    window: RotaryWindow, drive: DriveConstants, beside: SolveSettings = SolveSettings()
) -> tuple[np.ndarray, float, int] | None:
    """The least squares of t on (1, a, o) and ``beside``'s nuisance columns over the sliding samples: g
    from the whole window and from each jackknife block left out ((B + 1,), the whole first), the RMS
    equation error and the samples used; None where too few samples slide for Eq. 5.1's own solution
    (``MIN_SLIDING_KERNELS``)."""
    rate = window.sample_rate_hz
    seen = as_read(window.signals, rate)
    t, a, o, sliding = (x[0] for x in regressors(seen, rate, drive, beside))
    used = int(sliding.sum())
    if used < MIN_SLIDING_KERNELS * kernel_samples(rate, DERIVATIVE_SPAN_S):
        return None
    blocks = np.minimum(np.arange(len(t)) * JACKKNIFE_BLOCKS // len(t), JACKKNIFE_BLOCKS - 1)
    nuisances = [column[0] for column in nuisance_columns(seen, rate, drive, beside)]
    columns = np.column_stack([np.ones_like(t), a, o, *nuisances])
    keep = [sliding] + [sliding & (blocks != b) for b in range(JACKKNIFE_BLOCKS)]
    betas = np.array([coefficients(columns[k], t[k]) for k in keep])
    eta_o = eta_o_from_product((1 - betas[:, 1]) / (1 + betas[:, 2]), drive.gear_ratio)
    misfit = rms(t[sliding] - columns[sliding] @ betas[0])
    return 1.0 / ((1 + betas[:, 2]) * eta_o), misfit, used


def _margin(
    window: RotaryWindow, drive: DriveConstants, free_rms: float, used: int, rivals: list[SolveSettings]
) -> float:
    """ln LR by which the free load solution explains ``window`` better than the best of Eq. 5.1's solutions with
    g = 1 and ``rivals``' terms (−inf where one cannot be compared)."""
    rate = window.sample_rate_hz
    solutions = [solve_as_read(window.signals, rate, drive, rival) for rival in rivals]
    best = min(float(solution.residual_rms_nm[0]) for solution in solutions)
    if not (np.isfinite(best) and free_rms > 0):
        return -np.inf
    return rms_log_likelihood_ratio(best, free_rms, used, rate, resolution_nm=float(solutions[0].resolution_nm[0]))


def read_hinge_gain(window: RotaryWindow, drive: DriveConstants, leading: bool = False) -> HingeGain:
    """g where it stands out and is plausible (module docstring), with FDJ's and η_O's change across g ± its
    std; ``leading``: only where it also explains the window ``GAIN_DECISIVE`` (ln LR) better than γ or ΔJ alone,
    each beside an offset and ΔC, to be read before them (which would each take a part of it)."""
    solved = free_load_solution(window, drive, BESIDE)
    if solved is None:
        return HingeGain()
    gain, free_rms, used = solved
    plausible = np.all(np.isfinite(gain)) and GAIN_PLAUSIBLE[0] <= gain[0] <= GAIN_PLAUSIBLE[1]
    if not (plausible and abs(gain[0] - 1.0) >= GAIN_MIN_CHANGE):
        return HingeGain()
    if not 2.0 * _margin(window, drive, free_rms, used, [BESIDE]) > DECISIVE_Z**2:
        return HingeGain()
    rivals = [replace(BESIDE, **{name: True}) for name in FIELDS]  # γ alone, ΔJ alone
    if leading and not _margin(window, drive, free_rms, used, rivals) > GAIN_DECISIVE:
        return HingeGain()
    std = float(jackknife_std(gain[None, 1:])[0])
    rate = window.sample_rate_hz
    low, high = (
        solve_as_read(HingeGain(float(gain[0]) + d).corrected(window).signals, rate, drive) for d in (-std, std)
    )
    spread = {
        "FDJ": abs(float(high.fdj_nm[0] - low.fdj_nm[0])) / 2,
        "eta_O": abs(float(high.eta_o[0] - low.eta_o[0])) / 2,
    }
    return HingeGain(float(gain[0]), std, spread)


def hinge_gain_note(read: HingeGain) -> list[Note]:
    """The gain, for the result's notes."""
    if read.gain == 1.0:
        return []
    return [
        Note(
            code="hinge_gain",
            parameter="hinge_moment_nm",
            text=f"the hinge moment is logged {read.gain:.3f} ± {read.gain_std:.3f} times the load it shows (a strain "
            f"gauge "
            "calibrated off, or other units): divided by that before every estimator, read from the opposing and "
            "aiding loads' terms of Eq. 5.1 together with Eq. 3.4; the stds include its uncertainty",
        )
    ]
