"""A servo window's own dataset: its set point run in closed loop (``ema.kinds.servo.closed_loop``) at constants drawn
around the physics estimate.

Every constant the inverse model read that the simulator has (M, C or C per direction, FDJ, the offset, a
Stribeck term, a force once per turn) is drawn in a box centred on its estimate, ±``SPAN_SIGMAS`` of its std wide
but never narrower than ``MIN_HALF_SHARE`` of FDJ (a constant of either sign, which may be near 0) or of itself,
filled by a scrambled Halton sequence. Each simulation reads its position sensor
at its own phase of the sensor's step (the quantization a real log carries, drawn anew). The network's inputs
are the drive's force, averaged into ``n_timesteps`` bins: what a window of this command shows of its
constants.

Where the window holds more than the model explains (its Eq. 5.1 residual beyond what the model's own noise
leaves, ``misfit_limit``), the simulations are not the log: a network trained on them alone reads the log's
unexplained part as a change of its constants. So each simulation then carries the window's own misfit in its
inputs (``carrying``: the window's bins less those of its simulation at the physics answer), shifted in time and
signed at random: the network learns the constants beside a disturbance of that size and shape, and its errors
on the held-out simulations, which carry it too, say what it costs.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from ema.estimate.config import PipelineConfig
from ema.estimate.simulate.design import SPAN_SIGMAS, binned, halton, shifted_copies
from ema.kinds.servo.closed_loop import LANE_PARAMETERS, ServoRuns
from ema.kinds.servo.inverse import EITHER_SIGN, InverseSolution
from ema.kinds.servo.log_reading import ServoPrepared

MIN_HALF_SHARE = 0.05
LANE_COLUMNS = {
    "mass_kg": (0,),
    "fdj_n": (1,),
    "viscous_ns_per_m": (2, 3),
    "viscous_up_ns_per_m": (2,),
    "viscous_down_ns_per_m": (3,),
    "offset_n": (4,),
    "stribeck_n": (5,),
    "presliding_n": (7,),
    "turn_ripple_sin_n": (9,),
    "turn_ripple_cos_n": (10,),
}  # a constant of the inverse model the simulator has -> the lane parameters it sets (``LANE_PARAMETERS``)
NONLINEAR_COLUMNS = {"stribeck": LANE_PARAMETERS.index("stribeck_speed_mps"),
                     "presliding": LANE_PARAMETERS.index("presliding_travel_m"),
                     "turn_ripple": LANE_PARAMETERS.index("turn_ripple_travel_m")}  # fmt: skip


@dataclass(frozen=True)
class ServoData:
    targets: tuple[str, ...]  # the constants drawn, in the inverse model's names
    low: np.ndarray  # (T,) the box
    high: np.ndarray  # (T,)
    truth: np.ndarray  # (S, T) each simulation's constants
    runs: ServoRuns  # (S, N) position and force as the controller logged them
    inputs: np.ndarray  # (S, F) the network's inputs
    window_inputs: np.ndarray  # (F,) the window's

    def normalize(self, values: np.ndarray) -> np.ndarray:
        return (values - self.low) / (self.high - self.low)

    def denormalize(self, unit: np.ndarray) -> np.ndarray:
        return self.low + unit * (self.high - self.low)


def lane_parameters(values: dict[str, float], effects: dict[str, float] | None = None) -> np.ndarray:
    """A lane's parameters (``LANE_PARAMETERS``) from the inverse model's named constants and its effects'
    nonlinear constants; the simulator leaves out what it has no parameter for."""
    lane = np.zeros(len(LANE_PARAMETERS))
    for name, value in values.items():
        for column in LANE_COLUMNS.get(name, ()):
            lane[column] = value
    for effect, column in NONLINEAR_COLUMNS.items():
        lane[column] = (effects or {}).get(effect, 0.0)
    return lane


def box(physics: InverseSolution, targets: tuple[str, ...]) -> tuple[np.ndarray, np.ndarray]:
    """(low, high) of each target: its estimate ±max(``SPAN_SIGMAS`` stds, ``MIN_HALF_SHARE`` of its scale)."""
    scale = {name: abs(physics.values[name]) for name in targets}
    for name in EITHER_SIGN.intersection(targets):  # a constant of either sign, near 0, is drawn on FDJ's scale
        scale[name] = abs(physics.values["fdj_n"])
    centre = np.array([physics.values[name] for name in targets])
    half = np.array([max(SPAN_SIGMAS * physics.stds[n], MIN_HALF_SHARE * scale[n], 1e-9) for n in targets])
    low = centre - half
    floor = np.array(
        [-np.inf if name in EITHER_SIGN else 1e-3 * abs(c) for name, c in zip(targets, centre, strict=True)]
    )
    shift = np.maximum(floor - low, 0.0)  # a box that would reach a negative mass or friction moves up, not shrinks
    return low + shift, centre + half + shift


def simulate_servo_dataset(prepared: ServoPrepared, physics: InverseSolution, config: PipelineConfig) -> ServoData:
    """The window's ``config.total_simulations`` closed-loop runs, their constants and the network's inputs."""
    targets = tuple(name for name in physics.values if name in LANE_COLUMNS)
    low, high = box(physics, targets)
    count = config.total_simulations
    unit = halton(count, config.seed, len(targets))
    truth = low + unit * (high - low)
    effects = prepared.effects
    lanes = np.stack([lane_parameters(dict(zip(targets, row, strict=True)), effects) for row in truth])
    phases = np.random.default_rng(config.seed).uniform(size=count)
    runs = prepared.closed_loop(lanes, phases)
    s, kept = prepared.window.signals, prepared.motion.samples
    bins = min(config.n_timesteps, (kept.stop - kept.start) // 2)
    inputs = binned(runs.drive_force_n[:, kept], bins)
    window_inputs = binned(s["drive_force_n"][kept], bins)
    return ServoData(targets, low, high, truth, runs, inputs, window_inputs)


def window_misfit(prepared: ServoPrepared, physics: InverseSolution, bins: int) -> np.ndarray:
    """(bins,) what the window's binned force holds beyond its simulation at the physics answer (the sensor read
    mid-step): the model's miss, with one draw of noise."""
    kept = prepared.motion.samples
    centre = prepared.closed_loop(lane_parameters(physics.values, prepared.effects)[None, :], np.array([0.5]))
    return binned(prepared.window.signals["drive_force_n"][kept], bins) - binned(centre.drive_force_n[:, kept], bins)[0]


def carrying(data: ServoData, misfit: np.ndarray, seed: int) -> ServoData:
    """``data`` with ``misfit`` (bins,) added to every simulation's inputs, each at its own circular shift and sign
    (drawn from ``seed``): a disturbance of the window's own size and spectrum, at no fixed place."""
    return replace(data, inputs=data.inputs + shifted_copies(misfit, len(data.inputs), seed))
