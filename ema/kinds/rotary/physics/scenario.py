"""The model of one window: its scenario (command, logged load, first state, rate) simulated at a health,
and how closely that simulation follows the drive's own speed and current.

Every stage that asks "what would the model do with this window?" asks it here: the departures read in
preparation (a story checked by simulating it), the dataset, and the answer's check against the window.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ema.estimate.stats import rms
from ema.kinds.rotary.box import physical
from ema.kinds.rotary.simulator.batch import BatchResult, InitialState, simulate_batch
from ema.kinds.rotary.simulator.commands import knots_from_samples
from ema.kinds.rotary.simulator.effects import EffectSet
from ema.kinds.rotary.simulator.loads import Load, LoggedLoad
from ema.kinds.rotary.simulator.residual import smoothed
from ema.model.aircraft import FlightCondition, HingeGeometry
from ema.model.bounds import DEFAULT_SAMPLE_RATE_HZ
from ema.model.noise import SensorNoise
from ema.model.params import DriveConstants, HealthParams
from ema.model.window import RotaryWindow

INITIAL_SOLVE_SAMPLES = 8
SETTLE_S = 0.02  # the simulation settles from an estimated first state: compared after this
CLEAR_MARGIN = 0.05  # of two models, the loser's ``following_error`` this far above the winner's: a clear call


@dataclass(frozen=True)
class Scenario:
    """What every simulation of a dataset shares: the actuator, the command, the load, the start, the rate."""

    drive: DriveConstants  # the constants the simulations run with
    command_knots_deg: np.ndarray  # (n_samples + 1,) one command (Case 1) or (n_sims, n_samples + 1) (Case 2)
    load: Load = field(default_factory=FlightCondition)
    initial: InitialState = field(default_factory=InitialState)
    sample_rate_hz: float = DEFAULT_SAMPLE_RATE_HZ
    effects: EffectSet = field(default_factory=EffectSet)

    @property
    def n_samples(self) -> int:
        return self.command_knots_deg.shape[-1] - 1

    def simulate(self, health: HealthParams, lanes: int | None = None, reuse_output: bool = False) -> BatchResult:
        return simulate_batch(
            self.command_knots_deg,
            health,
            self.load,
            self.initial,
            self.sample_rate_hz,
            self.effects,
            drive=self.drive,
            lanes=lanes,
            reuse_output=reuse_output,
        )


def initial_state(window: RotaryWindow, drive: DriveConstants) -> InitialState:
    """The state at t = 0: a parabola through the first samples (at their interval centres), taken at 0.

    Not the first sample: the solution averages the sensor noise down, and a parabola follows the motor,
    which reaches 60 rad/s within a millisecond from rest, where a line or a mean would lag it.
    """
    n = min(INITIAL_SOLVE_SAMPLES, window.n_samples)
    centres = np.arange(n) + 0.5

    def at_zero(values: np.ndarray) -> float:
        return float(np.polyfit(centres, values[:n], 2)[-1])

    speed, current = drive.max_motor_speed_radps, drive.max_current_a
    return InitialState(
        position_deg=float(np.clip(at_zero(window.signals["position_deg"]), -drive.end_stop_deg, drive.end_stop_deg)),
        motor_speed_radps=float(np.clip(at_zero(window.signals["motor_speed_radps"]), -speed, speed)),
        current_a=float(np.clip(at_zero(window.signals["current_a"]), -current, current)),
    )


def logged_load(window: RotaryWindow, hinge: HingeGeometry | None, sensor_bias_nm: float = 0.0) -> LoggedLoad:
    """The window's own hinge moment (smoothed of sensor noise) as the load its simulations feel, less the
    sensor's bias where one is supposed (the drive feels the moment, the sensor adds its bias to it); with
    the airframe's ``hinge`` model in flight, corrected for the simulation's own deflection."""
    rate = window.sample_rate_hz
    return LoggedLoad(
        window.flight_condition,
        smoothed(window.signals["hinge_moment_nm"], rate) - sensor_bias_nm,
        smoothed(window.signals["position_deg"], rate),
        hinge,
    )


def scenario_from_window(
    window: RotaryWindow, drive: DriveConstants, hinge: HingeGeometry | None, effects: EffectSet = EffectSet()
) -> Scenario:
    """Case 1B for a logged window: its actuator, its command, its logged load, its first state."""
    return Scenario(
        drive=drive,
        command_knots_deg=knots_from_samples(window.signals["command_deg"])[0],
        load=logged_load(window, hinge, effects.get("hinge_moment_bias", "bias_nm")),
        initial=initial_state(window, drive),
        sample_rate_hz=window.sample_rate_hz,
        effects=effects,
    )


def inside(fdj_nm: float, eta_o: float, nominal_fdj_nm: float, fsd: float = 2.0) -> HealthParams:
    """One health point at (FDJ, η_O), held inside the physical limits of an actuator of ``nominal_fdj_nm`` (a
    window the model cannot explain may be solved with a negative FDJ: it is still simulated, at the limit)."""
    limits = physical(nominal_fdj_nm)
    fdj = float(np.clip(fdj_nm, *limits.fdj_nm))
    return HealthParams.single(fsd * fdj, fdj, float(np.clip(eta_o, *limits.eta_o)))


def following_error(scenario: Scenario, window: RotaryWindow, health: HealthParams, noise: SensorNoise) -> float:
    """RMS(speed)/σ_speed + RMS(current)/σ_current of ``window`` simulated clean at ``health`` in ``scenario``
    (after ``SETTLE_S``): how closely a model with its effects follows the drive itself."""
    simulated = scenario.simulate(health, lanes=1).simulation(0)
    keep = slice(round(SETTLE_S * window.sample_rate_hz), None)
    return sum(
        rms(window.signals[name][keep] - simulated[name][keep]) / max(sigma, 1e-9)
        for name, sigma in (("motor_speed_radps", noise.motor_speed_radps), ("current_a", noise.current_a))
    )
