"""Window -> ``ema-estimate/1``: what ``ema estimate``, the service and the fleet call.

The thesis's §6.3 proposal, made to hold on data our simulator did not draw:

1. **prepare**: repair, average, align and zero the window's sensors (``training.conditioning``);
2. **physics**: fit Eq. 5.1 by least squares (``training.baseline``), a block-jackknife std beside;
3. **simulate**: a Case-1B dataset of the window's own command, logged load and first state, its
   health drawn in a box around the physics estimate (``training.design``: no fixed range, so no
   cap on a worn actuator), with the window's own sensor noise;
4. **train**: the shallow network on the residual torque of the sliding samples;
5. **assess**: both estimators scored on held-out simulations, blended per parameter, checked
   against the window itself (``training.assess``) and by simulating it at the answer
   (``training.reproduction``);
6. **FSJ** where the window shows a quasi-static break-away (``training.static_friction``).
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, replace

import numpy as np

from sim.noise import SensorNoise
from sim.params import DEFAULT_RANGES, ActuatorParams, eta_a_from_eta_o
from sim.residual import residual_torque_nm
from sim.window import Window
from training import design
from training.assess import Assessed, Candidates, assess, physics_values
from training.baseline import FIT_ARRAYS, FitSettings, FrictionFit, fit_friction, fit_window, regressors
from training.conditioning import Prepared, conditioning_done, conditioning_notes, prepare, widened
from training.config import PipelineConfig
from training.dataset import Scenario, Simulated, scenario_from_window, simulate_noisy
from training.documents import (
    TARGETS,
    DatasetInfo,
    Estimate,
    Estimates,
    FitCheck,
    RatioEstimate,
    Timings,
    TrainingInfo,
    WindowInfo,
    parameter,
)
from training.estimator import NetworkEstimator
from training.network import TrainConfig
from training.preprocess import as_read, sliding_features
from training.reproduction import MAX_RATIO, output_error_ratios
from training.static_friction import StaticFriction, read_static_friction

NOMINAL = {"FDJ": DEFAULT_RANGES.nominal_fdj_nm, "eta_O": DEFAULT_RANGES.nominal_eta_o}
NOMINAL_ETA_A = float(eta_a_from_eta_o(DEFAULT_RANGES.nominal_eta_o))
HEALTHY_RANGE = {"FDJ": DEFAULT_RANGES.fdj_nm, "eta_O": DEFAULT_RANGES.eta_o}  # Table 3.1: "% of range" is of these
# ±2 std wider than this share of the healthy range: the window is said to determine the parameter weakly.
WEAK_SHARE_OF_RANGE = 0.10


def share_of_range(name: str, amount: float) -> float:
    """``amount`` (in the parameter's unit) as a share of the width of its Table 3.1 range."""
    low, high = HEALTHY_RANGE[name]
    return amount / (high - low)


def weakly_determined(name: str, std: float) -> bool:
    """±2 std wider than ``WEAK_SHARE_OF_RANGE`` of ``name``'s healthy range."""
    return share_of_range(name, 2 * std) > WEAK_SHARE_OF_RANGE


@dataclass(frozen=True)
class Data:
    """Everything simulated for one window."""

    scenario: Scenario
    box: design.Box
    noise: SensorNoise
    sims: Simulated  # n_simulations for training, then check_windows held out
    sliding: np.ndarray  # (n_samples,) the window's Eq. 5.1 samples
    inputs: np.ndarray  # (n_total, n_timesteps) network inputs of every simulation
    window_inputs: np.ndarray  # (1, n_timesteps)


def simulate_dataset(window: Window, seen: Window, physics: FrictionFit, config: PipelineConfig) -> Data:
    """The box around the physics estimate, the window's sensor noise (measured on ``window`` as logged),
    the simulations, and the features of both (the window read as ``seen``: through ``as_read``)."""
    box = design.box_around(physics.fdj_nm[0], physics.fdj_std_nm[0], physics.eta_o[0], physics.eta_o_std[0])
    scenario = scenario_from_window(seen)
    health = design.draw(box, config.total_simulations, config.seed)
    sims = simulate_noisy(scenario, health, window, design.centre(box), config.seed + 1, config.check_windows)
    rate = window.sample_rate_hz
    residual = residual_torque_nm(
        seen.signals["current_a"], seen.signals["motor_speed_radps"], seen.signals["hinge_moment_nm"], rate
    )
    sliding = regressors(seen.signals, rate, ActuatorParams(), FitSettings(), residual_nm=residual)[3][0]
    n_timesteps = min(config.n_timesteps, window.n_samples)
    inputs = sliding_features(sims.residual_nm, sliding, n_timesteps)
    return Data(scenario, box, sims.noise, sims, sliding, inputs, sliding_features(residual, sliding, n_timesteps))


# On a few dozen noisy simulations the network stops improving within a few epochs, and the physics fit
# carries most of the answer (training.assess): the thesis's 12 failures and 1000 epochs made its time
# the pipeline's least predictable.
PIPELINE_TRAINING = TrainConfig(max_epochs=60, max_validation_failures=6)


def train_network(data: Data, config: PipelineConfig) -> NetworkEstimator:
    n = config.n_simulations
    train = replace(PIPELINE_TRAINING, hidden=config.hidden_units, seed=config.seed)
    health = data.sims.health
    return NetworkEstimator(train, config.members).fit(data.inputs[:n], health.fdj_nm[:n], health.eta_o[:n], data.box)


def candidates(
    window: Window, physics: FrictionFit, data: Data, network: NetworkEstimator, n: int
) -> tuple[Candidates, FrictionFit]:
    """Physics and network on the window and on the held-out simulations (and the physics fit of those)."""
    held = {name: values[n:] for name, values in data.sims.signals.items()}
    check_physics = fit_friction(held, window.sample_rate_hz, residual_nm=data.sims.residual_nm[n:])
    unit = network.predict_unit(np.vstack([data.inputs[n:], data.window_inputs]))
    fdj, eta_o = data.box.denormalize(unit)
    health = data.sims.health
    # A held-out simulation that never slides long enough has no physics answer: left out, not poisoning the scores.
    ok = np.isfinite(check_physics.fdj_nm) & np.isfinite(check_physics.eta_o)
    check_physics = replace(check_physics, **{k: getattr(check_physics, k)[ok] for k in FIT_ARRAYS})
    fdj_check, eta_check = fdj[:-1][ok], eta_o[:-1][ok]
    truth_fdj, truth_eta = health.fdj_nm[n:][ok], health.eta_o[n:][ok]
    return Candidates(
        physics={k: float(v) for k, v in physics_values(physics).items()},
        physics_std={"FDJ": float(physics.fdj_std_nm[0]), "eta_O": float(physics.eta_o_std[0])},
        network={"FDJ": float(fdj[-1]), "eta_O": float(eta_o[-1])},
        network_unit=unit[-1],
        check_truth={"FDJ": truth_fdj, "eta_O": truth_eta},
        check_physics=physics_values(check_physics, slice(None)),
        check_network={"FDJ": fdj_check, "eta_O": eta_check},
    ), check_physics


def fit_check(window: Window, data: Data, answer: Assessed, equation_ratio: float, n: int) -> FitCheck:
    """Simulate the window at the answer and compare (``training.reproduction``)."""
    health = design.inside(answer.values["FDJ"], answer.values["eta_O"])
    floor = float(np.sqrt(np.mean((data.sims.residual_nm[n:] - data.sims.clean_residual_nm)[:, data.sliding] ** 2)))
    ratios = output_error_ratios(window, data.scenario, health, data.noise, floor, data.sliding)
    reproduced = ratios["residual_torque"] <= MAX_RATIO
    notes = list(answer.notes)
    if not reproduced:
        notes.append(
            f"simulated at these estimates, the window's residual torque differs by {ratios['residual_torque']:.1f}x "
            "its noise floor: the model does not reproduce this window"
        )
    return FitCheck(
        reproduced=reproduced,
        equation_error_ratio=equation_ratio,
        output_error_ratio=ratios,
        uncertainty_inflation=answer.inflation,
        notes=notes,
    )


def estimate_window(
    window: Window,
    config: PipelineConfig = PipelineConfig(),
    on_stage: Callable[[str], None] | None = None,
    take_off_offset: bool = True,
) -> Estimate:
    """The ``ema-estimate/1`` result for one window; ``on_stage`` hears each stage as it starts (and may
    raise to stop the job there); ``take_off_offset=False`` reads the window with the spec's model alone
    (``calibration``'s base). Raises InputError (field ``signals``) for a window with too little sliding motion.
    """
    stage = on_stage or (lambda _: None)
    clock = [time.perf_counter()]
    prepared = prepare(window, take_off_offset=take_off_offset)
    w, n = prepared.window, config.n_simulations
    seen = replace(w, signals=as_read(w.signals, w.sample_rate_hz))
    physics = fit_window(seen.signals, w.sample_rate_hz)
    stage(f"simulating {config.total_simulations} windows around the physics estimate")
    data = simulate_dataset(w, seen, physics, config)
    clock.append(time.perf_counter())
    stage(f"training {config.members} network(s) of {config.hidden_units} neurons")
    network = train_network(data, config)
    clock.append(time.perf_counter())
    stage("estimating")
    found, check_physics = candidates(w, physics, data, network, n)
    floor = np.median(check_physics.residual_rms_nm) if len(check_physics.residual_rms_nm) else np.nan
    equation_ratio = float(physics.residual_rms_nm[0] / floor) if np.isfinite(floor) else 1.0
    answer = assess(found, equation_ratio)
    answer = replace(answer, stds=widened(answer.stds, prepared.offset.spread, prepared.lags.spread))
    clock.append(time.perf_counter())
    stage("checking the answer against the window")
    check = fit_check(seen, data, answer, equation_ratio, n)
    fsj = read_static_friction(seen.signals, w.sample_rate_hz, answer.values["FDJ"], answer.values["eta_O"], data.noise)
    clock.append(time.perf_counter())
    return _document(prepared, physics, data, network, answer, check, fsj, config, clock)


def _estimates(answer: Assessed, fsj: StaticFriction) -> Estimates:
    """FDJ and η_O as assessed, η_A by Eq. 3.4 (its std through the derivative), FSJ and FSD if read."""
    eta_o, eta_o_std = answer.values["eta_O"], answer.stds["eta_O"]
    slope = float((eta_a_from_eta_o(eta_o + 1e-6) - eta_a_from_eta_o(eta_o - 1e-6)) / 2e-6)
    fdj = answer.values["FDJ"]
    ratio = None
    if fsj.value_nm is not None and fsj.std_nm is not None:
        relative = np.hypot(fsj.std_nm / fsj.value_nm, answer.stds["FDJ"] / fdj)
        ratio = RatioEstimate(value=fsj.value_nm / fdj, std=fsj.value_nm / fdj * relative)
    weak_eta = weakly_determined("eta_O", eta_o_std)  # η_A is η_O's through Eq. 3.4, and as weak
    return Estimates(
        FDJ=parameter(fdj, answer.stds["FDJ"], NOMINAL["FDJ"], weakly_determined("FDJ", answer.stds["FDJ"])),
        eta_O=parameter(eta_o, eta_o_std, NOMINAL["eta_O"], weak_eta),
        eta_A=parameter(float(eta_a_from_eta_o(eta_o)), abs(slope) * eta_o_std, NOMINAL_ETA_A, weak_eta),
        FSJ=None if fsj.value_nm is None else parameter(fsj.value_nm, fsj.std_nm, DEFAULT_RANGES.nominal_fsj_nm),
        FSD=ratio,
    )


def _notes(prepared: Prepared, physics: FrictionFit, estimates: Estimates, check: FitCheck) -> list[str]:
    notes = [*check.notes, *conditioning_notes(prepared)]
    for name in TARGETS:
        entry = getattr(estimates, name)
        if entry.weakly_determined:
            low, high = HEALTHY_RANGE[name]
            spread = share_of_range(name, 2 * entry.std)
            notes.append(
                f"{name} is weakly determined by this window: ±2 std spans {100 * spread:.0f} % of the healthy "
                f"range ({low:g}–{high:g}); a short window, a slow log or a hinge load that barely varies "
                "holds little of it (trend it with its std)"
            )
    if physics.at_search_edge[0]:
        notes.append("η_O lies at an end of the physical search range: read it as a bound, not a value")
    if estimates.FDJ.value <= 0:
        notes.append("FDJ ≤ 0 is not a friction: the model does not describe this window (see fit_check)")
    if estimates.eta_A.value < 0:
        notes.append("η_A < 0: the transmission is irreversible (the load cannot back-drive it; thesis Case 1C)")
    return notes


def _window_info(prepared: Prepared, data: Data) -> WindowInfo:
    """The window as logged, and what conditioning did to it."""
    w = prepared.window
    return WindowInfo(
        n_samples=prepared.original_samples,
        duration_s=prepared.original_samples / prepared.original_rate_hz,
        sample_rate_hz=prepared.original_rate_hz,
        processed_rate_hz=w.sample_rate_hz,
        **conditioning_done(prepared),
        sliding_fraction=float(np.mean(data.sliding)),
        recorded_at=w.recorded_at,
        flight_hours=w.flight_hours,
    )


def _document(
    prepared: Prepared,
    physics: FrictionFit,
    data: Data,
    network: NetworkEstimator,
    answer: Assessed,
    check: FitCheck,
    fsj: StaticFriction,
    config: PipelineConfig,
    clock: list[float],
) -> Estimate:
    w = prepared.window
    estimates = _estimates(answer, fsj)
    first = network.fits_[0]
    return Estimate(
        actuator_id=w.actuator_id,
        window_id=w.window_id,
        estimates=estimates,
        fsj_note=fsj.reason,
        irreversible=estimates.eta_A.value < 0,
        notes=_notes(prepared, physics, estimates, check),
        timings_s=Timings(
            simulate=clock[1] - clock[0],
            train=clock[2] - clock[1],
            predict=clock[3] - clock[2],
            check=clock[4] - clock[3],
            total=clock[4] - clock[0],
        ),
        dataset=DatasetInfo(
            n_simulations=config.n_simulations,
            n_timesteps=data.inputs.shape[1],
            inputs=["residual_torque, sliding samples"],
            check_windows=config.check_windows,
            noise_estimated=data.noise.as_dict(),
            box={"FDJ": data.box.fdj_nm, "eta_O": data.box.eta_o},
        ),
        training=TrainingInfo(
            epochs=first.epochs,
            stop_reason=first.stop_reason,
            val_mse=first.val_mse,
            test_mse=first.test_mse,
            members=config.members,
            hidden_units=config.hidden_units,
        ),
        methods=answer.methods,
        fit_check=check,
        window=_window_info(prepared, data),
        config=config,
    )
