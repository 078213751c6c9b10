"""A physics baseline with no simulation and no network: Eq. 5.1 fitted by least squares.

While sliding, the residual torque is T_R = sgn(ω)·(FDJ + k·|T_ext|) + C·ω with k = 1 − η_A when
the load aids the motion and 1/η_O − 1 when it opposes it (T_ext = H_e / n). Both sides go
through the same smoothing kernel as the reconstruction (``sim.residual``), which keeps the
model linear in FDJ and k. η_A is tied to η_O by Eq. 3.4, as everywhere in the product, so the
fit is a one-dimensional search over η_O with FDJ solved in closed form at each point.

FSJ is read at break-away: while the shaft is stuck, dω/dt = 0 and T_R = k_T·I + H_e/n is
exactly the friction, which the drive raises until it reaches FSJ + k·|T_ext| and slips.
"""

from __future__ import annotations

import numpy as np

from sim.checks import InputError
from sim.params import ActuatorParams, eta_a_from_eta_o
from sim.residual import DEFAULT_DERIVATIVE_WINDOW_S, residual_torque_nm, smoothed
from sim.window import Window

ETA_O_RANGE = (0.30, 0.999)  # the search interval of η_O
GRID_POINTS = 41  # per refinement: 3 passes resolve η_O to ~1e-5
END_STOP_MARGIN_DEG = 1.0


def _sliding_min(values: np.ndarray, width: int) -> np.ndarray:
    """Minimum over a centred window of ``width`` samples (edges use the part that exists)."""
    half = width // 2
    padded = np.pad(values, half, mode="edge")
    return np.lib.stride_tricks.sliding_window_view(padded, 2 * half + 1).min(axis=1)


