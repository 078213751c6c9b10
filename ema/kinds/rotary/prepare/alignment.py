"""The current, the speed and the hinge moment aligned in time: a sensor's filter delays what it logs.

Eq. 5.1 sets the motor torque k_T·I against the inertia's J·dω/dt at each instant; at the shaft's
accelerations both are far larger than the friction read from their difference, so a current
logged a fraction of a millisecond after the speed (an anti-aliasing filter, an averaging ADC, a
speed read through a filtered resolver) leaves a residual that no friction explains.

The lag is read as the shift of the current, to half a sample within ``MAX_LAG_S``, that minimizes
the equation error of the physics solution: batched solutions of the window with the current shifted each way
(the sliding samples, set by the speed, stay the same). The minimum is sharp, because the
accelerations are large. A lag is applied only where it lowers the equation error by ``MIN_GAIN``;
then the later of the two signals is advanced (a filter only delays), by linear interpolation, the
end held.

The hinge moment's lag barely shows in the equation error; it is read from its filter's trace in
its noise, the deflection and Eq. 5.1 together (``ema.kinds.rotary.prepare.hinge_lag``), and advanced by it.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from ema.kinds.rotary.physics.friction import SolveSettings
from ema.kinds.rotary.physics.shifts import advanced, shifted_solutions
from ema.kinds.rotary.prepare.hinge_lag import hinge_lag
from ema.model.params import DriveConstants
from ema.model.window import RotaryWindow

MAX_LAG_S = 1e-3
HALF_STEP = 0.5  # samples: the finest grid searched
MIN_GAIN = 0.05  # the least relative drop of the equation error a lag must bring
# Each shift is solved with a free scale of the motor torque and a free inertia: a current read a few per cent
# high (or a k_T off the document's) leaves γ·k_T·I, an inertia off the document's ΔJ·dω/dt, both largest where
# the shaft accelerates, and with the current decaying after a step a shifted current took either (a 6 % gain
# read as 0.5 ms, a rotor 20 % light as 0.9 ms). A lag leaves k_T·τ·dI/dt, which neither matches.
LAG_SOLVE = SolveSettings(torque_scale=True, inertia=True)


def _errors(signals: dict[str, np.ndarray], rate: float, lags: np.ndarray, drive: DriveConstants) -> np.ndarray:
    return shifted_solutions(signals, rate, lags, drive, settings=LAG_SOLVE).residual_rms_nm


def current_lag_samples(signals: dict[str, np.ndarray], sample_rate_hz: float, drive: DriveConstants) -> float:
    """How many samples the logged current trails the logged speed (negative: the speed trails), 0
    unless that lag lowers the window's equation error by ``MIN_GAIN`` inside ``MAX_LAG_S``: whole samples
    first, then half a sample either side of the best, then the parabola's vertex. A best shift at the end
    of the search is no minimum: the shift trades with the free drive constants there, and none is made."""
    reach = max(1.0, np.floor(MAX_LAG_S * sample_rate_hz))
    grid = np.arange(-reach, reach + 0.5)
    coarse = _errors(signals, sample_rate_hz, grid, drive)
    if not np.all(np.isfinite(coarse)):
        return 0.0  # too little sliding motion: the physics solution says so next
    near = grid[int(np.argmin(coarse))] + np.array([-HALF_STEP, HALF_STEP])
    errors = dict(zip(grid, coarse, strict=True)) | dict(
        zip(near, _errors(signals, sample_rate_hz, near, drive), strict=True)
    )
    best = min(errors, key=errors.__getitem__)
    if errors[best] >= (1.0 - MIN_GAIN) * errors[0.0] or abs(best) >= reach:
        return 0.0  # no drop worth a shift, or a minimum at the end of the search: none there, only a trade
    if best - HALF_STEP in errors and best + HALF_STEP in errors:  # a filter's delay falls between: the vertex
        below, at, above = (errors[best + d] ** 2 for d in (-HALF_STEP, 0.0, HALF_STEP))
        return float(best + 0.5 * HALF_STEP * (below - above) / (below - 2 * at + above))
    return float(best)


@dataclass(frozen=True)
class Lags:
    """How late each signal was logged [s], undone: the current behind the speed (negative: the speed
    behind the current), the hinge moment behind the load; and the std its read uncertainty adds, per target."""

    current_s: float = 0.0
    hinge_s: float = 0.0  # the hinge moment advanced by (``ema.kinds.rotary.prepare.hinge_lag``)
    spread: dict[str, float] = field(default_factory=dict)
    hinge_filter_s: float = 0.0  # the delay of the filter its noise went through
    hinge_weight: float = 0.0  # how likely the moment is late at all (not only its noise filtered)


def aligned(window: RotaryWindow, drive: DriveConstants) -> tuple[RotaryWindow, Lags]:
    """``window`` with the later of its current and speed advanced onto the other and its hinge moment
    advanced by its lag's posterior mean (``ema.kinds.rotary.prepare.hinge_lag``), and those lags."""
    rate, signals = window.sample_rate_hz, dict(window.signals)
    current = current_lag_samples(signals, rate, drive)
    if current != 0.0:
        late = "current_a" if current > 0 else "motor_speed_radps"
        signals[late] = advanced(signals[late], abs(current))
    hinge = hinge_lag(signals, rate, drive, in_flight=not window.on_ground)
    if hinge.advance != 0.0:
        signals["hinge_moment_nm"] = advanced(signals["hinge_moment_nm"], hinge.advance)
    if current == 0.0 and hinge.filter_delay == 0.0:
        return window, Lags()
    lags = Lags(current / rate, hinge.advance / rate, hinge.spread, hinge.filter_delay / rate, hinge.late)
    return replace(window, signals=signals), lags