class FrictionLeastSquares:
    """scikit-learn shape: settings checked here, ``fit(window)`` returns self, results end in ``_``."""

    def __init__(
        self,
        actuator: ActuatorParams = ActuatorParams(),
        min_speed_radps: float = 30.0,
        derivative_window_s: float = DEFAULT_DERIVATIVE_WINDOW_S,
        stuck_speed_radps: float = 0.5,
        min_stick_events: int = 1,
    ) -> None:
        if min_speed_radps <= 0:
            raise InputError("min_speed_radps", f"must be positive, got {min_speed_radps}")
        if not 0 < stuck_speed_radps < min_speed_radps:
            raise InputError("stuck_speed_radps", f"must be in (0, {min_speed_radps}), got {stuck_speed_radps}")
        if min_stick_events < 1:
            raise InputError("min_stick_events", f"must be at least 1, got {min_stick_events}")
        self.actuator = actuator
        self.min_speed_radps = min_speed_radps
        self.derivative_window_s = derivative_window_s
        self.stuck_speed_radps = stuck_speed_radps
        self.min_stick_events = min_stick_events

    def fit(self, window: Window) -> FrictionLeastSquares:
        rate, a = window.sample_rate_hz, self.actuator
        s = window.signals
        residual = residual_torque_nm(s["current_a"], s["motor_speed_radps"], s["hinge_moment_nm"], rate, a)
        speed = s["motor_speed_radps"]
        load = smoothed(s["hinge_moment_nm"] / a.gear_ratio, rate, self.derivative_window_s)
        width = 2 * round(self.derivative_window_s * rate / 2) + 1
        sliding = _sliding_min(np.abs(speed), width) > self.min_speed_radps  # one sign over the whole kernel
        sliding &= np.abs(s["position_deg"]) < a.end_stop_deg - END_STOP_MARGIN_DEG
        if sliding.sum() < 10 * width:
            raise InputError("signals", f"too little sliding motion to fit ({int(sliding.sum())} samples)")
        direction = np.sign(speed)
        aiding = load * direction > 0
        aid_part = smoothed(np.abs(load) * aiding, rate, self.derivative_window_s)[sliding]
        opp_part = smoothed(np.abs(load) * ~aiding, rate, self.derivative_window_s)[sliding]
        viscous = a.viscous_nms * smoothed(speed, rate, self.derivative_window_s)
        target = (direction * (residual - viscous))[sliding]  # = FDJ + k_aid·aid + k_opp·opp

        low, high = ETA_O_RANGE
        for _ in range(3):  # coarse-to-fine grid: the SSE is smooth and unimodal in η_O here
            grid = np.linspace(low, high, GRID_POINTS)
            fdj, sse = self._profile(grid, target, aid_part, opp_part)
            best = int(np.argmin(sse))
            step = grid[1] - grid[0]
            low, high = max(grid[best] - step, ETA_O_RANGE[0]), min(grid[best] + step, ETA_O_RANGE[1])
        self.fdj_ = float(fdj[best])
        self.eta_o_ = float(grid[best])
        self.eta_a_ = float(eta_a_from_eta_o(self.eta_o_, a.gear_ratio))
        self.n_sliding_samples_ = int(sliding.sum())
        self.residual_rms_ = float(np.sqrt(sse[best] / len(target)))
        self._fit_static(window, load, direction)
        return self

    def _profile(
        self, eta_o: np.ndarray, target: np.ndarray, aid: np.ndarray, opp: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
        """For each η_O: the best FDJ (closed form) and the sum of squared residuals."""
        k_opp = 1.0 / eta_o - 1.0
        k_aid = 1.0 - eta_a_from_eta_o(eta_o, self.actuator.gear_ratio)
        explained = k_aid[:, None] * aid + k_opp[:, None] * opp  # (grid, samples)
        fdj = (target - explained).mean(axis=1)
        return fdj, ((target - explained - fdj[:, None]) ** 2).sum(axis=1)

    def _fit_static(self, window: Window, load: np.ndarray, direction: np.ndarray) -> None:
        """FSJ from the end of each rest: ≥ 1 ms at rest, then motion for ≥ 1 ms.

        Rest is judged on the smoothed speed (the sensor noise alone exceeds a creep of 1 rad/s),
        which lags the break-away by up to a millisecond. At rest the friction equals the drive
        k_T·I + H_e/n, which peaks at the static level FSJ + k·|T_ext| when the shaft breaks away:
        the peak of the drive (over 3 samples, against noise) in the last 1 ms is that level.
        """
        a, s = self.actuator, window.signals
        rate = window.sample_rate_hz
        speed = np.abs(smoothed(s["motor_speed_radps"], rate, self.derivative_window_s))
        run = max(2, round(1e-3 * rate))
        rest = speed < self.stuck_speed_radps
        drive = a.torque_constant_nm_per_a * s["current_a"] + s["hinge_moment_nm"] / a.gear_ratio
        drive = np.abs(np.convolve(drive, np.ones(3) / 3, mode="same"))
        events = []
        for end in np.flatnonzero(rest[:-1] & ~rest[1:]):
            if end + 1 < run or not rest[end + 1 - run : end + 1].all() or rest[end + 1 : end + 1 + run].any():
                continue  # too short a rest or too short a motion: hunting in passing, not a stick
            if end + 1 + run > len(rest):
                continue
            moving = direction[end + run // 2]
            k = 1.0 - self.eta_a_ if load[end] * moving > 0 else 1.0 / self.eta_o_ - 1.0
            peak = end + 1 - run + int(np.argmax(drive[end + 1 - run : end + 2]))
            events.append(drive[peak] - k * abs(load[peak]))
        self.n_stick_events_ = len(events)
        if len(events) >= self.min_stick_events:
            self.fsj_: float | None = float(np.median(events))
            self.fsj_reason_ = f"median of {len(events)} break-away(s)"
        else:
            self.fsj_ = None
            self.fsj_reason_ = (
                f"{len(events)} break-away(s) in the window, {self.min_stick_events} needed: the shaft never "
                "rests for 1 ms then moves (in flight the position loop keeps it hunting in the backlash)"
            )
